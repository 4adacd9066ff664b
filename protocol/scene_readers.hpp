// Typed reads of scene values shared by the scene parser and the element
// modules (protocol/occluders/). Failures throw ProtocolError with the
// value's JSON pointer, like every reader in json_reader.hpp.
#pragma once

#include <array>

#include "protocol/json_reader.hpp"
#include "protocol/mesh_obj.hpp"
#include "protocol/scene_json.hpp"

namespace beamcast::json_read {

// A position: finite, |component| <= max_abs_coordinate.
Vec3 read_point(const Node& n, const SceneLimits& limits);
// The smallest length a scene may give (a size, an edge): the GPU computes
// in float, whose normal numbers end at 1.2e-38, so a length's square (an
// area, 1e-30) must still be one (issue 43).
inline constexpr double kMinLength = 1e-15;
// A length: in [kMinLength, max_abs_coordinate].
double read_size(const Node& n, const SceneLimits& limits);
// True if normalize(v) is finite: any nonzero finite vector (normalize is scale-free).
bool normalizable(const Vec3& v);
// A direction: finite, not the zero vector (need not be unit).
Vec3 read_direction(const Node& n);
// The largest radiometric number a scene may give (a colour channel, an
// intensity) and the largest product of them (with a density's peak) a
// pixel may gain from one element: the GPU adds light in float (3.4e38), and a
// background of 1e39 was an infinite pixel (render fuzzer, issue 43).
inline constexpr double kMaxRadiometric = 1e30;
// A radiometric number: in [0, kMaxRadiometric].
double read_radiometric(const Node& n);
// Components in [0, kMaxRadiometric].
Color read_color(const Node& n);
// Components in [0, 1].
Color read_albedo(const Node& n);
// [w, x, y, z], not all zero, returned normalized (scale-free: any nonzero
// length is accepted).
std::array<double, 4> read_quaternion(const Node& n);
// A mesh's "translate", "scale" (a number or three, nonzero) and "rotation"
// (a quaternion) from its object, as occluders and medium regions give them.
MeshTransform parse_mesh_transform(const ObjectReader& o, const SceneLimits& limits);

}  // namespace beamcast::json_read
