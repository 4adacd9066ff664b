// SLIM model files (issue 16): the JSON form and the compact binary form of a
// list of support spheres (protocol/slim_model.hpp), read for scenes (from
// the assets directory, with JSON-pointer errors) and written by
// `beamcast slim fit`.
//
// JSON: {"format": "beamcast-slim", "version": 1, "spheres": [S, ...]} with
// every S as in a scene's inline "spheres" (docs/scene-format.md, "slim"):
//   {"center": [x, y, z], "radius": r, "rotation": [w, x, y, z],
//    "coefficients": [A, B, C, D, E, F],
//    "coefficients2": [A, B, C, D, E, F], "crease": "min" | "max"}
// ("rotation" defaults to identity; "coefficients2" and "crease" together or
// not at all).
//
// Binary (little-endian): "BSLM", uint32 version (1), uint32 sphere count,
// uint32 0; then per sphere 20 float32 (centre xyz, radius, rotation wxyz,
// coefficients A-F, coefficients2 A-F) and a uint32 crease (0 none, 1 min,
// 2 max): 84 bytes a sphere. The file's size must be exactly that.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "protocol/slim_model.hpp"

namespace beamcast {

// Reads one sphere object / an array of them; errors are ProtocolError at
// `path` and below (radius > 0 and <= max_abs, a rotation that can be
// normalized, finite coefficients, crease rules). `max_spheres` bounds the
// array (limit_exceeded).
std::vector<SlimSphere> parse_slim_spheres(const nlohmann::json& array, const std::string& path,
                                           std::int64_t max_spheres, double max_abs_coordinate);

// A model file's contents, JSON or binary (told apart by the first bytes).
// Errors: "bad_slim" at `json_path` (truncated or malformed binary, a JSON
// file that is not a model: the message then names the field inside the
// file), "limit_exceeded" past max_spheres.
std::vector<SlimSphere> parse_slim_file_bytes(const std::string& bytes, const std::string& file,
                                              const std::string& json_path,
                                              std::int64_t max_spheres,
                                              double max_abs_coordinate);

nlohmann::json slim_to_json(const std::vector<SlimSphere>& spheres);
std::string slim_to_binary(const std::vector<SlimSphere>& spheres);
// Writes JSON if `path` ends in .json, else binary. Throws std::runtime_error
// if the file cannot be written.
void write_slim_file(const std::filesystem::path& path, const std::vector<SlimSphere>& spheres);

}  // namespace beamcast
