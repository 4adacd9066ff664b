#include "server/render_service.hpp"

#include <boost/asio/post.hpp>

#include <algorithm>
#include <cstdio>
#include <iterator>
#include <optional>

#include "render/gl_util.hpp"
#include "render/image.hpp"
#include "render/jpeg.hpp"

namespace beamcast {
namespace {

using Clock = std::chrono::steady_clock;

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
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
  void fail_next_render_for_test() override { renderer_.fail_next_render_for_test(); }

 private:
  Renderer renderer_;
};

}  // namespace

RendererFactory gl_renderer_factory(const RendererOptions& opts) {
  return [opts] { return std::make_unique<GlFrameRenderer>(opts); };
}

RenderService::RenderService(RendererFactory factory, int workers, int encode_threads,
                             int png_level, int png_filters, int max_inflight)
    : factory_(std::move(factory)),
      png_level_(png_level),
      png_filters_(png_filters),
      max_inflight_(max_inflight),
      encoders_(static_cast<std::size_t>(std::max(1, encode_threads))) {
  for (int i = 0; i < std::max(1, workers); ++i) {
    workers_.emplace_back([this, i] { worker_main(i); });
  }
}

RenderService::~RenderService() { stop(); }

std::string RenderService::wait_ready() {
  std::unique_lock lock(mu_);
  ready_cv_.wait(lock, [&] { return ready_ == static_cast<int>(workers_.size()); });
  if (description_.empty()) throw std::runtime_error(failure_);
  return description_;
}

bool RenderService::submit(RenderJob job) {
  // Admission counts everything accepted and not yet answered (queued,
  // rendering, encoding), so the queue can never grow without bound.
  int current = inflight_.load();
  do {
    if (current >= max_inflight_) return false;
  } while (!inflight_.compare_exchange_weak(current, current + 1));
  {
    std::lock_guard lock(mu_);
    if (stopping_) {
      inflight_.fetch_sub(1);
      return false;
    }
    queue_.push_back(std::move(job));
  }
  cv_.notify_one();
  return true;
}

