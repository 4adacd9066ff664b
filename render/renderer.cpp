#include "render/renderer.hpp"

#include <GL/glcorearb.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "protocol/camera.hpp"
#include "protocol/cancel.hpp"
#include "protocol/turns.hpp"
#include "render/gl_util.hpp"
#include "render/gl_validate.hpp"
#include "render/passes.hpp"
#include "render/scene_resources.hpp"

namespace beamcast {

namespace {
double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

// Copies `views` images of w x h (GL rows bottom-up, RGB) from `src` into
// top-down frames.
template <class T, class Dst>
void split_views(const T* src, int w, int h, std::size_t first, std::size_t views, Dst dst) {
  const std::size_t row = 3 * static_cast<std::size_t>(w);
  for (std::size_t v = 0; v < views; ++v) {
    auto* out = dst(first + v);
    const T* layer = src + v * row * h;
    for (int y = 0; y < h; ++y) {
      std::copy(layer + (h - 1 - y) * row, layer + (h - y) * row, out + y * row);
    }
  }
}

// How long finishing a read-back waits for the GPU before it gives up (a
// device that has not finished a frame in this time has hung or been
// lost): the wait is made in steps of kFenceStepNs, between which a
// cancelled render (deadline, shutdown) stops waiting.
constexpr double kFenceLimitMs = 120'000.0;
constexpr GLuint64 kFenceStepNs = 50'000'000;  // 50 ms

// A render submitted by Renderer::submit: its plan and frames, filled in as
// its read-backs complete.
struct SubmittedRender {
  FramePlan plan;
  std::vector<FrameResult> frames;
  std::vector<int> batch_of;  // each frame's batch, in render order
};

// A read-back queued into a pixel buffer object with a fence after a frame's
// or multi-view batch's passes, not yet mapped. It is completed (fence
// waited, buffer mapped, views split into their frames) only when its slot
// is needed again or its render is finished, so the wait overlaps whatever
// was submitted since: the next camera or batch of the same render, or the
// next render.
struct PendingReadback {
  SubmittedRender* render = nullptr;
  std::vector<std::size_t> idx;  // frames of the batch
  int w = 0, h = 0;
  bool wide = false;  // 16-bit channels
  GLsync fence = nullptr;
  double submit_ms = 0.0;  // CPU time issuing the passes and the read-back
  PendingReadback() = default;
  PendingReadback(const PendingReadback&) = delete;
  PendingReadback& operator=(const PendingReadback&) = delete;
  ~PendingReadback() { clear(); }
  void clear() {
    if (fence) glDeleteSync(fence);
    fence = nullptr;
    render = nullptr;
  }
};

// A frame's timestamps (one before the first pass, one after each) and the
// time given to other renders in turns (protocol/turns.hpp) as each was
// issued: a pass's own time is its timestamps' difference less the turns
// between them.
struct PassStamps {
  std::vector<GlQuery> queries;
  std::vector<double> turn_ms;  // turn_ms_taken() when each query was issued
  double turns() const { return turn_ms.empty() ? 0.0 : turn_ms.back() - turn_ms.front(); }
};

struct Renderer::Impl {
  std::unique_ptr<EglContext> context;
  std::map<const PassDecl*, std::unique_ptr<Pass>> passes;  // by catalog row
  TableCache tables;
  PhotonCache photons;  // photon maps by what they depend on (gi/photon_cache.hpp)
  VolumeTextureCache volumes;  // volume textures across frames (render/volume_pass.hpp)
  SceneGpuCache scene_cache;   // uploads of scene content across renders
  FrameTargets targets;
  FrameTargets layered;  // multi-view batches
  GlVertexArray empty_vao;
  // Timestamps (frame start, then one after each pass), one set per read-back
  // slot: a slot's set is read when its read-back completes, before the slot
  // is used again.
  std::array<PassStamps, 2> query_sets;
  // Double-buffered pixel pack buffers and their read-backs in flight, by slot.
  std::array<GlBuffer, 2> pbos;
  std::array<std::size_t, 2> pbo_bytes{};
  std::array<PendingReadback, 2> in_flight;
  int next_slot = 0;
  // Submitted renders not yet finished, by ticket.
  std::map<std::uint64_t, std::unique_ptr<SubmittedRender>> submitted;
  std::uint64_t next_ticket = 1;
  int max_layers = 0;
  bool fail_next = false;  // fail_next_render_for_test()

