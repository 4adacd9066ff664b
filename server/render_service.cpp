#include "server/render_service.hpp"

#include <boost/asio/post.hpp>

#include <malloc.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>
#include <exception>
#include <iterator>
#include <optional>
#include <utility>

#include "gi/gi_scene.hpp"
#include "gi/photon_map.hpp"
#include "protocol/cancel.hpp"
#include "protocol/check.hpp"
#include "protocol/turns.hpp"

#include "render/gl_util.hpp"
#include "render/image.hpp"
#include "render/jpeg.hpp"
#include "server/memory.hpp"

namespace beamcast {
namespace {

using Clock = std::chrono::steady_clock;

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// A render slower than this, or one that failed, gives the heap's free
// pages back (malloc_trim): photon maps and frames are large, and glibc
// would otherwise keep them resident (issue 43; server/memory.hpp).
constexpr double kTrimAfterRenderMs = 200.0;

ErrorInfo deadline_error(const RenderJob& job, const std::string& when) {
  return {"deadline_exceeded",
          "the render passed its deadline (max_render_ms = " +
              std::to_string(std::llround(ms_between(job.arrived, job.deadline))) +
              " after it arrived) " + when +
              "; it was stopped: lower its cost (photons, cameras, pixels, supersample, samples)",
          ""};
}

class GlFrameRenderer final : public FrameRenderer {
 public:
  explicit GlFrameRenderer(const RendererOptions& opts) : renderer_(opts) {}
  std::string description() const override { return renderer_.description(); }
  std::vector<FrameResult> render(const Scene& scene, const std::vector<Camera>& cameras) override {
    return renderer_.render(scene, cameras);
  }
  std::vector<FrameResult> render(const Scene& scene, const std::vector<Camera>& cameras,
                                  const FrameOptions& options) override {
    return renderer_.render(scene, cameras, options);
  }
  std::uint64_t submit(const Scene& scene, const std::vector<Camera>& cameras,
                       const FrameOptions& options) override {
    return renderer_.submit(scene, cameras, options);
  }
  std::vector<FrameResult> finish(std::uint64_t ticket) override {
    return renderer_.finish(ticket);
  }
  bool overlaps() const override { return true; }
  void fail_next_render_for_test() override { renderer_.fail_next_render_for_test(); }
  bool needs_photon_trace(const Scene& scene, const FrameOptions& options) override {
    return renderer_.needs_photon_trace(scene, options);
  }
  void release_idle_memory() override { renderer_.release_idle_memory(kIdlePhotonCacheBytes); }
  SceneGpuCache::Stats scene_cache_stats() const override { return renderer_.scene_cache_stats(); }

 private:
  Renderer renderer_;
};

// A job's cameras in slices of camera indices, as the renderer batches them
// (camera_batches); never empty.
std::vector<std::vector<std::size_t>> make_slices(const std::vector<Camera>& cameras,
                                                  const FrameOptions& o) {
  std::vector<std::vector<std::size_t>> slices = camera_batches(cameras, o);
  if (slices.empty()) slices.emplace_back();  // no cameras: one empty render
  return slices;
}

}  // namespace

nlohmann::json scene_cache_json(const SceneGpuCache::Stats& s) {
  return {{"bytes", s.bytes},   {"budget_bytes", s.budget}, {"entries", s.entries},
          {"hits", s.hits},     {"misses", s.misses},       {"evictions", s.evictions}};
}

const char* work_class_name(WorkClass c) {
  return c == WorkClass::kInteractive ? "interactive" : "batch";
}

// One unit of scheduling: a job (or jobs merged by the batch window) and how
// far its slices have come.
struct RenderService::Task {
  std::vector<RenderJob> members;         // one, or several merged jobs
  std::vector<Camera> cameras;            // every member's cameras, in order
  std::vector<std::size_t> member_of;     // per camera: its member
  std::vector<std::size_t> first_camera;  // per member: its first camera
  std::vector<std::vector<std::size_t>> slices;
  WorkClass cls = WorkClass::kBatch;
  std::uint64_t client = 0;
  const void* batch_key = nullptr;
  FrameOptions options;  // the first member's: merged jobs share options by their key
  double cost_per_camera = 0.0;  // the first member's estimate over its cameras

  // Guarded by the service's mu_.
  std::size_t next_slice = 0;  // slices before it have been taken by a worker
  bool started = false;
  Clock::time_point start;
  // Photon tracing before the first slice: checked by a worker (once), then
  // traced on the CPU pool; meanwhile the task is held (its connection's
  // work waits, the workers serve others). The maps go to options, a
  // failure to prep_error (rethrown where the first slice would render).
  bool prep_checked = false;
  bool held = false;
  std::exception_ptr prep_error;

  // Guarded by mu (frames, images: each element is written by one thread at
  // a time, handed over through the queues).
  std::mutex mu;
  std::mutex emit_mu;  // parts and the completion go out in order, one at a time
  std::vector<FrameResult> frames;
  std::vector<std::vector<std::uint8_t>> images;
  std::vector<char> is_jpeg;
  std::vector<double> encode_ms;
  std::vector<std::size_t> slice_left;  // frames of a slice still encoding
  std::vector<Clock::time_point> slice_encode_start;
  std::vector<char> slice_done;
  std::size_t finished = 0;   // slices encoded or dropped
  std::size_t next_part = 0;  // streaming: the next slice to send
  int batches = 0;            // GPU batches rendered so far (frames' batch index)
  double render_ms = 0.0;
  double encode_wall_ms = 0.0;
  std::optional<ErrorInfo> error;
  bool cancelled = false;  // the clients had gone: the rest was not rendered

