// Render work: a bounded set of admitted jobs, worker threads that each own a
// renderer (and so a GL context), and a CPU pool that encodes frames to PNG in
// parallel. A job is rendered in slices of at most FrameOptions::max_batch_views
// cameras (one GPU batch each); each slice's frames are encoded while the next
// slice renders, and between slices the scheduler picks what runs next:
// interactive work before batch work, connections of one class by the render
// time each has used, and a job whose client has gone stops (PROTOCOL.md,
// "Scheduling"). A job's photon tracing runs before its first slice on a CPU
// pool of its own, off the render workers, which serve other jobs meanwhile.
// Sockets never reach here; GL never leaves the renderer behind FrameRenderer.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/thread_pool.hpp>
#include <nlohmann/json.hpp>

#include "server/threads.hpp"

#include "protocol/errors.hpp"
#include "protocol/frame_format.hpp"
#include "protocol/scene.hpp"
#include "render/atlas.hpp"
#include "render/image.hpp"
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
  // Two steps (Renderer::submit and finish): the service submits a slice,
  // then the next one when more work is queued, and only then finishes the
  // first, so a GPU's work and read-back overlap the next submission. A
  // renderer without them renders in submit().
  virtual std::uint64_t submit(const Scene& scene, const std::vector<Camera>& cameras,
                               const FrameOptions& options) {
    const std::uint64_t ticket = next_ticket_++;
    done_[ticket] = render(scene, cameras, options);
    return ticket;
  }
  // Whether submit() returns with the frames still in flight (a GPU's work
  // and read-back), so that finishing the slice after the next submission
  // overlaps them; false (the default): submit() renders, and each slice is
  // finished at once (a later submission would only hold its frames back).
  virtual bool overlaps() const { return false; }
  virtual std::vector<FrameResult> finish(std::uint64_t ticket) {
    const auto it = done_.find(ticket);
    if (it == done_.end()) throw std::logic_error("finish: unknown ticket");
    std::vector<FrameResult> frames = std::move(it->second);
    done_.erase(it);
    return frames;
  }
  // Test hook (RenderService::fail_next_render_for_test): the next render
  // throws GlError from inside the renderer.
  virtual void fail_next_render_for_test() = 0;
  // Whether render(scene, cameras, options) would trace photon maps, which
  // the service then traces first off the render worker and hands over in
  // FrameOptions::photon_maps (Renderer::needs_photon_trace). Called on the
  // renderer's thread.
  virtual bool needs_photon_trace(const Scene& scene, const FrameOptions& options) {
    (void)scene;
    (void)options;
    return false;
  }
  // The worker has been idle a while (RenderService::set_idle_release): give
  // back what is kept for later renders (caches, targets), as far as
  // repeating the last render stays cheap.
  virtual void release_idle_memory() {}
  // The scene-content cache's use (Renderer::scene_cache_stats); none by default.
  virtual SceneGpuCache::Stats scene_cache_stats() const { return {}; }

 private:
  std::uint64_t next_ticket_ = 1;
  std::map<std::uint64_t, std::vector<FrameResult>> done_;  // submitted, by ticket
};

// `stats`' "scene_cache" object (bytes, budget_bytes, entries, hits, misses, evictions).
nlohmann::json scene_cache_json(const SceneGpuCache::Stats& s);

// Called on each worker thread, so a GL context is created on the thread that uses it.
using RendererFactory = std::function<std::unique_ptr<FrameRenderer>()>;
// The GPU renderer (render/) behind the interface.
RendererFactory gl_renderer_factory(const RendererOptions& opts);

// The scheduling class of a job (PROTOCOL.md, "Scheduling"): interactive
// frames (`quality: "auto"`, the preview) are served before batch work, slice
// by slice; within a class connections take turns.
enum class WorkClass { kInteractive = 0, kBatch = 1 };

// Turns inside a slice (RenderService::set_turn, PROTOCOL.md "Scheduling"):
// how long (ms) a slice renders before a waiting cheap slice gets a turn
// inside it, and the most a slice may be estimated to cost (cost units,
// protocol/request_cost.hpp) to run in a turn. 250 admits one 512 x 512
// camera of beams or of a lit scene's raster passes (10 + 262 144 pixels x
// 4e-4 = 115); a costly slice waits for the worker as before.
inline constexpr int kRenderTurnMs = 50;
inline constexpr double kTurnSliceMaxCost = 250.0;
inline constexpr int kWorkClasses = 2;
const char* work_class_name(WorkClass c);