  explicit Impl(const RendererOptions& opts)
      : context(EglContext::create(opts.egl)),
        tables(opts.table_cache_entries),
        scene_cache(opts.scene_cache_bytes) {
    const EglContext::Current current(*context);
    // One executor per catalog row: a row the renderer cannot run is an
    // error here, not a pass silently missing from frames.
    for (const PassDecl& decl : pass_catalog()) {
      std::unique_ptr<Pass> pass = decl.make ? decl.make() : nullptr;
      if (!pass) throw GlError("pass " + decl.name + " has no executor");
      passes[&decl] = std::move(pass);
    }
    GLuint id = 0;
    glCreateVertexArrays(1, &id);
    empty_vao = GlVertexArray(id);
    // Window depth in [0, 1] with reversed Z keeps float depth precise from
    // near to far.
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &max_layers);
    gl_check("renderer setup");
  }

  // Clears the plan's targets and runs its passes, with a timestamp before
  // the first and after each (plan.passes.size() + 1 queries).
  void run_passes(const Scene& scene, FrameContext& ctx, PassStamps& stamps) {
    const FramePlan& plan = ctx.plan;
    std::vector<GlQuery>& queries = stamps.queries;
    while (queries.size() < plan.passes.size() + 1) {
      GLuint id = 0;
      glGenQueries(1, &id);
      queries.emplace_back(id);
    }
    stamps.turn_ms.assign(plan.passes.size() + 1, 0.0);
    glDepthMask(GL_TRUE);
    glQueryCounter(queries[0].get(), GL_TIMESTAMP);
    stamps.turn_ms[0] = turn_ms_taken();
    ctx.targets.clear(plan, scene.background);
    for (std::size_t i = 0; i < plan.passes.size(); ++i) {
      const PassDecl& decl = *plan.passes[i];
      const GlPassLabel label(decl.name);
      passes.at(&decl)->execute(ctx, decl);
      glQueryCounter(queries[i + 1].get(), GL_TIMESTAMP);
      stamps.turn_ms[i + 1] = turn_ms_taken();
      // Between passes a long frame may give waiting renders a turn
      // (protocol/turns.hpp): its own commands complete first, so the turn's
      // time is the other render's (taken out of the next pass's time).
      // Where turns may be taken each pass is flushed, so that a software
      // rasterizer, which draws at a flush, draws it now and the time since
      // the last turn counts it.
      if (i + 1 < plan.passes.size() && turn_hook_installed()) {
        glFlush();
        turn_point([] { glFinish(); });
      }
    }
    gl_check("frame");
  }

  // Pass times of the last run_passes (waits for the GPU).
  BatchTiming read_timings(const FramePlan& plan, const PassStamps& st) {
    std::vector<GLuint64> stamps(plan.passes.size() + 1);
    for (std::size_t i = 0; i < stamps.size(); ++i) {
      glGetQueryObjectui64v(st.queries[i].get(), GL_QUERY_RESULT, &stamps[i]);
    }
    BatchTiming t;
    for (std::size_t i = 0; i < plan.passes.size(); ++i) {
      const double turns = st.turn_ms[i + 1] - st.turn_ms[i];
      t.passes.push_back(
          {plan.passes[i]->name, std::max(0.0, (stamps[i + 1] - stamps[i]) * 1e-6 - turns)});
    }
    t.gpu_ms = std::max(0.0, (stamps.back() - stamps.front()) * 1e-6 - st.turns());
    return t;
  }

  // The next read-back slot, its earlier read-back completed first (its
  // timestamp queries and pixel buffer are about to be reused).
  int take_slot() {
    const int slot = next_slot;
    next_slot ^= 1;
    complete_slot(slot);
    return slot;
  }

  // Whether `queue` asks for the synchronous read (completed as soon as issued).
  static bool synchronous(const FrameOptions& opts) {
    return opts.readback == Readback::kSynchronous;
  }

