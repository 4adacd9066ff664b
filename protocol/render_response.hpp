// The result of a `render` request (protocol/PROTOCOL.md, "render"), typed.
// The server builds one and writes it with to_json; the C++ client, `beamcast
// load` and the server tests read it with render_response_from_json. One
// definition of the wire format instead of one parser per reader.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace beamcast {

struct PassTime {
  std::string name;
  double gpu_ms = 0.0;
  bool operator==(const PassTime&) const = default;
};

// The multi-view GPU batch a frame was part of.
struct GpuBatch {
  int index = 0;
  int views = 1;
  double gpu_ms = 0.0;
  double readback_ms = 0.0;
  bool operator==(const GpuBatch&) const = default;
};

// Lit scenes: the photons splatted into the frame, the disks they were
// drawn as (gi.cluster merges photons; without it, one each) and the CPU
// time of the render's photon tracing (0 when the maps came from the
// server's cache) and upload.
struct PhotonReport {
  std::int64_t count = 0;
  double trace_ms = 0.0;
  double upload_ms = 0.0;
  std::int64_t disks = 0;
  bool operator==(const PhotonReport&) const = default;
};

// Where a frame's PNG lies in the message's binary section.
struct Attachment {
  std::uint64_t offset = 0;
  std::uint64_t length = 0;
  bool operator==(const Attachment&) const = default;
};

struct RenderFrame;

// With "atlas": true: the grid, and per camera a tile (a RenderFrame with x, y
// and GPU timings, without an image of its own).
struct RenderAtlas {
  int columns = 0, rows = 0, cell_width = 0, cell_height = 0;
  std::vector<RenderFrame> tiles;
  bool operator==(const RenderAtlas&) const;
};

struct RenderFrame {
  std::string camera;  // the camera's name, "camera_<index>", or "atlas"
  std::size_t index = 0;
  int width = 0, height = 0;
  // GPU timings: on camera frames and atlas tiles, not on the atlas frame.
  std::optional<double> gpu_ms;
  std::optional<std::vector<PassTime>> pass_ms;  // on the wire an object keyed by pass name
  std::optional<double> readback_ms;
  std::optional<GpuBatch> gpu_batch;
  std::optional<PhotonReport> photons;  // lit scenes only
  // Atlas tiles only: top-left pixel in the atlas.
  std::optional<int> x, y;
  // The image: on camera frames and the atlas frame, not on tiles.
  std::optional<std::string> format;  // "png", "jpeg", "raw" or "raw_zstd" (frame_format.hpp)
  std::optional<int> bit_depth;
  std::optional<double> encode_ms;
  std::optional<Attachment> attachment;    // "encoding": "binary"
  std::optional<std::string> data_base64;  // "encoding": "base64"
  std::optional<RenderAtlas> atlas;        // the atlas frame only
  // Written out (render_response.cpp): clang 14 crashes defaulting the
  // comparisons of these two mutually recursive types.
  bool operator==(const RenderFrame&) const;
};

// "quality": "auto" only: the accuracy controller's choice for this frame.
struct QualityReport {
  std::string mode = "auto";
  std::size_t level = 0, levels = 0;
  std::string label, reason;
  bool still = false, moving = false;
  double scale = 1.0;
  std::string method;  // "table", "closed_form" or "march"
  std::array<int, 2> table{};
  int samples = 0;
  std::string format;               // "png" or "jpeg"
  std::optional<int> jpeg_quality;  // JPEG frames only
  std::optional<int> bitrate_kbps;  // video frames only: the stream's target
  std::optional<bool> keyframe;     // video frames only
  std::optional<int> encoder_speed; // video frames only: the encoder's speed (cpu-used)
  std::optional<int> encoder_bit_depth;  // video frames only: the stream's sample depth (8 or 10)
  std::optional<int> encoder_bands;  // video frames only: horizontal bands the picture is sent as (1: one picture)
  double budget_ms = 0.0, estimate_ms = 0.0, frame_ms = 0.0;
  bool operator==(const QualityReport&) const = default;
};

struct RenderTimings {
  double queue_ms = 0.0, render_ms = 0.0, readback_ms = 0.0, encode_ms = 0.0, server_ms = 0.0;
  bool operator==(const RenderTimings&) const = default;
};

// A streamed render ("stream": true, PROTOCOL.md "Streaming"): this message
// is part `part` of the response; `last` on the final one; `frames` is the
// request's total frame count.
struct StreamPart {
  int part = 0;
  bool last = true;
  std::size_t frames = 0;
  bool operator==(const StreamPart&) const = default;
};

struct RenderResponse {
  std::vector<std::string> passes;
  std::vector<RenderFrame> frames;
  bool batched = false;
  int batch_requests = 1, batch_views = 0;  // "batch": {"requests", "views"}
  RenderTimings timings;
  std::optional<QualityReport> quality;
  std::optional<StreamPart> stream;  // streamed renders only
  bool operator==(const RenderResponse&) const = default;
};

nlohmann::json to_json(const RenderFrame& frame);
nlohmann::json to_json(const RenderResponse& response);

// Reads a render `result` object. Bad or missing fields throw ProtocolError
// with the JSON pointer of the field (`path` is the result's own, e.g.
// "/result"). Unknown keys are ignored, not rejected: a newer server may add
// fields, and an older client must still read the ones it knows.
RenderResponse render_response_from_json(const nlohmann::json& result,
                                         const std::string& path = "");

}  // namespace beamcast
