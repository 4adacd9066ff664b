// Building a render's response from its outcome: a pure function (no sockets,
// no GL, no clock), so every field of the wire format is unit-tested
// (tests/unit/test_render_result.cpp) without a server or a renderer.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "protocol/camera.hpp"
#include "protocol/render_response.hpp"
#include "render/accuracy_controller.hpp"
#include "server/render_service.hpp"

namespace beamcast {

// What the response needs besides the outcome, fixed when the request was read.
struct RenderResultContext {
  std::vector<Camera> cameras;              // in frame order: names and sizes
  std::vector<std::string> planned_passes;  // reported when no frame ran
  int bit_depth = 8;                        // of PNG frames (JPEG frames are 8)
  bool base64 = false;                      // data_base64 instead of attachments
  bool stream = false;                      // "stream": true: each part carries "stream"
  std::optional<QualityReport> quality;     // "quality": "auto" only
  std::string video_codec;                  // set: the frame is a video frame of this codec
  double server_ms = 0.0;                   // arrival to response, measured by the caller
};

// The "quality" block of an interactive frame; `frame_ms` is what it cost
// (render with read-back, plus encoding).
QualityReport quality_report(const ControllerDecision& decision, const AccuracyLevel& level,
                             std::size_t ladder_size, double budget_ms, bool jpeg, int jpeg_quality,
                             double frame_ms);

// The render result; appends the encoded images to `binary` (unless base64),
// in frame order, and points the frames' attachments at them.
RenderResponse build_render_response(const RenderOutcome& out, const RenderResultContext& ctx,
                                     std::vector<std::uint8_t>* binary);

}  // namespace beamcast