struct RenderOutcome {
  bool dropped = false;  // the client went away before the job reached the GPU
  std::optional<ErrorInfo> error;
  std::vector<FrameResult> frames;  // images released after encoding
  std::vector<std::vector<std::uint8_t>> pngs;  // encoded frames (JPEG when RenderJob::jpeg)
  std::vector<char> is_jpeg;      // per frame: 1 if encoded as JPEG
  // The other frames' format: PNG, or what the connection negotiated in hello.
  FrameFormat frame_format = FrameFormat::kPng;
  std::vector<double> encode_ms;  // per frame
  // The request's camera index of each frame (empty: frame i is camera i).
  // Set for the parts of a streamed job, which carry a slice's frames each.
  std::vector<std::size_t> frame_index;
  // Streamed jobs (RenderJob::on_part): this outcome's part number, and
  // whether it is the last one (the one passed to `done`).
  int part = -1;
  bool last_part = true;
  double queue_ms = 0.0;
  // The renderer's wall time for this job: the sum over its slices.
  double render_ms = 0.0;
  // Encoding wall time: per slice, from its first frame's encode start to its
  // last one's end, summed (slices encode while later slices render).
  double encode_wall_ms = 0.0;
  // Slices (GPU batches) the job was rendered in.
  int slices = 0;
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
  // Resolution scale of `quality: "auto"` frames; max_batch_views is also the
  // size of the slices the service renders the job in.
  FrameOptions options;
  bool jpeg = false;       // encode as JPEG (interactive frames) instead of PNG
  // Frames that are not JPEG: PNG, or raw samples (hello's frame_format).
  FrameFormat frame_format = FrameFormat::kPng;
  int jpeg_quality = 90;
  std::shared_ptr<const std::atomic<bool>> client_alive;
  std::chrono::steady_clock::time_point arrived;
  // The request's wall-clock deadline (max_render_ms after `arrived`; max:
  // none): checked between slices and, through a CancelToken
  // (protocol/cancel.hpp), inside the renderer's long CPU loops. Past it
  // the job is answered deadline_exceeded and the worker takes other work.
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
  // The JSON pointer a scene error found while rendering is reported under:
  // "/params/scene" (its field's path is appended) or "/params/scene_id".
  std::string scene_path = "/params/scene";
  // Jobs with the same non-null key (one stored scene, unmodified) that arrive
  // within the batch window are rendered in one call; null: never merged.
  const void* batch_key = nullptr;
  bool atlas = false;  // encode the frames as one atlas image (render/atlas.hpp)
  WorkClass work_class = WorkClass::kBatch;
  // The connection it came from: connections of one class take turns.
  std::uint64_t client = 0;
  // Estimated cost (protocol/request_cost.hpp): a slice is charged its share
  // of it when taken, corrected to the measured time when done (PROTOCOL.md,
  // "Scheduling"), so cheap renders pass costly ones.
  double cost = 0.0;
  // Streaming (render param "stream"): if set, called for every slice but the
  // last, in slice order, with that slice's frames (RenderOutcome::part,
  // frame_index); the last slice's frames then come to `done`. Never merged
  // with other jobs (batch_key must be null).
  std::function<void(RenderOutcome&&)> on_part;
  // Called exactly once, on a worker or encoder thread.
  std::function<void(RenderOutcome&&)> done;
};

class RenderService {
 public:
  RenderService(RendererFactory factory, int workers, int encode_threads, PngSettings png,
                int max_inflight);
  ~RenderService();

  // Blocks until every worker has a renderer (or failed to get one); returns
  // the first renderer's description, throws if none could be created.
  std::string wait_ready();

  // Batching across requests: a worker that takes a job with a batch key waits
  // until `window` after the job's arrival and renders every queued job of the
  // same key with it, up to `max_views` cameras in all. 0 (default): off, each
  // job renders as soon as a worker is free.
  void set_batch_window(std::chrono::milliseconds window, int max_views);

