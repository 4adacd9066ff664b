// Render work: a bounded queue, worker threads that each own a renderer (and
// so a GL context), and a CPU pool that encodes frames to PNG in parallel.
// Sockets never reach here; GL never leaves the renderer behind FrameRenderer.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/thread_pool.hpp>

#include "server/threads.hpp"

#include "protocol/errors.hpp"
#include "protocol/scene.hpp"
#include "render/atlas.hpp"
#include "render/renderer.hpp"

namespace beamcast {

// What the service needs of a renderer; the GL one is the real thing, tests
// may substitute another.
class FrameRenderer {
 public:
  virtual ~FrameRenderer() = default;
  virtual std::string description() const = 0;
  virtual std::vector<FrameResult> render(const Scene& scene, const std::vector<Camera>& cameras) = 0;
  // With frame options (resolution scale); a renderer without them ignores them.
  virtual std::vector<FrameResult> render(const Scene& scene, const std::vector<Camera>& cameras,
                                          const FrameOptions& options) {
    (void)options;
    return render(scene, cameras);
  }
  // Test hook (RenderService::fail_next_render_for_test): the next render
  // throws GlError from inside the renderer.
  virtual void fail_next_render_for_test() = 0;
};

// Called on each worker thread, so a GL context is created on the thread that uses it.
using RendererFactory = std::function<std::unique_ptr<FrameRenderer>()>;
// The GPU renderer (render/) behind the interface.
RendererFactory gl_renderer_factory(const RendererOptions& opts);

struct RenderOutcome {
  bool dropped = false;  // the client went away before the job reached the GPU
  std::optional<ErrorInfo> error;
  std::vector<FrameResult> frames;  // images released after encoding
  std::vector<std::vector<std::uint8_t>> pngs;  // encoded frames (JPEG when RenderJob::jpeg)
  std::vector<char> is_jpeg;      // per frame: 1 if encoded as JPEG
  std::vector<double> encode_ms;  // per frame
  double queue_ms = 0.0;
  double render_ms = 0.0;
  double encode_wall_ms = 0.0;
  // Cross-request batching (RenderService::set_batch_window): how many
  // requests and views shared this job's render call (1 and its own cameras'
  // count when it rendered alone).
  int batched_requests = 1;
  int batched_views = 0;
  // With RenderJob::atlas: the layout (its image released after encoding);
  // `pngs` then holds the one atlas PNG.
  std::optional<Atlas> atlas;
};

struct RenderJob {
  std::shared_ptr<const Scene> scene;
  std::vector<Camera> cameras;
  FrameOptions options;    // resolution scale of `quality: "auto"` frames
  bool jpeg = false;       // encode as JPEG (interactive frames) instead of PNG
  int jpeg_quality = 90;
  std::shared_ptr<const std::atomic<bool>> client_alive;
  std::chrono::steady_clock::time_point arrived;
  // Jobs with the same non-null key (one stored scene, unmodified) that arrive
  // within the batch window are rendered in one call; null: never merged.
  const void* batch_key = nullptr;
  bool atlas = false;  // encode the frames as one atlas image (render/atlas.hpp)
  // Called exactly once, on a worker or encoder thread.
  std::function<void(RenderOutcome&&)> done;
};

class RenderService {
 public:
  RenderService(RendererFactory factory, int workers, int encode_threads, int png_level,
                int png_filters, int max_inflight);
  ~RenderService();

  // Blocks until every worker has a renderer (or failed to get one); returns
  // the first renderer's description, throws if none could be created.
  std::string wait_ready();

  // Batching across requests: a worker that takes a job with a batch key waits
  // until `window` after the job's arrival and renders every queued job of the
  // same key with it, up to `max_views` cameras in all. 0 (default): off, each
  // job renders as soon as a worker is free.
  void set_batch_window(std::chrono::milliseconds window, int max_views);

  // False if `max_inflight` jobs are already accepted and unanswered (busy).
  bool submit(RenderJob job);
  int inflight() const { return inflight_.load(); }
  int queued() const;
  // Jobs dropped because their client had gone (never rendered).
  std::uint64_t dropped() const { return dropped_.load(); }
  // Renderers discarded and recreated after a render threw GlError: a GL
  // error leaves the context in an unknown state, so the worker answers the
  // failed jobs `internal` and builds a new renderer (a new EGL context)
  // before it takes the next job.
  std::uint64_t renderer_rebuilds() const { return rebuilds_.load(); }
  // Test hook, compiled in always and reached only from tests: the next render
  // (on whichever worker takes it) fails with a real GL error
  // (Renderer::fail_next_render_for_test).
  void fail_next_render_for_test() { inject_failures_.fetch_add(1); }
  // Stops the workers; jobs still queued are dropped (their `done` is called
  // with dropped = true).
  void stop();

 private:
  void worker_main(int index);
  // Creates a renderer on the calling (worker) thread; null, with the reason
  // in failure_, if it cannot.
  std::unique_ptr<FrameRenderer> make_renderer(int index);
  void finish(RenderJob& job, RenderOutcome&& outcome);
  // Takes the queued jobs that may join `first` (same batch key) once its
  // window has passed; called with `lock` held, may wait on it.
  std::vector<RenderJob> gather_batch(RenderJob first, std::unique_lock<std::mutex>& lock);
  void encode_and_finish(RenderJob job, RenderOutcome out);

  RendererFactory factory_;
  int png_level_;
  int png_filters_;
  int max_inflight_;
  std::chrono::milliseconds batch_window_{0};
  int batch_max_views_ = 64;
  std::atomic<int> inflight_{0};
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<std::uint64_t> rebuilds_{0};
  std::atomic<int> inject_failures_{0};
  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::condition_variable window_cv_;  // batch windows wait here (stop() wakes them)
  std::deque<RenderJob> queue_;
  bool stopping_ = false;
  int ready_ = 0;
  std::string description_;
  std::string failure_;
  std::condition_variable ready_cv_;
  std::vector<SizedThread> workers_;  // each owns a GL context
  boost::asio::thread_pool encoders_;
};

}  // namespace beamcast