  void render_camera(const Scene& scene, const Camera& full_cam, SceneResources& res,
                     SubmittedRender& sub, std::size_t index, const FrameOptions& opts) {
    const auto wall0 = std::chrono::steady_clock::now();
    const FramePlan& plan = sub.plan;
    const int slot = take_slot();
    FrameResult& result = sub.frames[index];
    // A scaled frame renders a smaller copy of the camera (same view, fewer pixels).
    Camera small = full_cam;
    if (PlanInput{scene, opts.resolution_scale}.scaled()) {
      small.width = std::max(1, static_cast<int>(std::lround(full_cam.width * opts.resolution_scale)));
      small.height =
          std::max(1, static_cast<int>(std::lround(full_cam.height * opts.resolution_scale)));
    }
    const Camera& cam = small;
    const CameraBasis basis = camera_basis(cam);
    res.bind_camera(cam, basis);
    targets.ensure(plan, cam.width, cam.height, full_cam.width, full_cam.height,
                   scene.output.bit_depth);
    glViewport(0, 0, cam.width, cam.height);
    glBindBufferBase(GL_UNIFORM_BUFFER, 0, res.camera_buffer());
    FrameContext ctx{scene,           plan, cam, basis, res, targets, empty_vao.get(), 0,
                     full_cam.width, full_cam.height, {}};
    run_passes(scene, ctx, query_sets[static_cast<std::size_t>(slot)]);
    if (res.slim() && !res.slim()->slots().empty()) result.slim_points = res.slim()->slots()[0];

    // The last pass's framebuffer holds the final target at attachment 0.
    const bool wide = scene.output.bit_depth == 16;
    const int w = full_cam.width, h = full_cam.height;
    const std::size_t bytes = 3 * static_cast<std::size_t>(w) * h * (wide ? 2 : 1);
    bind_pack_buffer(slot, bytes);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, targets.fbo(*plan.passes.back(), -1));
    // With a pack buffer bound, the pointer argument is an offset into it.
    glReadnPixels(0, 0, w, h, GL_RGB, wide ? GL_UNSIGNED_SHORT : GL_UNSIGNED_BYTE,
                  static_cast<GLsizei>(bytes), nullptr);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    gl_check("glReadnPixels(output into PBO)");
    fence_slot(slot, sub, {index}, w, h, wide, wall0);
    if (!synchronous(opts) && !opts.read_hdr && opts.read_targets.empty()) return;
    complete_slot(slot);

    if (opts.read_hdr) {
      // The HDR buffer stays at the render size.
      const int hw = cam.width, hh = cam.height;
      const std::size_t hrow = 3 * static_cast<std::size_t>(hw);
      result.hdr.width = hw;
      result.hdr.height = hh;
      std::vector<float> buf(hrow * hh);
      glGetTextureImage(targets.texture(TargetId::kHdr), 0, GL_RGB, GL_FLOAT,
                        static_cast<GLsizei>(buf.size() * sizeof(float)), buf.data());
      gl_check("glGetTextureImage(hdr)");
      result.hdr.rgb.resize(buf.size());
      for (int y = 0; y < hh; ++y) {
        std::memcpy(&result.hdr.rgb[y * hrow], &buf[(hh - 1 - y) * hrow], hrow * sizeof(float));
      }
    }

    for (const TargetId name : opts.read_targets) {
      // Debug and bench read-back of targets (RGBA float, top-down).
      if (!plan.uses(name)) continue;  // not in this frame's plan
      const GLuint tex = targets.texture(name);
      const int tw = cam.width, th = cam.height;
      const std::size_t trow = 4 * static_cast<std::size_t>(tw);
      std::vector<float> buf(trow * th);
      glGetTextureImage(tex, 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(buf.size() * sizeof(float)),
                        buf.data());
      gl_check("glGetTextureImage(read_targets)");
      std::vector<float>& out = result.targets[name];
      out.resize(buf.size());
      for (int y = 0; y < th; ++y) {
        std::memcpy(&out[y * trow], &buf[(th - 1 - y) * trow], trow * sizeof(float));
      }
    }
  }

