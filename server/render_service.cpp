#include "server/render_service.hpp"

#include <boost/asio/post.hpp>

#include <cstdio>

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

void RenderService::worker_main(int index) {
  std::unique_ptr<FrameRenderer> renderer;
  try {
    renderer = factory_();
    std::lock_guard lock(mu_);
    if (description_.empty()) description_ = renderer->description();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "beamcast-server: render worker %d: %s\n", index, e.what());
    std::lock_guard lock(mu_);
    failure_ = e.what();
  }
  {
    std::lock_guard lock(mu_);
    ++ready_;
  }
  ready_cv_.notify_all();

  for (;;) {
    RenderJob job;
    {
      std::unique_lock lock(mu_);
      cv_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping
      job = std::move(queue_.front());
      queue_.pop_front();
    }
    RenderOutcome out;
    const auto start = Clock::now();
    out.queue_ms = ms_between(job.arrived, start);
    if (!job.client_alive->load()) {
      out.dropped = true;  // a disconnected client costs no GPU time
      dropped_.fetch_add(1);
      finish(job, std::move(out));
      continue;
    }
    if (!renderer) {
      out.error = ErrorInfo{"internal", "no renderer: " + failure_, ""};
      finish(job, std::move(out));
      continue;
    }
    try {
      out.frames = renderer->render(*job.scene, job.cameras, job.options);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "beamcast-server: render failed: %s\n", e.what());
      out.error = ErrorInfo{"internal", std::string("render failed: ") + e.what(), ""};
      finish(job, std::move(out));
      continue;
    }
    out.render_ms = ms_between(start, Clock::now());

    // Encode every frame in parallel on the CPU pool; the last one to finish
    // completes the job, while this worker moves on to the next render.
    struct EncodeState {
      RenderJob job;
      RenderOutcome out;
      std::atomic<std::size_t> remaining;
      Clock::time_point start;
    };
    const std::size_t n = out.frames.size();
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
        Image& img = st->out.frames[i].image;
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