  void add(RenderJob job) {
    first_camera.push_back(cameras.size());
    for (const Camera& c : job.cameras) {
      cameras.push_back(c);
      member_of.push_back(members.size());
    }
    members.push_back(std::move(job));
  }
  void prepare() {
    const std::size_t n = cameras.size();
    frames.resize(n);
    images.resize(n);
    is_jpeg.assign(n, 0);
    encode_ms.assign(n, 0.0);
    slice_left.assign(slices.size(), 0);
    slice_encode_start.resize(slices.size());
    slice_done.assign(slices.size(), 0);
  }
  bool any_alive() const {
    return std::any_of(members.begin(), members.end(),
                       [](const RenderJob& j) { return j.client_alive->load(); });
  }
  bool streamed() const { return members.size() == 1 && members[0].on_part != nullptr; }
  // Whether this task's next slice may run in a turn inside `inside`'s
  // (RenderService::set_turn): another connection's, of the same or a
  // higher class, not held, estimated cheap, and not waiting for a batch
  // window to gather (which would block the turn). Under the service's mu_.
  bool fits_turn(const Task& inside, std::chrono::milliseconds batch_window) const {
    if (client == inside.client || cls > inside.cls || held) return false;
    if (!started && batch_key != nullptr && batch_window.count() > 0) return false;
    const std::size_t n = next_slice < slices.size() ? slices[next_slice].size() : 1;
    return cost_per_camera * static_cast<double>(n) <= kTurnSliceMaxCost;
  }
  // The frames of slice `s` as a part of the (single-job) streamed response.
  RenderOutcome part(std::size_t s) {
    RenderOutcome o;
    o.part = static_cast<int>(s);
    o.last_part = s + 1 == slices.size();
    for (std::size_t i : slices[s]) {
      o.frames.push_back(std::move(frames[i]));
      o.pngs.push_back(std::move(images[i]));
      o.is_jpeg.push_back(is_jpeg[i]);
      o.encode_ms.push_back(encode_ms[i]);
      o.frame_index.push_back(i);
    }
    o.frame_format = members[0].frame_format;
    o.queue_ms = ms_between(members[0].arrived, start);
    o.render_ms = render_ms;
    o.encode_wall_ms = encode_wall_ms;
    o.slices = static_cast<int>(slices.size());
    o.batched_views = static_cast<int>(cameras.size());
    return o;
  }
};

RendererFactory gl_renderer_factory(const RendererOptions& opts) {
  return [opts] { return std::make_unique<GlFrameRenderer>(opts); };
}


// Photon traces that run at once off the render workers: one connection
// traces one job at a time (its connection is held meanwhile), so a second
// tracer lets another connection's trace start beside a long one.
constexpr int kPhotonTracers = 2;

// Connections whose used render time differs by less than this take plain
// turns (RenderService::pick_locked).
constexpr double kTurnQuantumMs = 5.0;

RenderService::RenderService(RendererFactory factory, int workers, int encode_threads,
                             PngSettings png, int max_inflight)
    : factory_(std::move(factory)),
      png_(png),
      max_inflight_(max_inflight),
      idle_release_ms_(kIdleReleaseMs),
      turn_ms_(kRenderTurnMs),
      encoders_(static_cast<std::size_t>(std::max(1, encode_threads))) {
  for (int i = 0; i < std::max(1, workers); ++i) {
    workers_.emplace_back([this, i] { worker_main(i); });
  }
  for (int i = 0; i < kPhotonTracers; ++i) tracers_.emplace_back([this] { prep_main(); });
}

RenderService::~RenderService() { stop(); }

std::string RenderService::wait_ready() {
  std::unique_lock lock(mu_);
  ready_cv_.wait(lock, [&] { return ready_ == static_cast<int>(workers_.size()); });
  if (description_.empty()) throw std::runtime_error(failure_);
  // The leanest idle size is at most the size now (every context made,
  // nothing rendered) plus the rebuild margin (server/memory.hpp).
  idle_rss_floor_.store(resident_bytes() + kRebuildWhenIdleAboveBytes);
  return description_;
}

bool RenderService::submit(RenderJob job) {
  // Admission counts everything accepted and not yet answered (queued,
  // rendering, encoding), so the queue can never grow without bound.
  int current = inflight_.load();
  do {
    if (current >= max_inflight_) return false;
  } while (!inflight_.compare_exchange_weak(current, current + 1));
  // Batch work submitted while a preview is active renders one camera per
  // slice: on llvmpipe a batch of 4 costs what 4 single frames cost
  // (docs/performance.md), and the preview then waits for one frame, not 4.
  const std::int64_t now_ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                                  Clock::now().time_since_epoch())
                                  .count();
  if (job.work_class == WorkClass::kInteractive) {
    last_interactive_ms_.store(now_ms);
  } else if (now_ms - last_interactive_ms_.load() < interactive_window_ms_.load()) {
    job.options.max_batch_views = 1;
  }
  auto task = std::make_shared<Task>();
  task->cls = job.work_class;
  task->client = job.client;
  task->batch_key = job.on_part ? nullptr : job.batch_key;  // a streamed job renders alone
  task->options = job.options;
  task->cost_per_camera = job.cost / static_cast<double>(std::max<std::size_t>(1, job.cameras.size()));
  task->add(std::move(job));
  task->slices = make_slices(task->cameras, task->options);
  {
    std::lock_guard lock(mu_);
    if (stopping_) {
      inflight_.fetch_sub(1);
      return false;
    }
    enqueue_locked(task, false);
  }
  cv_.notify_one();
  return true;
}

int RenderService::queued() const {
  std::lock_guard lock(mu_);
  int n = 0;
  for (const ClassQueue& q : queues_) n += q.tasks;
  return n;
}

int RenderService::queued(WorkClass c) const {
  std::lock_guard lock(mu_);
  return queues_[static_cast<int>(c)].tasks;
}

void RenderService::finish(RenderJob& job, RenderOutcome&& outcome) {
  auto done = std::move(job.done);
  inflight_.fetch_sub(1);
  done(std::move(outcome));
}

std::unique_ptr<FrameRenderer> RenderService::make_renderer(int index) {
  try {
    auto renderer = factory_();
    std::lock_guard lock(mu_);
    if (description_.empty()) description_ = renderer->description();
    return renderer;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "beamcast-server: render worker %d: %s\n", index, e.what());
    std::lock_guard lock(mu_);
    failure_ = e.what();
    return nullptr;
  }
}

void RenderService::enqueue_locked(const TaskPtr& task, bool front) {
  ClassQueue& q = queues_[static_cast<int>(task->cls)];
  std::deque<TaskPtr>& mine = q.by_client[task->client];
  const bool was_empty = mine.empty();
  if (front) {
    mine.push_front(task);
  } else {
    mine.push_back(task);
  }
  ++q.tasks;
  if (was_empty) {
    if (front) {
      q.turns.push_front(task->client);
    } else {
      q.turns.push_back(task->client);
    }
  }
}

namespace {

// Whether a connection of the class has a next task `fits` takes.
template <class Queue, class Fits>
bool any_queued(const Queue& q, const Fits& fits) {
  return std::any_of(q.turns.begin(), q.turns.end(), [&](std::uint64_t client) {
    const auto it = q.by_client.find(client);
    return it != q.by_client.end() && !it->second.empty() && fits(*it->second.front());
  });
}

// Whether a connection of the class has queued work that is not held
// (photon tracing off the workers).
template <class Queue>
bool has_ready_work(const Queue& q) {
  return any_queued(q, [](const auto& task) { return !task.held; });
}

}  // namespace

