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

// How many spheres a model file or inline list may add: `left` of the scene's
// max_slim_spheres = `limit` (messages name the limit, not what is left).
struct SlimCount {
  std::int64_t left = 0;
  std::int64_t limit = 0;
};

// Reads one sphere object / an array of them; errors are ProtocolError at
// `path` and below (radius > 0 and <= max_abs, a rotation that can be
// normalized, finite coefficients, crease rules). `count` bounds the
// array (limit_exceeded).
std::vector<SlimSphere> parse_slim_spheres(const nlohmann::json& array, const std::string& path,
                                           SlimCount count, double max_abs_coordinate);

// A model file's contents, JSON or binary (told apart by the first bytes).
// Errors: "bad_slim" at `json_path` (truncated or malformed binary, a JSON
// file that is not a model: the message then names the field inside the
// file), "limit_exceeded" past count.left spheres. JSON is read as a stream:
// each sphere is checked and its parsed form dropped as it completes, and the
// read stops at the first sphere over the count, at a sphere of more than
// kSlimMaxSphereValues values or at more than kSlimMaxOtherValues values
// outside "spheres", so memory stays a small multiple of the spheres kept.
std::vector<SlimSphere> parse_slim_file_bytes(const std::string& bytes, const std::string& file,
                                              const std::string& json_path, SlimCount count,
                                              double max_abs_coordinate);

// The same from the file `file` below `assets_dir` (AssetFile's rules), of at
// most kSlimFileHeaderBytes + kSlimMaxJsonBytesPerSphere x count.left bytes
// (checked before reading).
std::vector<SlimSphere> load_slim_file(const std::filesystem::path& assets_dir,
                                       const std::string& file, const std::string& json_path,
                                       SlimCount count, double max_abs_coordinate);

inline constexpr std::int64_t kSlimFileHeaderBytes = 16;
// JSON takes more than the binary form's 84 bytes a sphere; 1 KiB each bounds
// what a file may make the server read.
inline constexpr std::int64_t kSlimMaxJsonBytesPerSphere = 1024;
inline constexpr int kSlimMaxSphereValues = 64;   // a full sphere has 26
inline constexpr int kSlimMaxOtherValues = 16;    // format, version and the root

nlohmann::json slim_to_json(const std::vector<SlimSphere>& spheres);
std::string slim_to_binary(const std::vector<SlimSphere>& spheres);
// Writes JSON if `path` ends in .json, else binary. Throws std::runtime_error
// if the file cannot be written.
void write_slim_file(const std::filesystem::path& path, const std::vector<SlimSphere>& spheres);

}  // namespace beamcast