  // Renders cameras[idx[0..]] (all one size) in one multi-view pass set and
  // queues every view's read-back into a pixel pack buffer with a fence
  // (completed later by complete_slot); Readback::kSynchronous reads into
  // client memory at once instead. With read_hdr the batch is completed at
  // once (the HDR read-back is synchronous).
  void render_batch(const Scene& scene, const std::vector<Camera>& cameras,
                    const std::vector<std::size_t>& idx, SceneResources& res,
                    SubmittedRender& sub, const FrameOptions& opts) {
    const auto wall0 = std::chrono::steady_clock::now();
    const FramePlan& plan = sub.plan;
    const std::size_t k = idx.size();
    std::vector<Camera> cams;
    std::vector<CameraBasis> bases;
    for (std::size_t i : idx) {
      cams.push_back(cameras[i]);
      bases.push_back(camera_basis(cameras[i]));
    }
    const int w = cams[0].width, h = cams[0].height;
    const int slot = take_slot();
    res.bind_views(cams, bases, kMaxBatchViews);
    layered.ensure(plan, w, h, w, h, scene.output.bit_depth, static_cast<int>(k));
    glViewport(0, 0, w, h);
    glBindBufferBase(GL_UNIFORM_BUFFER, 0, res.views_camera_buffer());
    FrameContext ctx{scene, plan, cams[0], bases[0], res, layered, empty_vao.get(),
                     static_cast<int>(k), w, h, {}};
    for (const CameraBasis& b : bases) ctx.view_eyes.push_back(b.eye);
    ctx.view_cameras = &cams;
    ctx.view_bases = &bases;
    run_passes(scene, ctx, query_sets[static_cast<std::size_t>(slot)]);

    const bool wide = scene.output.bit_depth == 16;
    if (synchronous(opts)) {
      read_batch_now(plan, sub.frames, idx, w, h, wide, slot,
                     ms_since(wall0) - query_sets[static_cast<std::size_t>(slot)].turns());
    } else {
      const std::size_t bytes = 3 * static_cast<std::size_t>(w) * h * k * (wide ? 2 : 1);
      bind_pack_buffer(slot, bytes);
      // With a pack buffer bound, the pointer argument is an offset into it.
      glGetTextureImage(layered.texture(plan.final_target), 0, GL_RGB,
                        wide ? GL_UNSIGNED_SHORT : GL_UNSIGNED_BYTE, static_cast<GLsizei>(bytes),
                        nullptr);
      glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
      gl_check("glGetTextureImage(output layers into PBO)");
      fence_slot(slot, sub, idx, w, h, wide, wall0);
    }
    if (opts.read_hdr) {
      complete_slot(slot);
      std::vector<float> all(3 * static_cast<std::size_t>(w) * h * k);
      glGetTextureImage(layered.texture(TargetId::kHdr), 0, GL_RGB, GL_FLOAT,
                        static_cast<GLsizei>(all.size() * sizeof(float)), all.data());
      gl_check("glGetTextureImage(hdr layers)");
      for (std::size_t v = 0; v < k; ++v) {
        HdrImage& hdr = sub.frames[idx[v]].hdr;
        hdr.width = w;
        hdr.height = h;
        hdr.rgb.resize(3 * static_cast<std::size_t>(w) * h);
      }
      split_views(all.data(), w, h, 0, k,
                  [&](std::size_t v) { return sub.frames[idx[v]].hdr.rgb.data(); });
    }
  }

  // Gives the frames of a batch their images' size and depth.
  static void size_frames(std::vector<FrameResult>& frames, const std::vector<std::size_t>& idx,
                          int w, int h, bool wide) {
    for (std::size_t i : idx) {
      FrameResult& f = frames[i];
      f.image.width = w;
      f.image.height = h;
      f.image.bit_depth = wide ? 16 : 8;
      f.image.rgb.resize(3 * static_cast<std::size_t>(w) * h);
    }
  }

  // The synchronous read-back of a batch (Readback::kSynchronous):
  // glGetTextureImage into client memory waits for the passes, then
  // transfers every layer.
  void read_batch_now(const FramePlan& plan, std::vector<FrameResult>& frames,
                      const std::vector<std::size_t>& idx, int w, int h, bool wide, int slot,
                      double submit_ms) {
    const std::size_t k = idx.size();
    const std::size_t n = 3 * static_cast<std::size_t>(w) * h * k;
    const auto rb0 = std::chrono::steady_clock::now();
    size_frames(frames, idx, w, h, wide);
    auto image_of = [&](std::size_t v) { return frames[idx[v]].image.rgb.data(); };
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    double wait_ms = 0.0;
    if (wide) {
      std::vector<std::uint16_t> all(n);
      glGetTextureImage(layered.texture(plan.final_target), 0, GL_RGB, GL_UNSIGNED_SHORT,
                        static_cast<GLsizei>(all.size() * 2), all.data());
      wait_ms = ms_since(rb0);
      split_views(all.data(), w, h, 0, k, image_of);
    } else {
      std::vector<std::uint8_t> all(n);
      glGetTextureImage(layered.texture(plan.final_target), 0, GL_RGB, GL_UNSIGNED_BYTE,
                        static_cast<GLsizei>(all.size()), all.data());
      wait_ms = ms_since(rb0);
      split_views(all.data(), w, h, 0, k, image_of);
    }
    gl_check("glGetTextureImage(output layers)");
    const double readback_ms = ms_since(rb0);
    set_batch_timing(plan, frames, idx, slot, submit_ms, wait_ms, readback_ms - wait_ms);
  }