bool RenderService::turn_work_locked(const Task& inside) const {
  return std::any_of(queues_.begin(), queues_.end(), [&](const ClassQueue& q) {
    return any_queued(q, [&](const Task& t) { return t.fits_turn(inside, batch_window_); });
  });
}

bool RenderService::has_work_locked() const {
  return std::any_of(queues_.begin(), queues_.end(),
                     [](const ClassQueue& q) { return has_ready_work(q); });
}

void RenderService::charge_locked(const Task& task, double ms) {
  ClassQueue& q = queues_[static_cast<int>(task.cls)];
  q.used.try_emplace(task.client, q.vtime).first->second += ms;
}

// The next slice: the first class with queued work that is not held
// (interactive before batch); in it, the connection whose next slice would
// finish first in render time: its start (the render time it has used,
// ClassQueue::used, or the clock) plus the slice's estimated cost (ties in
// turn order), so a cheap render passes a costly one queued at the same
// start; of that connection's tasks, the oldest. The connection then goes to the back of the turns.
// A task's first slice is preceded by a check for photon tracing
// (Pick::check), which holds its connection until the worker answers.
RenderService::Pick RenderService::pick_locked(std::unique_lock<std::mutex>& lock,
                                              const Task* inside) {
  // In a turn: only what fits it (Task::fits_turn).
  const auto fits = [&](const Task& t) {
    return inside == nullptr ? !t.held : t.fits_turn(*inside, batch_window_);
  };
  for (;;) {
    ClassQueue* q = nullptr;
    for (ClassQueue& c : queues_) {
      if (any_queued(c, fits)) {
        q = &c;
        break;
      }
    }
    if (q == nullptr) return {};
    // Starts within kTurnQuantumMs of the least count as equal: of those,
    // the first in turn order goes (equal costs take plain turns whatever
    // the timing noise).
    std::vector<double> starts(q->turns.size(), std::numeric_limits<double>::infinity());
    std::vector<double> finishes(q->turns.size(), std::numeric_limits<double>::infinity());
    double least = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < q->turns.size(); ++i) {
      const auto queued = q->by_client.find(q->turns[i]);
      BEAMCAST_CHECK(queued != q->by_client.end() && !queued->second.empty(),
                     "a connection in the turns has queued work");
      const Task& next = *queued->second.front();
      if (!fits(next)) continue;
      const auto used = q->used.find(q->turns[i]);
      starts[i] = std::max(q->vtime, used == q->used.end() ? 0.0 : used->second);
      const std::size_t cameras =
          next.next_slice < next.slices.size() ? next.slices[next.next_slice].size() : 1;
      finishes[i] = starts[i] + next.cost_per_camera * static_cast<double>(cameras);
      least = std::min(least, finishes[i]);
    }
    const auto at = std::find_if(finishes.begin(), finishes.end(),
                                 [&](double v) { return v <= least + kTurnQuantumMs; });
    const auto best = static_cast<std::size_t>(at - finishes.begin());
    const double best_start = starts[best];
    const std::uint64_t client = q->turns[best];
    auto it = q->by_client.find(client);
    TaskPtr task = it->second.front();
    if (!task->started) {
      task->started = true;
      if (task->batch_key != nullptr && batch_window_.count() > 0) {
        // Out of the queue while its window runs (no other worker takes a
        // slice of it meanwhile); back at the head of its turn after merging.
        q->turns.erase(q->turns.begin() + static_cast<std::ptrdiff_t>(best));
        it->second.pop_front();
        --q->tasks;
        if (it->second.empty()) {
          q->by_client.erase(it);
        } else {
          q->turns.push_front(client);
        }
        gather_batch(*task, lock);
        task->start = Clock::now();
        if (stopping_) {  // stop() drops it with the rest of the queue
          enqueue_locked(task, true);
          return {};
        }
        task->prepare();
        enqueue_locked(task, true);
        continue;  // an interactive job may have come meanwhile
      }
      task->start = Clock::now();
      task->prepare();
    }
    if (!task->prep_checked) {
      // Nothing taken or charged yet: the worker checks, then picks again.
      task->prep_checked = true;
      task->held = true;
      return {task, 0, true};
    }
    q->turns.erase(q->turns.begin() + static_cast<std::ptrdiff_t>(best));
    q->vtime = std::max(q->vtime, best_start);
    const std::size_t cameras =
        task->next_slice < task->slices.size() ? task->slices[task->next_slice].size() : 1;
    q->used[client] = best_start + task->cost_per_camera * static_cast<double>(cameras);
    const std::size_t slice = task->next_slice++;
    if (task->next_slice == task->slices.size()) {
      it->second.pop_front();
      --q->tasks;
    }
    if (it->second.empty()) {
      q->by_client.erase(it);
    } else {
      q->turns.push_back(client);
    }
    // Tags the clock has passed, of connections without queued work, mean
    // nothing any more (such a connection starts at the clock).
    for (auto u = q->used.begin(); u != q->used.end();) {
      if (u->second <= q->vtime && q->by_client.count(u->first) == 0) {
        u = q->used.erase(u);
      } else {
        ++u;
      }
    }
    return {task, slice, false};
  }
}

void RenderService::after_check(const TaskPtr& task, bool trace) {
  {
    std::lock_guard lock(mu_);
    if (trace && !stopping_) {
      trace_queue_.push_back(task);
      ++traces_in_flight_;
    } else {
      task->held = false;
    }
  }
  if (trace) trace_cv_.notify_one();
  cv_.notify_all();
}

void RenderService::prep_main() {
  for (;;) {
    TaskPtr task;
    {
      std::unique_lock lock(mu_);
      trace_cv_.wait(lock, [&] { return tracers_stopping_ || !trace_queue_.empty(); });
      if (tracers_stopping_) return;  // stop() drops the held tasks with the queue
      task = std::move(trace_queue_.front());
      trace_queue_.pop_front();
    }
    trace_for(*task);
    cv_.notify_all();
  }
}

