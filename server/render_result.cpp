#include "server/render_result.hpp"

#include "protocol/base64.hpp"
#include "protocol/check.hpp"

#include <algorithm>

namespace beamcast {

QualityReport quality_report(const ControllerDecision& decision, const AccuracyLevel& level,
                             std::size_t ladder_size, double budget_ms, bool jpeg, int jpeg_quality,
                             double frame_ms) {
  const RenderSettings& r = level.render;
  QualityReport q;
  q.level = static_cast<std::size_t>(decision.level);
  q.levels = ladder_size;
  q.label = level.label;
  q.reason = decision.reason;
  q.still = decision.still;
  q.moving = decision.moving;
  q.scale = decision.still ? 1.0 : level.scale;
  q.method = r.method == IntegrationMethod::kTable        ? "table"
             : r.method == IntegrationMethod::kClosedForm ? "closed_form"
                                                          : "march";
  q.table = {r.table_d, r.table_s};
  q.samples = r.samples;
  q.format = jpeg ? "jpeg" : "png";
  if (jpeg) q.jpeg_quality = jpeg_quality;
  q.budget_ms = budget_ms;
  q.estimate_ms = decision.estimate_ms;
  q.frame_ms = frame_ms;
  return q;
}

namespace {

std::string frame_name(const Camera& cam, std::size_t i) {
  return cam.name.empty() ? "camera_" + std::to_string(i) : cam.name;
}

}  // namespace

RenderResponse build_render_response(const RenderOutcome& out, const RenderResultContext& ctx,
                                     std::vector<std::uint8_t>* binary) {
  // The service answers with one result per camera; one image each, or one atlas.
  BEAMCAST_CHECK(out.frames.size() <= ctx.cameras.size(), "a frame result without a camera");
  BEAMCAST_CHECK(out.frame_index.empty() || out.frame_index.size() == out.frames.size(),
                 "a camera index for every frame of a part");
  BEAMCAST_CHECK(out.pngs.size() == (out.atlas ? 1 : out.frames.size()),
                 "one image per frame, or one atlas");
  auto image = [&](RenderFrame& f, std::size_t i) {
    const bool video = !ctx.video_codec.empty();
    f.format = video           ? ctx.video_codec
               : out.is_jpeg[i] ? "jpeg"
                                : std::string(frame_format_name(out.frame_format));
    // JPEG and video have 8 bits per channel.
    f.bit_depth = out.is_jpeg[i] || video ? 8 : ctx.bit_depth;
    f.encode_ms = out.encode_ms[i];
    const std::vector<std::uint8_t>& png = out.pngs[i];
    if (ctx.base64) {
      f.data_base64 = base64_encode(png);
    } else {
      f.attachment = Attachment{binary->size(), png.size()};
      binary->insert(binary->end(), png.begin(), png.end());
    }
  };

  RenderResponse r;
  double readback_ms = 0.0;
  for (std::size_t i = 0; i < out.frames.size(); ++i) {
    const FrameResult& fr = out.frames[i];
    // A streamed part carries some of the frames: each names its camera index.
    const std::size_t cam = out.frame_index.empty() ? i : out.frame_index[i];
    BEAMCAST_CHECK(cam < ctx.cameras.size(), "a frame's camera index within the request");
    RenderFrame f;
    f.camera = frame_name(ctx.cameras[cam], cam);
    f.index = cam;
    f.width = ctx.cameras[cam].width;
    f.height = ctx.cameras[cam].height;
    f.gpu_ms = fr.gpu_ms;
    f.pass_ms.emplace();
    for (const PassTiming& p : fr.passes) f.pass_ms->push_back({p.name, p.gpu_ms});
    f.readback_ms = fr.readback_ms;
    f.gpu_batch = GpuBatch{fr.batch.index, fr.batch.views, fr.batch.gpu_ms, fr.batch.readback_ms};
    if (std::find_if(fr.passes.begin(), fr.passes.end(),
                     [](const PassTiming& p) { return p.name == "photons"; }) != fr.passes.end()) {
      f.photons = PhotonReport{fr.photons, fr.photon_trace_ms, fr.photon_upload_ms, fr.photon_disks};
    }
    readback_ms += fr.readback_ms;
    if (out.atlas) {
      f.x = out.atlas->tiles[i].x;
      f.y = out.atlas->tiles[i].y;
    } else {
      image(f, i);
    }
    r.frames.push_back(std::move(f));
  }
  if (out.atlas) {
    // One image; the frames become its tiles.
    const Atlas& a = *out.atlas;
    RenderFrame f;
    f.camera = "atlas";
    f.index = 0;
    f.width = a.columns * a.cell_width;
    f.height = a.rows * a.cell_height;
    image(f, 0);
    f.atlas = RenderAtlas{a.columns, a.rows, a.cell_width, a.cell_height, std::move(r.frames)};
    r.frames = {std::move(f)};
  }
  r.passes = ctx.planned_passes;
  if (!out.frames.empty()) {
    r.passes.clear();
    for (const PassTiming& p : out.frames[0].passes) r.passes.push_back(p.name);
  }
  r.batched = out.batched_requests > 1;
  r.batch_requests = out.batched_requests;
  r.batch_views = out.batched_views;
  r.timings =
      RenderTimings{out.queue_ms, out.render_ms, readback_ms, out.encode_wall_ms, ctx.server_ms};
  r.quality = ctx.quality;
  if (ctx.stream) r.stream = StreamPart{std::max(0, out.part), out.last_part, ctx.cameras.size()};
  return r;
}

}  // namespace beamcast
