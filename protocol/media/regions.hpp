// The medium region kinds, listed once. The scene parser, hello's
// capabilities, the GPU path (render/passes.cpp, set_medium_uniforms) and the
// CPU reference (MediumRegion in protocol/medium.hpp) all visit this list;
// adding a kind is its own files plus its include and its name in
// RegionShape below (and its branch in shaders/medium_regions.glsl).
#pragma once

#include <string_view>
#include <variant>
#include <vector>

#include "protocol/media/box.hpp"
#include "protocol/media/cylinder.hpp"
#include "protocol/media/mesh.hpp"
#include "protocol/media/sphere.hpp"

namespace beamcast {

namespace json_read {
struct Node;
}  // namespace json_read

using RegionShape = std::variant<BoxRegion, SphereRegion, MeshRegion, CylinderRegion>;

// The "type" strings of every kind, in RegionShape's order.
std::vector<std::string_view> medium_region_types();
// Every key a region may have: "type", each kind's kFields (in RegionShape's
// order, each once) and the coefficients.
std::vector<std::string_view> medium_region_fields();

// The kind whose kType is the string at `type`, its keys checked (refused:
// "unknown_field" at the key's path) and parsed by its parse function; an
// unknown type throws invalid_value at type.path, listing the types.
RegionShape parse_region_shape(const json_read::Node& type, const RegionParse& in);

}  // namespace beamcast