// The task's photon maps, traced here with the cores less one (a render
// beside it keeps a core), under the task's cancel token: its deadline, its
// client leaving (a single job) and the server's shutdown stop it within one
// check interval (gi/photon_map.hpp). The maps are those the renderer would
// trace (the same function over the same scene; any thread count).
void RenderService::trace_for(Task& task) {
  const RenderJob& first = task.members.front();
  Clock::time_point deadline = Clock::time_point::max();
  for (const RenderJob& j : task.members) deadline = std::min(deadline, j.deadline);
  const CancelToken token(deadline, &cancel_all_,
                          task.members.size() == 1 ? first.client_alive.get() : nullptr);
  const auto t0 = Clock::now();
  std::shared_ptr<const PhotonMaps> maps;
  std::exception_ptr error;
  photon_traces_.fetch_add(1);
  try {
    const CancelScope scope(&token);
    PhotonTraceOptions options;
    options.threads = std::max(1, usable_cores() - 1);
    maps = std::make_shared<const PhotonMaps>(
        trace_photons(*first.scene, GiScene(*first.scene), options));
  } catch (const Cancelled&) {
    photon_traces_cancelled_.fetch_add(1);
    error = std::current_exception();
  } catch (...) {
    error = std::current_exception();
  }
  const double ms = ms_between(t0, Clock::now());
  if (error) malloc_trim(0);
  std::lock_guard lock(mu_);
  task.options.photon_maps = std::move(maps);
  task.prep_error = error;
  task.held = false;
  --traces_in_flight_;
  charge_locked(task, ms);
}

// Takes the task's untaken slices out of the queue; returns how many.
std::size_t RenderService::withdraw_locked(Task& task) {
  const std::size_t left = task.slices.size() - task.next_slice;
  if (left == 0) return 0;  // not queued any more
  task.next_slice = task.slices.size();
  ClassQueue& q = queues_[static_cast<int>(task.cls)];
  auto it = q.by_client.find(task.client);
  if (it == q.by_client.end()) return left;  // in a batch window, out of the queue
  std::deque<TaskPtr>& mine = it->second;
  const auto at = std::find_if(mine.begin(), mine.end(),
                               [&](const TaskPtr& t) { return t.get() == &task; });
  if (at == mine.end()) return left;
  mine.erase(at);
  --q.tasks;
  if (mine.empty()) {
    q.by_client.erase(it);
    q.turns.erase(std::find(q.turns.begin(), q.turns.end(), task.client));
  }
  return left;
}

// A worker's turn hook (protocol/turns.hpp), installed while one of its
// slices renders; for a costly slice (estimated over kTurnSliceMaxCost):
// once the slice has rendered for turn_ms_ since it started
// or since its last turn, and a slice that fits a turn is queued
// (Task::fits_turn), the next such slice runs (RenderService::run_turn) on
// this worker's second renderer, made on the first turn, and the slice
// goes on. The turns' wall time is not the slice's: start_slice takes it
// out of the slice's measured time, so its connection is not charged it.
class RenderService::WorkerTurns final : public TurnHook {
 public:
  WorkerTurns(RenderService* service, int index) : service_(service), index_(index) {}
  // Only a costly slice (estimated over kTurnSliceMaxCost) gives turns: a
  // cheap one that runs long on a loaded machine does not (the second
  // renderer is made only beside costly work).
  void begin(const Task& task, std::size_t slice) {
    const bool costly = task.cost_per_camera * static_cast<double>(task.slices[slice].size()) >
                        kTurnSliceMaxCost;
    running_ = costly ? &task : nullptr;
    last_ = Clock::now();
    given_ms_ = 0.0;
  }
  void end() { running_ = nullptr; }
  // Wall time given to turns since begin().
  double given_ms() const { return given_ms_; }
  int index() const { return index_; }
  // Drops the turns' renderer (idle, or after a GL error in a turn).
  void release() { renderer.reset(); }

  bool due() override {
    if (running_ == nullptr || unavailable_) return false;
    if (ms_between(last_, Clock::now()) < static_cast<double>(service_->turn_ms_.load())) {
      return false;
    }
    std::lock_guard lock(service_->mu_);
    return !service_->stopping_ && service_->turn_work_locked(*running_);
  }
  void take() override {
    const auto t0 = Clock::now();
    if (!renderer) renderer = service_->make_renderer(index_);
    if (!renderer) {
      // No second context on this device: no turns (the slice goes on).
      unavailable_ = true;
      return;
    }
    // Photon-trace checks (Pick::check) come first for a new task; the
    // turn ends after one slice, or when nothing fits any more.
    for (;;) {
      Pick pick;
      {
        std::unique_lock lock(service_->mu_);
        if (!service_->stopping_) pick = service_->pick_locked(lock, running_);
      }
      if (!pick.task) break;
      service_->run_turn(*this, pick);
      if (!pick.check) break;
    }
    last_ = Clock::now();
    given_ms_ += ms_between(t0, last_);
  }

  std::unique_ptr<FrameRenderer> renderer;  // the turns' own (own GL context)

 private:
  RenderService* service_;
  int index_;
  const Task* running_ = nullptr;
  Clock::time_point last_;
  double given_ms_ = 0.0;
  bool unavailable_ = false;
};

void RenderService::run_turn(WorkerTurns& turns, const Pick& pick) {
  FrameRenderer* renderer = turns.renderer.get();
  if (pick.check) {
    check_prep(pick.task, renderer, turns.index());
    return;
  }
  turns_taken_.fetch_add(1);
  if (!pick.task->any_alive()) {
    drop_gone(pick);
    return;
  }
  // Rendered and finished at once: the turn ends with nothing in flight.
  bool gl_failed = false;
  std::optional<SubmittedSlice> sub =
      start_slice(pick.task, pick.slice, renderer, turns.index(), &gl_failed, nullptr);
  if (sub) end_slice(*sub, renderer, turns.index(), &gl_failed);
  if (gl_failed) {
    turns.release();  // a new one at the next turn
    rebuilds_.fetch_add(1);
  }
}

void RenderService::check_prep(const TaskPtr& task, FrameRenderer* renderer, int index) {
  // Photon tracing goes to the CPU pool (the job's connection waits, this
  // worker serves others); a job whose clients have gone is dropped at its
  // slice, after the next pick.
  bool trace = false;
  try {
    trace = renderer && task->any_alive() && !cancel_all_.load() &&
            renderer->needs_photon_trace(*task->members.front().scene, task->options);
  } catch (const std::exception& e) {
    // The render itself reports what went wrong.
    std::fprintf(stderr, "beamcast-server: render worker %d: %s\n", index, e.what());
  }
  after_check(task, trace);
}