  // While interactive work is about (an interactive job was submitted within
  // `window`), batch jobs submitted are sliced one camera at a time, so a
  // preview frame waits for at most one batch frame; 0: always full slices.
  void set_interactive_window(std::chrono::milliseconds window);

  // While an interactive slice renders, batch frames' encodes wait to start
  // (default on): on llvmpipe the renderer runs on the same cores as the
  // encoders, and the preview frame then has them to itself.
  void set_hold_batch_encodes(bool hold);

  // Turns inside a slice (protocol/turns.hpp): a costly slice (estimated
  // over kTurnSliceMaxCost) that has rendered for `turn` lets one waiting
  // cheap slice (estimated at most kTurnSliceMaxCost) of another connection,
  // of its class or a higher one, run between its passes or row blocks, on
  // a second renderer of the same worker, and so on every `turn` after.
  // Default kRenderTurnMs; 0: at every turn point.
  void set_turn(std::chrono::milliseconds turn) { turn_ms_.store(turn.count()); }
  // Slices run in turns inside other slices.
  std::uint64_t turns_taken() const { return turns_taken_.load(); }

  // A worker that has rendered nothing for `idle` releases its renderer's
  // caches (FrameRenderer::release_idle_memory) and trims the heap, once
  // per idle spell. Default kIdleReleaseMs (server/memory.hpp).
  void set_idle_release(std::chrono::milliseconds idle) { idle_release_ms_.store(idle.count()); }
  // Idle releases done (all workers), and the renderers they replaced
  // (kRebuildWhenIdleAboveBytes, server/memory.hpp).
  std::uint64_t idle_releases() const { return idle_releases_.load(); }
  std::uint64_t idle_rebuilds() const { return idle_rebuilds_.load(); }

  // False if `max_inflight` jobs are already accepted and unanswered (busy).
  bool submit(RenderJob job);
  int inflight() const { return inflight_.load(); }
  // Jobs with slices not yet taken by a worker (all classes, or one).
  int queued() const;
  int queued(WorkClass c) const;
  // Jobs dropped because their client had gone (never rendered).
  std::uint64_t dropped() const { return dropped_.load(); }
  // Jobs stopped between slices because their client had gone, and the
  // slices (GPU batches) that were therefore never rendered.
  std::uint64_t cancelled() const { return cancelled_.load(); }
  std::uint64_t slices_dropped() const { return slices_dropped_.load(); }
  // Renderers discarded and recreated after a render threw GlError: a GL
  // error leaves the context in an unknown state, so the worker answers the
  // failed jobs `internal` and builds a new renderer (a new EGL context)
  // before it takes the next job.
  std::uint64_t renderer_rebuilds() const { return rebuilds_.load(); }
  // The workers' scene-content caches, summed (as of each one's last slice).
  SceneGpuCache::Stats scene_cache() const;
  // Test hook, compiled in always and reached only from tests: the next render
  // (on whichever worker takes it) fails with a real GL error
  // (Renderer::fail_next_render_for_test).
  void fail_next_render_for_test() { inject_failures_.fetch_add(1); }
  // Photon traces run off the render workers (started, and stopped by their
  // cancel token: deadline, client gone, cancel_all).
  std::uint64_t photon_traces() const { return photon_traces_.load(); }
  std::uint64_t photon_traces_cancelled() const { return photon_traces_cancelled_.load(); }
  // Stops the workers; jobs still queued are dropped (their `done` is called
  // with dropped = true).
  void stop();
  // Cancels the work in progress and all work to come (the server's drain
  // deadline has passed): every render's long loops throw at their next
  // check and its job is answered shutting_down.
  void cancel_all() { cancel_all_.store(true); }