  // Binds the slot's pixel pack buffer for a transfer of `bytes`. The buffer's
  // old contents are dead (its read-back was completed by take_slot): a
  // larger transfer re-specifies its storage, a smaller one invalidates it,
  // so the driver never keeps old contents or waits for them.
  void bind_pack_buffer(int slot, std::size_t bytes) {
    const auto s = static_cast<std::size_t>(slot);
    if (!pbos[s].get()) {
      GLuint id = 0;
      glCreateBuffers(1, &id);
      pbos[s] = GlBuffer(id);
      pbo_bytes[s] = 0;
    }
    if (pbo_bytes[s] < bytes) {
      glNamedBufferData(pbos[s].get(), static_cast<GLsizeiptr>(bytes), nullptr, GL_STREAM_READ);
      pbo_bytes[s] = bytes;
    } else {
      glInvalidateBufferData(pbos[s].get());
    }
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, pbos[s].get());
  }

  // After a transfer into the slot's buffer: a fence behind it, and the
  // queued work started now (a fence waited on with
  // GL_SYNC_FLUSH_COMMANDS_BIT would flush only at the wait).
  void fence_slot(int slot, SubmittedRender& sub, std::vector<std::size_t> idx, int w, int h,
                  bool wide, std::chrono::steady_clock::time_point wall0) {
    PendingReadback& p = in_flight[static_cast<std::size_t>(slot)];
    p.fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    glFlush();
    gl_check("glFenceSync(read-back)");
    p.render = &sub;
    p.idx = std::move(idx);
    p.w = w;
    p.h = h;
    p.wide = wide;
    p.submit_ms = ms_since(wall0) - query_sets[static_cast<std::size_t>(slot)].turns();
  }

  // Waits for a fence in bounded steps (kFenceStepNs), up to kFenceLimitMs;
  // a cancelled render stops waiting between steps.
  static void wait_fence(GLsync fence) {
    const auto t0 = std::chrono::steady_clock::now();
    GLbitfield flags = GL_SYNC_FLUSH_COMMANDS_BIT;
    for (;;) {
      const GLenum r = glClientWaitSync(fence, flags, kFenceStepNs);
      if (r == GL_ALREADY_SIGNALED || r == GL_CONDITION_SATISFIED) return;
      if (r == GL_WAIT_FAILED) {
        gl_check("glClientWaitSync(read-back)");
        throw GlError("glClientWaitSync(read-back) failed");
      }
      flags = 0;  // flushed by the first call
      check_cancel();
      if (ms_since(t0) > kFenceLimitMs) {
        throw GlError("the GPU did not finish a frame in " +
                      std::to_string(std::lround(kFenceLimitMs / 1000.0)) + " s");
      }
    }
  }

  // Completes the slot's read-back, if one is in flight: waits for its fence
  // (the passes and the transfer), maps its buffer, splits the views into
  // their frames and reads its timestamps.
  void complete_slot(int slot) {
    PendingReadback& p = in_flight[static_cast<std::size_t>(slot)];
    if (!p.fence) return;
    const auto wait0 = std::chrono::steady_clock::now();
    wait_fence(p.fence);
    glDeleteSync(p.fence);
    p.fence = nullptr;
    const double wait_ms = ms_since(wait0);

    const auto copy0 = std::chrono::steady_clock::now();
    const std::size_t k = p.idx.size();
    const std::size_t bytes = 3 * static_cast<std::size_t>(p.w) * p.h * k * (p.wide ? 2 : 1);
    const GLuint pbo = pbos[static_cast<std::size_t>(slot)].get();
    const void* mapped =
        glMapNamedBufferRange(pbo, 0, static_cast<GLsizeiptr>(bytes), GL_MAP_READ_BIT);
    if (!mapped) {
      gl_check("glMapNamedBufferRange(read-back)");
      throw GlError("glMapNamedBufferRange(read-back) returned null");
    }
    std::vector<FrameResult>& frames = p.render->frames;
    size_frames(frames, p.idx, p.w, p.h, p.wide);
    auto image_of = [&](std::size_t v) { return frames[p.idx[v]].image.rgb.data(); };
    if (p.wide) {
      split_views(static_cast<const std::uint16_t*>(mapped), p.w, p.h, 0, k, image_of);
    } else {
      split_views(static_cast<const std::uint8_t*>(mapped), p.w, p.h, 0, k, image_of);
    }
    glUnmapNamedBuffer(pbo);
    gl_check("glUnmapNamedBuffer(read-back)");
    set_batch_timing(p.render->plan, frames, p.idx, slot, p.submit_ms, wait_ms, ms_since(copy0));
    p.clear();
  }

  // Completes the read-backs in flight of one submitted render (all: null).
  void complete_render(const SubmittedRender* sub) {
    for (int s = 0; s < 2; ++s) {
      if (in_flight[static_cast<std::size_t>(s)].fence &&
          (!sub || in_flight[static_cast<std::size_t>(s)].render == sub)) {
        complete_slot(s);
      }
    }
  }

  // Forgets a submitted render's read-backs in flight (after an error).
  void abandon(const SubmittedRender* sub) {
    for (PendingReadback& p : in_flight) {
      if (p.render == sub) p.clear();
    }
  }

  // The batch's timing (GPU timestamps from its query set, the CPU split),
  // shared out to its frames.
  void set_batch_timing(const FramePlan& plan, std::vector<FrameResult>& frames,
                        const std::vector<std::size_t>& idx, int slot, double submit_ms,
                        double wait_ms, double copy_ms) {
    const std::size_t k = idx.size();
    BatchTiming batch = read_timings(plan, query_sets[static_cast<std::size_t>(slot)]);
    batch.views = static_cast<int>(k);
    batch.submit_ms = submit_ms;
    batch.readback_wait_ms = wait_ms;
    batch.readback_copy_ms = copy_ms;
    batch.readback_ms = wait_ms + copy_ms;
    // The batch's own CPU time: its submission and its completion (not
    // what was submitted in between, which accounts for itself).
    batch.wall_ms = submit_ms + batch.readback_ms;
    const double share = 1.0 / static_cast<double>(k);
    for (std::size_t v = 0; v < k; ++v) {
      FrameResult& f = frames[idx[v]];
      f.batch = batch;
      f.gpu_ms = batch.gpu_ms * share;
      f.readback_ms = batch.readback_ms * share;
      f.wall_ms = batch.wall_ms * share;
      f.passes = batch.passes;
      for (PassTiming& pt : f.passes) pt.gpu_ms *= share;
    }
  }
};