// Between slices: a job whose clients have all gone costs no more GPU time.
// Its remaining slices leave the queue; nothing is answered.
void RenderService::drop_gone(const Pick& pick) {
  const TaskPtr& task = pick.task;
  std::size_t withdrawn = 0;
  {
    std::lock_guard lock(mu_);
    withdrawn = withdraw_locked(*task);
  }
  bool first_cancel = false;
  {
    std::lock_guard lock(task->mu);
    first_cancel = !task->cancelled;
    task->cancelled = true;
  }
  if (first_cancel) {
    if (pick.slice == 0) {
      dropped_.fetch_add(task->members.size());  // never reached the GPU
    } else {
      cancelled_.fetch_add(1);
    }
  }
  slices_dropped_.fetch_add(1 + withdrawn);
  slices_finished(task, std::numeric_limits<std::size_t>::max(), 1 + withdrawn);
}

void RenderService::worker_main(int index) {
  std::unique_ptr<FrameRenderer> renderer = make_renderer(index);
  // Declared after `renderer`: the turns' renderer goes first.
  WorkerTurns turns(this, index);
  bool rebuild_pending = false;  // a GL error discarded the renderer, no new one yet
  {
    std::lock_guard lock(mu_);
    ++ready_;
  }
  ready_cv_.notify_all();

  bool released = true;  // nothing rendered since the last idle release
  // The slice submitted last, its frames not yet taken (FrameRenderer::finish):
  // it is finished after the next slice is submitted when more work is
  // queued and the renderer overlaps (FrameRenderer::overlaps), so its GPU
  // work and read-back overlap that submission; at once otherwise.
  std::optional<SubmittedSlice> pending;
  // After the failed job is answered: the old context goes before the new
  // one is made current on this thread. A worker whose rebuild fails tries
  // again before its next slice (and answers `internal` meanwhile).
  const auto rebuild_if = [&](bool gl_failed) {
    rebuild_pending = rebuild_pending || gl_failed;
    if (gl_failed || !renderer) {
      renderer.reset();
      renderer = make_renderer(index);
      if (renderer && rebuild_pending) {
        rebuilds_.fetch_add(1);
        rebuild_pending = false;
      }
    }
  };
  for (;;) {
    Pick pick;
    {
      std::unique_lock lock(mu_);
      if (pending && (stopping_ || !has_work_locked())) {
        lock.unlock();
        bool gl_failed = false;
        end_slice(*pending, renderer.get(), index, &gl_failed);
        pending.reset();
        note_cache(renderer.get(), index);
        rebuild_if(gl_failed);
        continue;
      }
      const auto woken = [&] { return stopping_ || has_work_locked(); };
      if (!released &&
          !cv_.wait_for(lock, std::chrono::milliseconds(idle_release_ms_.load()), woken)) {
        // Not idle while a job's photons are traced for it (Task::held):
        // its render follows, with what the release would drop.
        if (traces_in_flight_ > 0) continue;
        // Idle: the caches go (server/memory.hpp, kIdleReleaseMs), then
        // the heap pages they held; the turns' renderer goes whole.
        lock.unlock();
        turns.release();
        release_when_idle(renderer, index);
        note_cache(renderer.get(), index);
        released = true;
        continue;
      }
      cv_.wait(lock, woken);
      if (stopping_) return;  // stop() drops what is still queued
      pick = pick_locked(lock);
    }
    released = false;
    const TaskPtr& task = pick.task;
    const std::size_t slice = pick.slice;
    if (!task) continue;
    if (pick.check) {
      check_prep(task, renderer.get(), index);
      continue;
    }
    if (!task->any_alive()) {
      drop_gone(pick);
      continue;
    }
    bool gl_failed = false;
    if (pending && task->cost_per_camera * static_cast<double>(task->slices[slice].size()) >
                       kTurnSliceMaxCost) {
      // A costly slice next: the earlier slice's frames are finished (and
      // answered) first, not held for the whole of it.
      end_slice(*pending, renderer.get(), index, &gl_failed);
      pending.reset();
      rebuild_if(gl_failed);
      gl_failed = false;
    }
    std::optional<SubmittedSlice> next =
        start_slice(task, slice, renderer.get(), index, &gl_failed, &turns);
    if (pending) {
      // The earlier slice's read-back, overlapped by this one's submission.
      end_slice(*pending, renderer.get(), index, &gl_failed);
      pending.reset();
    }
    if (next && (gl_failed || !renderer->overlaps())) {
      // The context goes: what was submitted on it is finished first. Or
      // the renderer rendered in submit(): nothing to overlap.
      end_slice(*next, renderer.get(), index, &gl_failed);
      next.reset();
    }
    pending = std::move(next);
    note_cache(renderer.get(), index);
    rebuild_if(gl_failed);
  }
}

void RenderService::note_cache(const FrameRenderer* renderer, int index) {
  const SceneGpuCache::Stats s = renderer ? renderer->scene_cache_stats() : SceneGpuCache::Stats{};
  std::lock_guard lock(cache_mu_);
  auto& [base, last] = cache_stats_[index];
  if (s.hits + s.misses < last.hits + last.misses) {  // a new renderer
    base.hits += last.hits;
    base.misses += last.misses;
    base.evictions += last.evictions;
  }
  last = s;
}

SceneGpuCache::Stats RenderService::scene_cache() const {
  std::lock_guard lock(cache_mu_);
  SceneGpuCache::Stats sum;
  for (const auto& [index, w] : cache_stats_) {
    const auto& [base, s] = w;
    sum.bytes += s.bytes;
    sum.entries += s.entries;
    sum.budget += s.budget;
    sum.hits += base.hits + s.hits;
    sum.misses += base.misses + s.misses;
    sum.evictions += base.evictions + s.evictions;
  }
  return sum;
}

void RenderService::release_when_idle(std::unique_ptr<FrameRenderer>& renderer, int index) {
  bool rebuild = false;
  try {
    if (renderer) renderer->release_idle_memory();
  } catch (const std::exception& e) {
    // A GL error leaves the context in an unknown state: a new one.
    std::fprintf(stderr, "beamcast-server: render worker %d: releasing memory failed: %s\n",
                 index, e.what());
    rebuild = true;
  }
  malloc_trim(0);
  const std::uint64_t rss = resident_bytes();
  std::uint64_t floor = idle_rss_floor_.load();
#if defined(BEAMCAST_ASAN)
  // Under ASan the resident size holds the allocator's quarantine, not the
  // renderer's memory: it says nothing about what a new context would free.
  const bool over = false;
#else
  const bool over = renderer && rss > floor + kRebuildWhenIdleAboveBytes;
#endif
  rebuild = rebuild || over;
  if (rebuild) {
    const auto t0 = Clock::now();
    renderer.reset();
    malloc_trim(0);
    renderer = make_renderer(index);
    if (renderer) idle_rebuilds_.fetch_add(1);
    std::fprintf(stderr,
                 "beamcast-server: render worker %d idle at %.0f MiB (leanest idle %.0f MiB): "
                 "new renderer in %.0f ms, %.0f MiB now\n",
                 index, rss / 1048576.0, floor / 1048576.0, ms_between(t0, Clock::now()),
                 resident_bytes() / 1048576.0);
  }
  const std::uint64_t now = resident_bytes();
  if (over) {
    // What a new context leaves is the leanest this process gets with what
    // it holds now (stored scenes, buffers): measured from there on, so
    // memory that is not the renderer's never makes every idle spell
    // replace the renderer (and every next render compile its shaders).
    idle_rss_floor_.store(now);
  } else {
    while (now < floor && !idle_rss_floor_.compare_exchange_weak(floor, now)) {
    }
  }
  idle_releases_.fetch_add(1);
}