 private:
  struct Task;
  using TaskPtr = std::shared_ptr<Task>;
  void worker_main(int index);
  // Creates a renderer on the calling (worker) thread; null, with the reason
  // in failure_, if it cannot.
  std::unique_ptr<FrameRenderer> make_renderer(int index);
  void finish(RenderJob& job, RenderOutcome&& outcome);
  // Scheduling, with mu_ held: queue a task at its connection's turn; take the
  // next slice (interactive class first, connections in turn); take a task's
  // remaining slices out of the queue.
  void enqueue_locked(const TaskPtr& task, bool front);
  bool has_work_locked() const;
  // What a worker does next: render `slice` of `task`, or (check) find out
  // whether the task needs photon tracing before its first slice (its
  // connection waits meanwhile: Task::held).
  struct Pick {
    TaskPtr task;
    std::size_t slice = 0;
    bool check = false;
  };
  // `inside` (a turn, protocol/turns.hpp): the task whose slice is
  // rendering on this thread; only a slice that may run in its turn is
  // picked (Task::fits_turn), or none.
  Pick pick_locked(std::unique_lock<std::mutex>& lock, const Task* inside = nullptr);
  // Whether a slice that may run in a turn inside `inside` is queued.
  bool turn_work_locked(const Task& inside) const;
  // A worker's turns: its hook, and the second renderer that turns run on.
  class WorkerTurns;
  void run_turn(WorkerTurns& turns, const Pick& pick);
  // A Pick::check answered with `renderer` (photon tracing needed or not).
  void check_prep(const TaskPtr& task, FrameRenderer* renderer, int index);
  // A picked slice whose clients have all gone: it and the task's remaining
  // slices leave without rendering.
  void drop_gone(const Pick& pick);
  // The worker's answer to a Pick::check: traces the maps on the CPU pool
  // (the task's connection still waits) or lets the task's slices be taken.
  void after_check(const TaskPtr& task, bool trace);
  void prep_main();
  void trace_for(Task& task);
  // Charges `ms` (may be negative: a correction) of render time to the
  // task's connection, with mu_ held.
  void charge_locked(const Task& task, double ms);
  std::size_t withdraw_locked(Task& task);
  // Merges the queued tasks that may join `first` (same batch key) once its
  // window has passed; called with `lock` held, may wait on it.
  void gather_batch(Task& first, std::unique_lock<std::mutex>& lock);
  // A slice submitted to the renderer (FrameRenderer::submit), its frames
  // not yet taken.
  struct SubmittedSlice {
    TaskPtr task;
    std::size_t slice = 0;
    std::uint64_t ticket = 0;
    double render_ms = 0.0;  // the submission's wall time
  };
  // One slice in two steps: submitted (null if it failed, the job answered),
  // then finished and its frames handed to the encoders.
  // `turns` (null inside a turn): installed as the slice's turn hook.
  std::optional<SubmittedSlice> start_slice(const TaskPtr& task, std::size_t slice,
                                            FrameRenderer* renderer, int index, bool* gl_failed,
                                            WorkerTurns* turns);
  void end_slice(SubmittedSlice& sub, FrameRenderer* renderer, int index, bool* gl_failed);
  std::optional<ErrorInfo> guarded_render(Task& task, std::size_t slice, int index,
                                          bool* gl_failed, bool starting,
                                          const std::function<void()>& render);
  void charge_measured(const Task& task, std::size_t slice, double render_ms);
  void fail_slice(Task& task, double render_ms, ErrorInfo error);
  std::size_t withdraw_slices(Task& task);
  // The worker has been idle for idle_release_ms_: release, trim, and if
  // the process is still well above its leanest idle size, a new renderer.
  void release_when_idle(std::unique_ptr<FrameRenderer>& renderer, int index);
  // `slice` of `task` is finished (encoded; none: SIZE_MAX) and `dropped`
  // more (never rendered); streamed parts go out in order, and the last
  // finished slice completes the task's jobs.
  void slices_finished(const TaskPtr& task, std::size_t slice, std::size_t dropped);
  void complete(Task& task);
  // The encoder pool runs interactive frames' encodes before batch ones.
  void post_encode(WorkClass c, std::function<void()> fn);

