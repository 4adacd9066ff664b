// The GPU renderer: owns one headless GL context and turns a validated Scene
// into frames. The passes that run are chosen from the scene's content.
#pragma once

#include <cstdint>
#include <memory>
#include <map>
#include <string>
#include <vector>

#include "protocol/scene.hpp"
#include "render/egl_context.hpp"
#include "render/image.hpp"
#include "render/pass_plan.hpp"
#include "render/scene_resources.hpp"

namespace beamcast {

struct PhotonMaps;

struct RendererOptions {
  EglOptions egl;
  std::size_t table_cache_entries = 64;  // CPU-side line-integral tables kept
  // Uploads that depend only on a scene's content (occluder triangles, SLIM
  // sphere records), kept across renders within this budget (SceneGpuCache).
  std::size_t scene_cache_bytes = 256u << 20;
};

struct PassTiming {
  std::string name;
  double gpu_ms = 0.0;  // GL timestamp queries around the pass
};

// How frames are read back.
enum class Readback {
  // kPipelined, on every device (issue 39).
  kAuto,
  // Each camera's frame or multi-view batch into one of two pixel buffer
  // objects with a fence, mapped only when its buffer is needed again (two
  // cameras or batches later) or when the render is finished
  // (Renderer::finish): on a GPU that renders asynchronously the transfer
  // and the wait overlap the next frames' submission, the next render's
  // included when the caller submits it before finishing this one.
  kPipelined,
  // Read at once after the passes (waits for them): multi-view batches with
  // glGetTextureImage into client memory, single cameras through the pixel
  // buffer, completed at once.
  kSynchronous,
};

struct FrameOptions {
  bool read_hdr = false;  // also read back the linear HDR buffer
  // Multi-view batching: cameras of one size are rendered together, K views
  // per pass into layered targets, and read back in one transfer. Off (or
  // without layered rendering in the driver): one camera at a time.
  bool batch = true;
  // Views per batch. 4 by measurement on llvmpipe (docs/performance.md,
  // "Multi-view rendering"): batches of 4 cost what 4 single frames cost,
  // larger ones grew slower per view (2x at 36 views of 64x64).
  int max_batch_views = 4;
  // Memory bound of a batch: views * width * height (the targets take about
  // 28 bytes a pixel; 16 Mpx is 448 MB, 64 views of 512x512).
  std::int64_t max_batch_pixels = 16LL << 20;
  // Read-back of multi-view batches (above). Same frames either way
  // (tests/gl/test_multiview.cpp).
  Readback readback = Readback::kAuto;
  // Render at this fraction of the camera's width and height, then upscale to
  // the camera's size with a bilinear blit on the GPU ("upscale" pass); 1 =
  // native (no extra pass). The HDR buffer, if read, stays at the render size.
  // Scaled frames take the per-camera path (no multi-view batches).
  double resolution_scale = 1.0;
  // Single-camera frames (batch off): also read back these targets of the
  // plan (render size, RGBA float, rows top-down) into FrameResult::targets;
  // targets the plan does not use are skipped. For tests and benches.
  std::vector<TargetId> read_targets{};
  // The scene's photon maps, traced before the render on another thread
  // (trace_photons over GiScene(scene): what the render would trace itself;
  // Renderer::needs_photon_trace): used, and cached, in place of tracing.
  std::shared_ptr<const PhotonMaps> photon_maps{};
};

// The GPU work a frame was part of: a multi-view batch of `views` cameras, or
// a single camera (views = 1). Frames' own gpu_ms, readback_ms and pass times
// are their share (batch / views).
struct BatchTiming {
  int index = 0;  // batches in render order
  int views = 1;
  double gpu_ms = 0.0;
  double readback_ms = 0.0;  // readback_wait_ms + readback_copy_ms
  // submit_ms + readback_ms: a multi-view batch's completion runs after the
  // next batch's submission (Readback::kPipelined), which is not
  // counted here.
  double wall_ms = 0.0;
  std::vector<PassTiming> passes;
  // Where the batch's CPU (wall) time went: submit_ms issuing its passes (and,
  // pipelined, its read-back into a pixel buffer object); readback_wait_ms
  // waiting for the GPU to finish the passes and the transfer;
  // readback_copy_ms mapping the buffer and splitting the views into frames.
  // The single-camera path reads synchronously and counts its whole
  // read-back as wait. (After `passes`, so that positional initializers of
  // the fields above keep their meaning.)
  double submit_ms = 0.0;
  double readback_wait_ms = 0.0;
  double readback_copy_ms = 0.0;
};

struct FrameResult {
  Image image;            // tone-mapped, rows top-down
  HdrImage hdr;           // only with FrameOptions::read_hdr
  std::vector<PassTiming> passes;
  double gpu_ms = 0.0;       // whole frame on the GPU
  double readback_ms = 0.0;  // completing the read-back (batch share): wait + copy, wall clock
  double wall_ms = 0.0;      // the whole call for this camera, wall clock (batch share)
  BatchTiming batch;
  // Lit scenes: photons splatted, and the CPU time of this render call's
  // photon tracing (0 when the maps came from the cache) and upload.
  std::int64_t photons = 0;
  std::int64_t photon_disks = 0;  // the disks they were drawn as (gi.cluster)
  std::int64_t volume_photons = 0;  // scenes with a scattering medium: the volume map's
  double photon_trace_ms = 0.0;
  double photon_upload_ms = 0.0;
  // FrameOptions::read_targets: width x height x 4 floats each.
  std::map<TargetId, std::vector<float>> targets{};
  // SLIM surfaces: the sample slots the point passes processed (single-camera
  // frames; 0 in multi-view batches).
  std::int64_t slim_points = 0;
};

// The cameras' indices in the batches Renderer::render draws them in: cameras
// of one size in order of first appearance, at most opts.max_batch_views,
// device_max_views and opts.max_batch_pixels (at least one camera) per batch;
// one camera per batch without batching or with scaled frames. The server's
// scheduler slices renders by the same rule. No GL.
std::vector<std::vector<std::size_t>> camera_batches(const std::vector<Camera>& cameras,
                                                    const FrameOptions& opts,
                                                    int device_max_views = 64);  // kMaxBatchViews

struct SubmittedRender;  // renderer.cpp

class Renderer {
 public:
  // Creates the EGL context (throws std::runtime_error if none can be had).
  explicit Renderer(const RendererOptions& opts = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  const std::string& description() const;

  // Renders every camera of the scene; scene resources (tables, occluder
  // geometry) are uploaded once and shared by the cameras.
  std::vector<FrameResult> render(const Scene& scene, const FrameOptions& opts = {});
  // Renders the given cameras (which need not be the scene's own).
  // finish(submit(...)).
  std::vector<FrameResult> render(const Scene& scene, const std::vector<Camera>& cameras,
                                  const FrameOptions& opts = {});
  // Submits the cameras' passes and queues their read-back (pixel buffers
  // and fences); the frames come from finish(ticket). Submitting the next
  // render before finishing this one overlaps this one's GPU work and
  // transfer with the next one's submission. `scene` need only outlive
  // this call. Every ticket is finished (or the renderer destroyed); a
  // submit or finish that throws leaves no read-back of its render behind.
  std::uint64_t submit(const Scene& scene, const std::vector<Camera>& cameras,
                       const FrameOptions& opts = {});
  // The frames of a submitted render, its read-backs completed (waiting for
  // the GPU only as long as it has not finished them).
  std::vector<FrameResult> finish(std::uint64_t ticket);

  // Test hook (the server's context-rebuild test): the next render issues an
  // invalid GL call after uploading its scene and throws the GlError that
  // gl_check reports, as a driver fault mid-frame would.
  void fail_next_render_for_test();
  // Whether render(scene, cameras, opts) would trace photon maps (its passes
  // use them and this renderer's cache has none for the scene), so that a
  // caller may trace them on another thread first (FrameOptions::photon_maps).
  // No GL; on the renderer's thread, as render().
  bool needs_photon_trace(const Scene& scene, const FrameOptions& opts) const;
  // Gives back what the renderer keeps for the next frame beyond
  // `keep_photon_bytes` of photon maps (least recently used first): the
  // other photon maps, textures of volumes whose scene is gone, the frame
  // targets and read-back buffers. The next render re-creates what it needs.
  // For a server whose renderer has gone idle (RenderService).
  // The scene-content cache is kept down to the same bytes.
  void release_idle_memory(std::size_t keep_photon_bytes);
  // The scene-content cache's use (render/scene_resources.hpp).
  SceneGpuCache::Stats scene_cache_stats() const;

 private:
  // submit() with supersampling (false: the cameras as given).
  std::uint64_t submit(const Scene& scene, const std::vector<Camera>& cameras,
                       const FrameOptions& opts, bool supersample);
  void submit_cameras(const Scene& scene, const std::vector<Camera>& cameras,
                      const FrameOptions& opts, SubmittedRender& sub);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace beamcast