// Runs `render` (a renderer call for the slice) as a render of `task`:
// its deadline and cancellation in scope, its failures as the job's error
// (a GL error or a cancelled render also sets *gl_failed: the context is
// rebuilt before the next slice).
std::optional<ErrorInfo> RenderService::guarded_render(Task& task, std::size_t slice, int index,
                                                       bool* gl_failed, bool starting,
                                                       const std::function<void()>& render) {
  // Merged jobs share the render: the earliest deadline holds for it.
  Clock::time_point deadline = Clock::time_point::max();
  for (const RenderJob& j : task.members) deadline = std::min(deadline, j.deadline);
  const RenderJob& first = task.members.front();
  const CancelToken token(deadline, &cancel_all_,
                          task.members.size() == 1 ? first.client_alive.get() : nullptr);
  if (starting && token.stopped()) {
    return ErrorInfo{"shutting_down", "the server is stopping: the render was cancelled", ""};
  }
  if (starting && token.expired()) {
    return deadline_error(first, "before its slice " + std::to_string(slice + 1) + " of " +
                                     std::to_string(task.slices.size()) + " started");
  }
  // Past the photon maps traced for it (Task::prep_error): a slice being
  // finished always is.
  bool rendering = !starting;
  const CancelScope scope(&token);
  try {
    if (!rendering && task.prep_error) std::rethrow_exception(task.prep_error);
    rendering = true;
    const InteractiveRender hold(this, task.cls == WorkClass::kInteractive);
    render();
    return std::nullopt;
  } catch (const Cancelled& e) {
    // Stopped inside a CPU loop, perhaps mid-frame: the context is
    // rebuilt before the next slice, as after a GL error, so no state of
    // the abandoned frame reaches another (not when shutting down, nor when
    // the photon trace before the render was what stopped).
    *gl_failed = *gl_failed || (rendering && e.reason() != Cancelled::Reason::kShutdown);
    if (e.reason() == Cancelled::Reason::kShutdown) {
      return ErrorInfo{"shutting_down", "the server is stopping: the render was cancelled", ""};
    }
    if (e.reason() == Cancelled::Reason::kClientGone) {
      // Never sent: the job completes as dropped (RenderService::complete).
      cancelled_.fetch_add(1);
      return ErrorInfo{"internal", "the client has gone", ""};
    }
    const std::string where =
        rendering ? "while rendering slice " : "while tracing photons for slice ";
    return deadline_error(first, where + std::to_string(slice + 1) + " of " +
                                     std::to_string(task.slices.size()));
  } catch (const PhotonEventLimit& e) {
    return ErrorInfo{"limit_exceeded", e.what(),
                     first.scene_path == "/params/scene" ? "/params/scene/gi/photons"
                                                         : first.scene_path};
  } catch (const ProtocolError& e) {
    ErrorInfo info = e.info();
    info.path =
        first.scene_path == "/params/scene" ? first.scene_path + info.path : first.scene_path;
    return info;
  } catch (const GlError& e) {
    std::fprintf(stderr, "beamcast-server: render worker %d: GL error, rebuilding its context: %s\n",
                 index, e.what());
    *gl_failed = true;
    return ErrorInfo{"internal", std::string("render failed: ") + e.what(), ""};
  } catch (const std::exception& e) {
    std::fprintf(stderr, "beamcast-server: render failed: %s\n", e.what());
    return ErrorInfo{"internal", std::string("render failed: ") + e.what(), ""};
  }
}

std::optional<RenderService::SubmittedSlice> RenderService::start_slice(
    const TaskPtr& t, std::size_t slice, FrameRenderer* renderer, int index, bool* gl_failed,
    WorkerTurns* turns) {
  Task& task = *t;
  SubmittedSlice sub{t, slice, 0, 0.0};
  const auto start = Clock::now();
  std::optional<ErrorInfo> error;
  if (turns != nullptr) turns->begin(task, slice);
  if (!renderer) {
    error = ErrorInfo{"internal", "no renderer: " + failure_, ""};
  } else {
    const TurnScope scope(turns);
    error = guarded_render(task, slice, index, gl_failed, true, [&] {
      int inject = inject_failures_.load();
      while (inject > 0 && !inject_failures_.compare_exchange_weak(inject, inject - 1)) {
      }
      if (inject > 0) renderer->fail_next_render_for_test();
      std::vector<Camera> cameras;
      cameras.reserve(task.slices[slice].size());
      for (std::size_t i : task.slices[slice]) cameras.push_back(task.cameras[i]);
      // Merged jobs share a render only with the same stored scene and default
      // options (RenderJob::batch_key), so the first job's options hold for all.
      sub.ticket = renderer->submit(*task.members.front().scene, cameras, task.options);
    });
  }
  // Turns given inside it are the other slices' time, not this one's.
  sub.render_ms = ms_between(start, Clock::now()) - (turns != nullptr ? turns->given_ms() : 0.0);
  if (turns != nullptr) turns->end();
  if (!error) return sub;
  charge_measured(task, slice, sub.render_ms);
  fail_slice(task, sub.render_ms, std::move(*error));
  slices_finished(t, std::numeric_limits<std::size_t>::max(), 1 + withdraw_slices(task));
  return std::nullopt;
}

// The estimate charged when the slice was taken, corrected to the time
// measured (its submission and its finish).
void RenderService::charge_measured(const Task& task, std::size_t slice, double render_ms) {
  std::lock_guard lock(mu_);
  charge_locked(task, render_ms - task.cost_per_camera *
                                      static_cast<double>(task.slices[slice].size()));
}