int RenderService::queued() const {
  std::lock_guard lock(mu_);
  return static_cast<int>(queue_.size());
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

void RenderService::worker_main(int index) {
  std::unique_ptr<FrameRenderer> renderer = make_renderer(index);
  bool rebuild_pending = false;  // a GL error discarded the renderer, no new one yet
  {
    std::lock_guard lock(mu_);
    ++ready_;
  }
  ready_cv_.notify_all();

  for (;;) {
    std::vector<RenderJob> jobs;
    {
      std::unique_lock lock(mu_);
      cv_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping
      RenderJob first = std::move(queue_.front());
      queue_.pop_front();
      jobs = gather_batch(std::move(first), lock);
    }
    const auto start = Clock::now();
    // Jobs whose client went away cost no GPU time.
    std::vector<RenderJob> live;
    for (RenderJob& job : jobs) {
      if (!job.client_alive->load()) {
        RenderOutcome out;
        out.queue_ms = ms_between(job.arrived, start);
        out.dropped = true;
        dropped_.fetch_add(1);
        finish(job, std::move(out));
      } else {
        live.push_back(std::move(job));
      }
    }
    if (live.empty()) continue;
    std::vector<Camera> cameras;
    for (const RenderJob& job : live) cameras.insert(cameras.end(), job.cameras.begin(), job.cameras.end());
    std::optional<ErrorInfo> error;
    std::vector<FrameResult> frames;
    bool gl_failed = false;
    if (!renderer) {
      error = ErrorInfo{"internal", "no renderer: " + failure_, ""};
    } else {
      try {
        int inject = inject_failures_.load();
        while (inject > 0 && !inject_failures_.compare_exchange_weak(inject, inject - 1)) {
        }
        if (inject > 0) renderer->fail_next_render_for_test();
        // Jobs share a render only with the same stored scene and default
        // options (RenderJob::batch_key), so the first job's options hold for all.
        frames = renderer->render(*live.front().scene, cameras, live.front().options);
      } catch (const GlError& e) {
        std::fprintf(stderr, "beamcast-server: render worker %d: GL error, rebuilding its context: %s\n",
                     index, e.what());
        error = ErrorInfo{"internal", std::string("render failed: ") + e.what(), ""};
        gl_failed = true;
      } catch (const std::exception& e) {
        std::fprintf(stderr, "beamcast-server: render failed: %s\n", e.what());
        error = ErrorInfo{"internal", std::string("render failed: ") + e.what(), ""};
      }
    }
    const double render_ms = ms_between(start, Clock::now());
    std::size_t at = 0;
    for (RenderJob& job : live) {
      RenderOutcome out;
      out.queue_ms = ms_between(job.arrived, start);
      out.batched_requests = static_cast<int>(live.size());
      out.batched_views = static_cast<int>(cameras.size());
      if (error) {
        out.error = error;
        finish(job, std::move(out));
        continue;
      }
      out.render_ms = render_ms;
      const std::size_t n = job.cameras.size();
      out.frames.assign(std::make_move_iterator(frames.begin() + static_cast<std::ptrdiff_t>(at)),
                        std::make_move_iterator(frames.begin() + static_cast<std::ptrdiff_t>(at + n)));
      at += n;
      encode_and_finish(std::move(job), std::move(out));
    }
    // After the failed jobs are answered: the old context goes before the
    // new one is made current on this thread. A worker whose rebuild fails
    // tries again before its next job (and answers `internal` meanwhile).
    rebuild_pending = rebuild_pending || gl_failed;
    if (gl_failed || !renderer) {
      renderer.reset();
      renderer = make_renderer(index);
      if (renderer && rebuild_pending) {
        rebuilds_.fetch_add(1);
        rebuild_pending = false;
      }
    }
  }
}

std::vector<RenderJob> RenderService::gather_batch(RenderJob first,
                                                   std::unique_lock<std::mutex>& lock) {
  std::vector<RenderJob> jobs;
  const void* key = first.batch_key;
  const auto deadline = first.arrived + batch_window_;
  int views = static_cast<int>(first.cameras.size());
  jobs.push_back(std::move(first));
  if (key == nullptr || batch_window_.count() <= 0) return jobs;
  // Wait out the window on a condition of its own (so this worker swallows no
  // wake-up meant for an idle one), then take the matching jobs.
  window_cv_.wait_until(lock, deadline, [&] { return stopping_; });
  for (auto it = queue_.begin(); it != queue_.end();) {
    const int n = static_cast<int>(it->cameras.size());
    if (it->batch_key == key && views + n <= batch_max_views_) {
      views += n;
      jobs.push_back(std::move(*it));
      it = queue_.erase(it);
    } else {
      ++it;
    }
  }
  return jobs;
}

void RenderService::set_batch_window(std::chrono::milliseconds window, int max_views) {
  std::lock_guard lock(mu_);
  batch_window_ = window;
  batch_max_views_ = std::max(1, max_views);
}

// Encodes every frame in parallel on the CPU pool; the last one to finish
// completes the job, while the worker moves on to the next render.
void RenderService::encode_and_finish(RenderJob job, RenderOutcome out) {
  struct EncodeState {
    RenderJob job;
    RenderOutcome out;
    std::atomic<std::size_t> remaining;
    Clock::time_point start;
  };
  if (job.atlas && !out.frames.empty()) {
    std::vector<const Image*> images;
    for (const FrameResult& f : out.frames) images.push_back(&f.image);
    out.atlas = make_atlas(images);
    for (FrameResult& f : out.frames) f.image.rgb = {};
  }
  // One PNG per frame, or the atlas alone.
  const std::size_t n = out.atlas ? 1 : out.frames.size();
  auto st = std::make_shared<EncodeState>();
  st->out = std::move(out);
  st->out.pngs.resize(n);
  st->out.encode_ms.resize(n);
  st->out.is_jpeg.assign(n, 0);
  st->remaining = n;
  st->start = Clock::now();
  st->job = std::move(job);
  for (std::size_t i = 0; i < n; ++i) {
    boost::asio::post(encoders_, [this, st, i] {
      const auto t0 = Clock::now();
      Image& img = st->out.atlas ? st->out.atlas->image : st->out.frames[i].image;
      bool png = !st->job.jpeg || img.rgb.empty();
      if (!png) {
        try {
          st->out.pngs[i] = encode_jpeg(img, st->job.jpeg_quality);
        } catch (const std::exception& e) {
          // Never expected of a valid image; the frame still goes out, as PNG.
          std::fprintf(stderr, "beamcast-server: %s; sending PNG\n", e.what());
          png = true;
        }
      }
      if (png) st->out.pngs[i] = encode_png(img, png_level_, png_filters_);
      st->out.is_jpeg[i] = png ? 0 : 1;
      st->out.encode_ms[i] = ms_between(t0, Clock::now());
      img.rgb = {};  // the PNG is what travels; free the pixels now
      if (st->remaining.fetch_sub(1) == 1) {
        st->out.encode_wall_ms = ms_between(st->start, Clock::now());
        finish(st->job, std::move(st->out));
      }
    });
  }
  if (n == 0) finish(st->job, std::move(st->out));
}

void RenderService::stop() {
  std::deque<RenderJob> left;
  {
    std::lock_guard lock(mu_);
    if (stopping_ && workers_.empty()) return;
    stopping_ = true;
    left.swap(queue_);
  }
  cv_.notify_all();
  window_cv_.notify_all();
  for (auto& t : workers_) t.join();
  workers_.clear();
  encoders_.join();
  for (auto& job : left) {
    RenderOutcome out;
    out.dropped = true;
    finish(job, std::move(out));
  }
}

}  // namespace beamcast
