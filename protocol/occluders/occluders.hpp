// The occluder kinds, listed once. The scene parser, hello's capabilities,
// the GPU path (render/scene_resources.cpp) and the CPU reference
// (render/reference.cpp) all visit this list; adding a kind is its own files
// plus its include and its name in OccluderShape below.
#pragma once

#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "protocol/occluders/box.hpp"
#include "protocol/occluders/mesh.hpp"
#include "protocol/occluders/plane.hpp"
#include "protocol/occluders/quad.hpp"
#include "protocol/occluders/slim.hpp"
#include "protocol/occluders/sphere.hpp"

namespace beamcast {

namespace json_read {
struct Node;
}

using OccluderShape =
    std::variant<PlaneOccluder, BoxOccluder, SphereOccluder, MeshOccluder, QuadOccluder,
                 SlimOccluder>;

// The "type" strings of every kind, in OccluderShape's order.
std::vector<std::string_view> occluder_types();

// The kind whose kType is the string at `type`, parsed by its parse function;
// an unknown type throws invalid_value at type.path, listing the types.
OccluderShape parse_occluder_shape(const json_read::Node& type, const OccluderParse& in);

}  // namespace beamcast