// The job is answered with the error: its other slices are not rendered.
void RenderService::fail_slice(Task& task, double render_ms, ErrorInfo error) {
  malloc_trim(0);
  std::lock_guard lock(task.mu);
  task.render_ms += render_ms;
  if (!task.error) task.error = std::move(error);
}

std::size_t RenderService::withdraw_slices(Task& task) {
  std::lock_guard lock(mu_);
  return withdraw_locked(task);
}

void RenderService::end_slice(SubmittedSlice& sub, FrameRenderer* renderer, int index,
                              bool* gl_failed) {
  const TaskPtr& t = sub.task;
  Task& task = *t;
  const std::size_t slice = sub.slice;
  const std::vector<std::size_t>& idx = task.slices[slice];
  std::vector<FrameResult> frames;
  const auto start = Clock::now();
  std::optional<ErrorInfo> error;
  if (!renderer) {
    error = ErrorInfo{"internal", "no renderer: " + failure_, ""};
  } else {
    error = guarded_render(task, slice, index, gl_failed, false, [&] {
      frames = renderer->finish(sub.ticket);
      BEAMCAST_CHECK(frames.size() == idx.size(), "one frame per camera of a slice");
    });
  }
  // The slice's own time on this worker: its submission and its finish, not
  // the next slice's submission between them.
  const double render_ms = sub.render_ms + ms_between(start, Clock::now());
  charge_measured(task, slice, render_ms);
  if (error) {
    fail_slice(task, render_ms, std::move(*error));
    slices_finished(t, std::numeric_limits<std::size_t>::max(), 1 + withdraw_slices(task));
    return;
  }
  if (render_ms >= kTrimAfterRenderMs) malloc_trim(0);
  std::vector<std::size_t> encode;  // frames that get their own image (not atlas tiles)
  {
    std::lock_guard lock(task.mu);
    task.render_ms += render_ms;
    int batches = 0;
    for (std::size_t k = 0; k < idx.size(); ++k) {
      batches = std::max(batches, frames[k].batch.index + 1);
      frames[k].batch.index += task.batches;  // batches counted over the whole job
      task.frames[idx[k]] = std::move(frames[k]);
      if (!task.members[task.member_of[idx[k]]].atlas) encode.push_back(idx[k]);
    }
    task.batches += batches;
    task.slice_left[slice] = encode.size();
    task.slice_encode_start[slice] = Clock::now();
  }
  if (encode.empty()) {
    slices_finished(t, slice, 0);
    return;
  }
  // Each frame on the encoder pool; this worker goes on to the next slice.
  for (std::size_t i : encode) {
    post_encode(task.cls, [this, t, slice, i] {
      Task& task = *t;
      const RenderJob& job = task.members[task.member_of[i]];
      const auto t0 = Clock::now();
      Image& img = task.frames[i].image;
      bool png = !job.jpeg || img.rgb.empty();
      std::vector<std::uint8_t> bytes;
      if (!png) {
        try {
          bytes = encode_jpeg(img, job.jpeg_quality);
        } catch (const std::exception& e) {
          // Never expected of a valid image; the frame still goes out, as PNG.
          std::fprintf(stderr, "beamcast-server: %s; sending PNG\n", e.what());
          png = true;
        }
      }
      if (png) bytes = encode_still(img, job.frame_format);
      const auto t1 = Clock::now();
      bool slice_complete = false;
      {
        std::lock_guard lock(task.mu);
        task.images[i] = std::move(bytes);
        task.is_jpeg[i] = png ? 0 : 1;
        task.encode_ms[i] = ms_between(t0, t1);
        img.rgb = {};  // the encoded image is what travels; free the pixels now
        slice_complete = --task.slice_left[slice] == 0;
        if (slice_complete) task.encode_wall_ms += ms_between(task.slice_encode_start[slice], t1);
      }
      if (slice_complete) slices_finished(t, slice, 0);
    });
  }
}

// A frame that is not JPEG: PNG with the server's settings, or the raw
// samples the connection asked for in hello.
std::vector<std::uint8_t> RenderService::encode_still(const Image& img, FrameFormat f) const {
  if (f == FrameFormat::kPng) return encode_png(img, png_);
  return encode_raw_frame(img.rgb, img.bit_depth, f);
}

// Marks `slice` done (none: max) and `dropped` more slices finished; sends the
// streamed parts that are ready, in slice order, and completes the task once
// every slice is finished. Parts and completion are serialized by emit_mu,
// so they leave in order whichever thread finishes which slice.
void RenderService::slices_finished(const TaskPtr& t, std::size_t slice, std::size_t dropped) {
  Task& task = *t;
  std::lock_guard emit(task.emit_mu);
  std::vector<RenderOutcome> parts;
  bool all = false;
  {
    std::lock_guard lock(task.mu);
    if (slice != std::numeric_limits<std::size_t>::max()) {
      task.slice_done[slice] = 1;
      ++task.finished;
    }
    task.finished += dropped;
    all = task.finished == task.slices.size();
    // The last slice goes with the completion (done), not as a part.
    if (task.streamed() && !task.error && !task.cancelled) {
      while (task.next_part + 1 < task.slices.size() && task.slice_done[task.next_part]) {
        parts.push_back(task.part(task.next_part++));
      }
    }
  }
  for (RenderOutcome& p : parts) {
    if (task.members[0].client_alive->load()) task.members[0].on_part(std::move(p));
  }
  if (all) complete(task);
}

