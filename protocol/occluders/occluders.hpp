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
#include "protocol/occluders/sphere.hpp"

namespace beamcast {

using OccluderShape =
    std::variant<PlaneOccluder, BoxOccluder, SphereOccluder, MeshOccluder, QuadOccluder>;

// The "type" strings of every kind, in OccluderShape's order.
std::vector<std::string_view> occluder_types();

// The kind whose kType is `type`, parsed by its parse function; throws
// invalid_value at `type_path` (listing the types) for an unknown type.
OccluderShape parse_occluder_shape(const std::string& type, const std::string& type_path,
                                   const OccluderParse& in);

}  // namespace beamcast