Renderer::Renderer(const RendererOptions& opts) : impl_(std::make_unique<Impl>(opts)) {}

Renderer::~Renderer() {
  if (!impl_) return;
  // The GL names are deleted in their own context, which goes last.
  const std::unique_ptr<EglContext> context = std::move(impl_->context);
  const EglContext::Current current(*context);
  impl_.reset();
}

const std::string& Renderer::description() const { return impl_->context->description(); }

void Renderer::fail_next_render_for_test() { impl_->fail_next = true; }

SceneGpuCache::Stats Renderer::scene_cache_stats() const { return impl_->scene_cache.stats(); }

void Renderer::release_idle_memory(std::size_t keep_photon_bytes) {
  Impl& m = *impl_;
  const EglContext::Current current(*m.context);
  m.complete_render(nullptr);  // the pixel buffers are about to go
  m.photons.shrink_to(keep_photon_bytes);
  m.scene_cache.shrink_to(keep_photon_bytes);
  m.volumes.drop_unused();
  m.targets = FrameTargets();
  m.layered = FrameTargets();
  for (std::size_t i = 0; i < m.pbos.size(); ++i) {
    m.pbos[i] = GlBuffer();
    m.pbo_bytes[i] = 0;
  }
  glFinish();  // the driver frees deleted objects once no command uses them
  gl_check("release_idle_memory");
}

std::vector<FrameResult> Renderer::render(const Scene& scene, const FrameOptions& opts) {
  return render(scene, scene.cameras, opts);
}

static_assert(kMaxBatchViews == 64, "camera_batches' default in renderer.hpp");