  RendererFactory factory_;
  std::vector<std::uint8_t> encode_still(const Image& img, FrameFormat f) const;
  const PngSettings png_;
  int max_inflight_;
  std::chrono::milliseconds batch_window_{0};
  std::atomic<std::int64_t> interactive_window_ms_{1000};
  std::atomic<std::int64_t> last_interactive_ms_{std::numeric_limits<std::int64_t>::min() / 2};
  int batch_max_views_ = 64;
  std::atomic<int> inflight_{0};
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<std::uint64_t> cancelled_{0};
  std::atomic<std::uint64_t> slices_dropped_{0};
  std::atomic<std::uint64_t> rebuilds_{0};
  std::atomic<int> inject_failures_{0};
  std::atomic<bool> cancel_all_{false};
  std::atomic<std::int64_t> idle_release_ms_;
  std::atomic<std::uint64_t> idle_releases_{0};
  std::atomic<std::uint64_t> idle_rebuilds_{0};
  std::atomic<std::uint64_t> photon_traces_{0};
  std::atomic<std::uint64_t> photon_traces_cancelled_{0};
  std::atomic<std::int64_t> turn_ms_;
  std::atomic<std::uint64_t> turns_taken_{0};
  mutable std::mutex cache_mu_;
  // By worker, guarded by cache_mu_: the counters of its discarded renderers
  // (a rebuilt renderer starts at zero), and its renderer's last stats.
  std::map<int, std::pair<SceneGpuCache::Stats, SceneGpuCache::Stats>> cache_stats_;
  void note_cache(const FrameRenderer* renderer, int index);
  // The lowest RSS after an idle release; set by wait_ready to the size at
  // start plus kRebuildWhenIdleAboveBytes.
  std::atomic<std::uint64_t> idle_rss_floor_{~std::uint64_t{0}};
  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::condition_variable window_cv_;  // batch windows wait here (stop() wakes them)
  // Per class: each connection's queued tasks (in arrival order), and the
  // connections with queued tasks in turn order (a connection is in `turns`
  // exactly when its deque is non-empty).
  struct ClassQueue {
    std::map<std::uint64_t, std::deque<TaskPtr>> by_client;
    std::deque<std::uint64_t> turns;
    int tasks = 0;
    // Start-time fair queueing by render time: each connection's tag is the
    // render time (ms) it has been charged, on a clock shared by the class;
    // the next slice goes to the connection with queued work whose start
    // (the later of its tag and the class's virtual time, the start of the
    // last slice taken) is least. A slice is charged its estimate when
    // taken and corrected to the measured time when done; photon tracing
    // off the workers is charged too. Idle connections bank nothing: their
    // start is the virtual time; their tags go once the clock passes them.
    double vtime = 0.0;
    std::map<std::uint64_t, double> used;
  };
  std::array<ClassQueue, kWorkClasses> queues_;
  bool stopping_ = false;
  int ready_ = 0;
  std::string description_;
  std::string failure_;
  std::condition_variable ready_cv_;
  std::vector<SizedThread> workers_;  // each owns a GL context
  // Photon tracing off the workers: tasks waiting for a tracer, and the
  // tracers (kPhotonTracers, each tracing with the cores less one).
  std::deque<TaskPtr> trace_queue_;  // guarded by mu_
  bool tracers_stopping_ = false;    // guarded by mu_
  int traces_in_flight_ = 0;         // queued or tracing; guarded by mu_
  std::condition_variable trace_cv_;
  std::vector<SizedThread> tracers_;
  std::mutex encode_mu_;
  std::condition_variable encode_cv_;  // batch encodes wait here for interactive renders
  std::array<std::deque<std::function<void()>>, kWorkClasses> encode_queue_;
  // Interactive slices being rendered now: batch encodes do not start
  // meanwhile (on a software rasterizer the render shares the CPU with them).
  int interactive_rendering_ = 0;  // guarded by encode_mu_
  bool hold_batch_encodes_ = true;  // guarded by encode_mu_
  bool encoders_stopping_ = false;  // guarded by encode_mu_
  // Counts an interactive render in interactive_rendering_ for its scope
  // (nothing for a batch one).
  class InteractiveRender {
   public:
    InteractiveRender(RenderService* service, bool interactive);
    ~InteractiveRender();
    InteractiveRender(const InteractiveRender&) = delete;
    InteractiveRender& operator=(const InteractiveRender&) = delete;

   private:
    RenderService* service_;
  };
  boost::asio::thread_pool encoders_;
};

}  // namespace beamcast