// Every slice is finished: each member job gets its outcome.
void RenderService::complete(Task& task) {
  const auto now = Clock::now();
  // Every slice has rendered: the maps traced for it (trace_for) are the
  // renderer's cache's now, or dropped, but not held by a finished task that
  // an encode or a connection may keep alive a while.
  {
    std::lock_guard lock(mu_);
    task.options.photon_maps.reset();
  }
  for (std::size_t m = 0; m < task.members.size(); ++m) {
    RenderJob& job = task.members[m];
    RenderOutcome out;
    out.queue_ms = ms_between(job.arrived, task.started ? task.start : now);
    out.batched_requests = static_cast<int>(task.members.size());
    out.batched_views = static_cast<int>(task.cameras.size());
    out.render_ms = task.render_ms;
    out.encode_wall_ms = task.encode_wall_ms;
    out.slices = static_cast<int>(task.slices.size());
    out.frame_format = job.frame_format;
    if (task.cancelled || !job.client_alive->load()) {
      out.dropped = true;
      finish(job, std::move(out));
      continue;
    }
    if (task.error) {
      out.error = task.error;
      finish(job, std::move(out));
      continue;
    }
    if (task.streamed()) {
      out = task.part(task.slices.size() - 1);
      out.queue_ms = ms_between(job.arrived, task.start);
      finish(job, std::move(out));
      continue;
    }
    const std::size_t first = task.first_camera[m];
    const std::size_t n = job.cameras.size();
    for (std::size_t i = first; i < first + n; ++i) out.frames.push_back(std::move(task.frames[i]));
    if (job.atlas && !out.frames.empty()) {
      // One image of all the job's frames: composed and encoded here, once
      // every slice is in.
      const auto t0 = Clock::now();
      std::vector<const Image*> images;
      for (const FrameResult& f : out.frames) images.push_back(&f.image);
      out.atlas = make_atlas(images);
      for (FrameResult& f : out.frames) f.image.rgb = {};
      out.pngs.push_back(encode_still(out.atlas->image, job.frame_format));
      out.atlas->image.rgb = {};
      out.is_jpeg.push_back(0);
      out.encode_ms.push_back(ms_between(t0, Clock::now()));
      out.encode_wall_ms += out.encode_ms.back();
    } else {
      for (std::size_t i = first; i < first + n; ++i) {
        out.pngs.push_back(std::move(task.images[i]));
        out.is_jpeg.push_back(task.is_jpeg[i]);
        out.encode_ms.push_back(task.encode_ms[i]);
      }
    }
    finish(job, std::move(out));
  }
}

void RenderService::gather_batch(Task& first, std::unique_lock<std::mutex>& lock) {
  // Wait out the window on a condition of its own (so this worker swallows no
  // wake-up meant for an idle one), then take the matching queued jobs.
  const auto deadline = first.members.front().arrived + batch_window_;
  window_cv_.wait_until(lock, deadline, [&] { return stopping_; });
  int views = static_cast<int>(first.cameras.size());
  ClassQueue& q = queues_[static_cast<int>(first.cls)];
  for (auto c = q.by_client.begin(); c != q.by_client.end();) {
    std::deque<TaskPtr>& mine = c->second;
    for (auto it = mine.begin(); it != mine.end();) {
      Task& other = **it;
      const int n = static_cast<int>(other.cameras.size());
      if (!other.started && other.batch_key == first.batch_key && views + n <= batch_max_views_) {
        views += n;
        for (RenderJob& job : other.members) first.add(std::move(job));
        it = mine.erase(it);
        --q.tasks;
      } else {
        ++it;
      }
    }
    if (mine.empty()) {
      q.turns.erase(std::find(q.turns.begin(), q.turns.end(), c->first));
      c = q.by_client.erase(c);
    } else {
      ++c;
    }
  }
  first.slices = make_slices(first.cameras, first.options);
}

void RenderService::set_hold_batch_encodes(bool hold) {
  {
    std::lock_guard lock(encode_mu_);
    hold_batch_encodes_ = hold;
  }
  encode_cv_.notify_all();
}

RenderService::InteractiveRender::InteractiveRender(RenderService* service, bool interactive)
    : service_(interactive ? service : nullptr) {
  if (service_ == nullptr) return;
  std::lock_guard lock(service_->encode_mu_);
  ++service_->interactive_rendering_;
}

RenderService::InteractiveRender::~InteractiveRender() {
  if (service_ == nullptr) return;
  {
    std::lock_guard lock(service_->encode_mu_);
    --service_->interactive_rendering_;
  }
  service_->encode_cv_.notify_all();
}

void RenderService::set_interactive_window(std::chrono::milliseconds window) {
  interactive_window_ms_.store(window.count());
}

void RenderService::set_batch_window(std::chrono::milliseconds window, int max_views) {
  std::lock_guard lock(mu_);
  batch_window_ = window;
  batch_max_views_ = std::max(1, max_views);
}

// One pool task per queued encode; each runs the most urgent queued encode,
// so an interactive frame is encoded before the batch frames queued ahead of
// it. A batch encode does not start while an interactive slice renders
// (set_hold_batch_encodes); an interactive one posted meanwhile still runs.
void RenderService::post_encode(WorkClass c, std::function<void()> fn) {
  {
    std::lock_guard lock(encode_mu_);
    encode_queue_[static_cast<int>(c)].push_back(std::move(fn));
  }
  encode_cv_.notify_all();
  boost::asio::post(encoders_, [this] {
    std::function<void()> next;
    {
      std::unique_lock lock(encode_mu_);
      auto& interactive = encode_queue_[static_cast<int>(WorkClass::kInteractive)];
      auto& batch = encode_queue_[static_cast<int>(WorkClass::kBatch)];
      encode_cv_.wait(lock, [&] {
        return !interactive.empty() || batch.empty() || !hold_batch_encodes_ ||
               interactive_rendering_ == 0 || encoders_stopping_;
      });
      for (auto& q : encode_queue_) {
        if (!q.empty()) {
          next = std::move(q.front());
          q.pop_front();
          break;
        }
      }
    }
    if (next) next();
  });
}

void RenderService::stop() {
  {
    std::lock_guard lock(mu_);
    if (stopping_ && workers_.empty()) return;
    stopping_ = true;
  }
  cv_.notify_all();
  window_cv_.notify_all();
  for (auto& t : workers_) t.join();
  workers_.clear();
  // A trace in progress finishes (or its token stops it: cancel_all);
  // queued ones are dropped with their tasks below.
  {
    std::lock_guard lock(mu_);
    tracers_stopping_ = true;
    traces_in_flight_ -= static_cast<int>(trace_queue_.size());
    trace_queue_.clear();
  }
  trace_cv_.notify_all();
  tracers_.clear();  // SizedThread joins
  // What is still queued is dropped (slices of a job being encoded included:
  // that job completes as dropped when its encodes are done).
  std::vector<std::pair<TaskPtr, std::size_t>> left;
  {
    std::lock_guard lock(mu_);
    for (ClassQueue& q : queues_) {
      std::vector<TaskPtr> tasks;
      for (auto& [client, mine] : q.by_client) tasks.insert(tasks.end(), mine.begin(), mine.end());
      for (const TaskPtr& t : tasks) left.emplace_back(t, withdraw_locked(*t));
    }
  }
  {
    std::lock_guard lock(encode_mu_);
    encoders_stopping_ = true;
  }
  encode_cv_.notify_all();
  for (auto& [t, n] : left) {
    {
      std::lock_guard lock(t->mu);
      t->cancelled = true;
      if (t->frames.size() != t->cameras.size()) t->prepare();  // never started
    }
    slices_finished(t, std::numeric_limits<std::size_t>::max(), n);
  }
  encoders_.join();
}

}  // namespace beamcast