std::vector<std::vector<std::size_t>> camera_batches(const std::vector<Camera>& cameras,
                                                    const FrameOptions& opts,
                                                    int device_max_views) {
  std::vector<std::vector<std::size_t>> batches;
  const bool scaled = opts.resolution_scale > 0.0 && opts.resolution_scale < 1.0;
  if (!opts.batch || scaled) {
    for (std::size_t i = 0; i < cameras.size(); ++i) batches.push_back({i});
    return batches;
  }
  std::vector<std::pair<int, int>> sizes;
  std::vector<std::vector<std::size_t>> groups;
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    const std::pair<int, int> size{cameras[i].width, cameras[i].height};
    auto it = std::find(sizes.begin(), sizes.end(), size);
    if (it == sizes.end()) {
      sizes.push_back(size);
      groups.emplace_back();
      it = sizes.end() - 1;
    }
    groups[static_cast<std::size_t>(it - sizes.begin())].push_back(i);
  }
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const std::int64_t pixels = static_cast<std::int64_t>(sizes[g].first) * sizes[g].second;
    const std::size_t cap = static_cast<std::size_t>(std::max<std::int64_t>(
        1, std::min<std::int64_t>({opts.max_batch_views, device_max_views,
                                   opts.max_batch_pixels / std::max<std::int64_t>(1, pixels)})));
    for (std::size_t at = 0; at < groups[g].size(); at += cap) {
      const std::size_t end = std::min(groups[g].size(), at + cap);
      batches.emplace_back(groups[g].begin() + static_cast<std::ptrdiff_t>(at),
                           groups[g].begin() + static_cast<std::ptrdiff_t>(end));
    }
  }
  return batches;
}

namespace {

// The mean of each k x k block of `big` (k times hdr's size each way).
HdrImage box_downsample(const HdrImage& big, int k) {
  HdrImage small;
  small.width = big.width / k;
  small.height = big.height / k;
  small.rgb.assign(3 * static_cast<std::size_t>(small.width) * small.height, 0.0f);
  const double scale = 1.0 / (k * k);
  for (int y = 0; y < small.height; ++y) {
    for (int x = 0; x < small.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        double sum = 0.0;
        for (int dy = 0; dy < k; ++dy) {
          const float* row = &big.rgb[3 * ((static_cast<std::size_t>(y) * k + dy) * big.width)];
          for (int dx = 0; dx < k; ++dx) sum += row[3 * (x * k + dx) + c];
        }
        small.rgb[3 * (static_cast<std::size_t>(y) * small.width + x) + c] =
            static_cast<float>(sum * scale);
      }
    }
  }
  return small;
}

}  // namespace

bool Renderer::needs_photon_trace(const Scene& scene, const FrameOptions& opts) const {
  if (opts.photon_maps || scene.lights.empty()) return false;
  const FramePlan plan = make_plan(PlanInput{scene, opts.resolution_scale});
  const bool uses = plan.uploads_group(UploadGroup::kPhotons) ||
                    plan.uploads_group(UploadGroup::kVolumePhotons) ||
                    plan.uploads_group(UploadGroup::kSpecular);
  return uses && !impl_->photons.holds(photon_key(scene));
}

std::vector<FrameResult> Renderer::render(const Scene& scene, const std::vector<Camera>& cameras,
                                          const FrameOptions& opts) {
  const EglContext::Current current(*impl_->context);
  const int k = scene.output.supersample;
  // Supersampled: every camera at k times the size, its HDR box-filtered
  // back and tone-mapped here (render/image.hpp's tone_map, the same curve
  // as the tonemap pass). Frames of a preview's lower resolution scale skip
  // it: they are a moving camera's quick frames.
  if (k <= 1 || PlanInput{scene, opts.resolution_scale}.scaled()) {
    return finish(submit(scene, cameras, opts));
  }
  std::vector<Camera> big = cameras;
  for (Camera& c : big) {
    c.width *= k;
    c.height *= k;
  }
  FrameOptions o = opts;
  o.read_hdr = true;
  std::vector<FrameResult> frames = finish(submit(scene, big, o, false));
  for (FrameResult& f : frames) {
    const auto t0 = std::chrono::steady_clock::now();
    f.hdr = box_downsample(f.hdr, k);
    f.image = tone_map(f.hdr, scene.output);
    if (!opts.read_hdr) f.hdr = {};
    f.wall_ms += ms_since(t0);
  }
  return frames;
}

std::uint64_t Renderer::submit(const Scene& scene, const std::vector<Camera>& cameras,
                               const FrameOptions& opts) {
  return submit(scene, cameras, opts, true);
}

std::uint64_t Renderer::submit(const Scene& scene, const std::vector<Camera>& cameras,
                               const FrameOptions& opts, bool supersample) {
  const EglContext::Current current(*impl_->context);
  Impl& m = *impl_;
  // Maps traced before the render (FrameOptions::photon_maps) are taken by
  // the photon cache in place of tracing; offered for this call only. Every
  // render, render() included, uploads its photons here.
  struct Offer {
    PhotonCache& cache;
    ~Offer() { cache.offer({}, nullptr); }
  } offer{m.photons};
  if (opts.photon_maps) m.photons.offer(photon_key(scene), opts.photon_maps);
  const std::uint64_t ticket = m.next_ticket++;
  auto sub = std::make_unique<SubmittedRender>();
  SubmittedRender& r = *sub;
  m.submitted.emplace(ticket, std::move(sub));
  try {
    if (supersample && scene.output.supersample > 1 && !PlanInput{scene, opts.resolution_scale}.scaled()) {
      // Supersampled frames are finished here (their HDR read-back is synchronous).
      r.frames = render(scene, cameras, opts);
    } else {
      submit_cameras(scene, cameras, opts, r);
    }
  } catch (...) {
    m.abandon(&r);
    m.submitted.erase(ticket);
    throw;
  }
  return ticket;
}

std::vector<FrameResult> Renderer::finish(std::uint64_t ticket) {
  const EglContext::Current current(*impl_->context);
  Impl& m = *impl_;
  const auto it = m.submitted.find(ticket);
  if (it == m.submitted.end()) throw GlError("finish: no submitted render " + std::to_string(ticket));
  const std::unique_ptr<SubmittedRender> sub = std::move(it->second);
  m.submitted.erase(it);
  try {
    m.complete_render(sub.get());
  } catch (...) {
    m.abandon(sub.get());
    throw;
  }
  for (std::size_t i = 0; i < sub->batch_of.size(); ++i) {
    sub->frames[i].batch.index = sub->batch_of[i];
  }
  return std::move(sub->frames);
}

void Renderer::submit_cameras(const Scene& scene, const std::vector<Camera>& cameras,
                              const FrameOptions& opts, SubmittedRender& sub) {
  sub.plan = make_plan(PlanInput{scene, opts.resolution_scale});
  const FramePlan& plan = sub.plan;
  SceneResources res(scene, impl_->tables, plan, &impl_->photons, &impl_->volumes,
                     &impl_->scene_cache);
  if (std::exchange(impl_->fail_next, false)) {
    // Out of KHR_debug's sight: the tests fail on any driver-reported error
    // they did not plant themselves; this one is planted, and glGetError
    // still reports it.
    const GLboolean debug_output = glIsEnabled(GL_DEBUG_OUTPUT);
    glDisable(GL_DEBUG_OUTPUT);
    glEnable(0);  // GL_INVALID_ENUM
    if (debug_output) glEnable(GL_DEBUG_OUTPUT);
    gl_check("glEnable(0) (injected test failure)");
  }
  std::vector<FrameResult>& frames = sub.frames;
  frames.assign(cameras.size(), FrameResult{});
  const std::vector<std::vector<std::size_t>> batches =
      camera_batches(cameras, opts, std::min(kMaxBatchViews, impl_->max_layers));
  // Every camera or batch's read-back is queued into a pixel buffer with a
  // fence and completed when its slot comes round again (two batches
  // later) or in finish(): the CPU never waits for the frame it has just
  // submitted.
  for (const auto& idx : batches) {
    if (idx.size() == 1) {
      impl_->render_camera(scene, cameras[idx[0]], res, sub, idx[0], opts);
    } else {
      impl_->render_batch(scene, cameras, idx, res, sub, opts);
    }
  }
  sub.batch_of.assign(cameras.size(), 0);
  for (std::size_t b = 0; b < batches.size(); ++b) {
    for (std::size_t i : batches[b]) sub.batch_of[i] = static_cast<int>(b);
  }
  for (FrameResult& f : frames) {
    f.photons = res.photons_kept();
    f.photon_disks = res.photon_count();
    f.volume_photons = res.volume_count();
    f.photon_trace_ms = res.photon_trace_ms();
    f.photon_upload_ms = res.photon_upload_ms();
  }
}

}  // namespace beamcast
