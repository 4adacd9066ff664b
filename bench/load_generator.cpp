// The load generator behind `beamcast load` (its options: cli/load_command.cpp;
// LoadArgs: load_generator.hpp), for beamcast-server. N connections on one
// Asio event loop, closed loop (each connection waits for its answer) or open
// loop (a fixed request rate, latency measured from each request's scheduled
// time so a slow server cannot hide queueing: no coordinated omission). Every
// frame received is decoded and checked; a fraction is compared with a local
// render of the same pose (the offline GL renderer, same code as the server).
//
// Traffic classes: by default one class ("load") made of the options above. With
// --preview-connections and/or --batch-connections the run is a mix (issue 13):
// a preview-like closed loop (one camera moving along an orbit every frame,
// `"quality": "auto"`, as server/preview/preview.js sends) next to a batch-like
// loop (multi-camera orbit renders, open loop at --batch-rate or closed loop),
// each class with its own latency histogram, throughput and errors. Every class
// reports each connection's throughput and the max/min ratio (fairness).
#include "bench/load_generator.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <boost/asio.hpp>
#include <nlohmann/json.hpp>

#include "bench/load_generator.hpp"

#include "client/client.hpp"
#include "client/latency_histogram.hpp"
#include "client/resilient_client.hpp"
#include "protocol/bounded_json.hpp"
#include "protocol/data_dir.hpp"
#include "protocol/framing.hpp"
#include "protocol/render_response.hpp"
#include "protocol/scene_json.hpp"
#include "render/image.hpp"
#include "render/jpeg.hpp"
#include "protocol/frame_format.hpp"
#include "render/renderer.hpp"

namespace beamcast::bench {
namespace {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;
using Clock = std::chrono::steady_clock;
using json = nlohmann::json;
using client::LatencyHistogram;


// ---- camera poses ---------------------------------------------------------

struct PoseSource {
  std::array<double, 3> target{0, 0, 0};
  double radius = 5, azimuth = 0, elevation = 0.3, fov = 45;
  int size = 256;

  explicit PoseSource(const json& cam, int sz) : size(sz) {
    const auto p = cam.at("position").get<std::array<double, 3>>();
    if (cam.contains("target")) target = cam.at("target").get<std::array<double, 3>>();
    fov = cam.value("fov_y", 45.0);
    const double dx = p[0] - target[0], dy = p[1] - target[1], dz = p[2] - target[2];
    radius = std::sqrt(dx * dx + dy * dy + dz * dz);
    azimuth = std::atan2(dx, dz);
    elevation = std::asin(std::clamp(dy / radius, -1.0, 1.0));
  }
  json camera(const std::string& name, double az, double el, double r) const {
    return {{"name", name},
            {"position",
             {target[0] + r * std::cos(el) * std::sin(az), target[1] + r * std::sin(el),
              target[2] + r * std::cos(el) * std::cos(az)}},
            {"target", target},
            {"fov_y", fov},
            {"width", size},
            {"height", size}};
  }
  // The cameras of request number `seq` (deterministic, so a reference render
  // of the same request can be made later from seq alone).
  json cameras_for(std::uint64_t seq, const std::string& mode, int count) const {
    const std::string m = mode == "mix" ? (seq % 3 == 0 ? "fixed" : seq % 3 == 1 ? "orbit" : "random")
                                        : mode;
    const int n = count > 0 ? count : (seq % 4 == 3 ? 4 : 1);
    std::mt19937_64 rng(seq * 0x9E3779B97F4A7C15ull + 1);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    json cams = json::array();
    for (int k = 0; k < n; ++k) {
      double az = azimuth + 2 * std::numbers::pi * k / n, el = elevation, r = radius;
      if (m == "orbit") az += 2 * std::numbers::pi * static_cast<double>(seq % 120) / 120.0;
      if (m == "random") {
        az = 2 * std::numbers::pi * u(rng);
        el = (-30.0 + 90.0 * u(rng)) * std::numbers::pi / 180.0;  // keep clear of the up axis
        r = radius * (0.7 + 0.6 * u(rng));
      }
      cams.push_back(camera("c" + std::to_string(k), az, el, r));
    }
    return cams;
  }
};

// ---- results ----------------------------------------------------------------

struct Results {
  std::mutex mu;
  LatencyHistogram latency, queue_ms, render_ms, encode_ms, server_ms;
  LatencyHistogram busy_latency;  // how fast refusals come back
  std::map<std::string, std::uint64_t> errors;
  std::uint64_t sent = 0, ok = 0, frames = 0, bytes = 0, skipped = 0;
  // Verification (filled by the verifier threads).
  std::uint64_t decoded = 0, decode_failed = 0, size_mismatch = 0;
  std::uint64_t ref_checked = 0, ref_failed = 0;
  int ref_max_diff = 0;
  std::vector<std::string> failures;  // first few, for the report
  // Retries: requests sent again, connections opened again, scenes put again
  // (unknown_scene), retries the budget refused.
  std::uint64_t retries = 0, reconnects = 0, reputs = 0, budget_refused = 0;
  // Per timeline bucket (by the time an answer or error arrived).
  struct Bucket {
    LatencyHistogram latency;
    std::uint64_t ok = 0, errors = 0, retries = 0;
  };
  std::map<long long, Bucket> timeline;
};

// One class of traffic: how its requests look and how they are sent, and what
// came back (counters guarded by Results::mu).
struct TrafficClass {
  std::string name;
  int connections = 1;
  double rate = 0;   // open loop requests/s over the class; 0: closed loop
  int pipeline = 1;  // closed loop: in flight per connection
  int inflight_cap = 8;  // open loop: in flight per connection before a skip
  int cameras = 0;       // 0: mix of 1 and 4
  std::string poses = "mix";
  bool preview = false;  // one moving camera per request, quality "auto"
  double budget_ms = 33;
  double step_rad = 0;
  double verify_fraction = 0;
  std::optional<PoseSource> pose_source;
  // State (event-loop thread only).
  std::uint64_t next_seq = 0;
  std::size_t rr = 0;
  // Results (under Results::mu).
  LatencyHistogram latency;
  std::map<std::string, std::uint64_t> errors;
  std::uint64_t sent = 0, ok = 0, frames = 0, bytes = 0, skipped = 0;
  std::uint64_t still_frames = 0, jpeg_frames = 0;  // preview: full-accuracy and interactive
  std::map<int, std::uint64_t> levels;              // preview: frames per quality level
};

void note_failure(Results& r, std::string what) {
  if (r.failures.size() < 5) r.failures.push_back(std::move(what));
}

// ---- frame verification -----------------------------------------------------

struct VerifyJob {
  std::vector<std::uint8_t> png;  // or a JPEG (interactive preview frames), or raw samples
  bool jpeg = false;
  FrameFormat format = FrameFormat::kPng;  // when not JPEG
  int width = 0, height = 0, bit_depth = 8;
  json camera;     // set for a reference comparison
  std::uint64_t seq = 0;
};

class Verifier {
 public:
  Verifier(Results& r, const json& scene_json, const std::string& scene_file, int tolerance)
      : results_(r), tolerance_(tolerance) {
    SceneLoadOptions opts;
    opts.assets_dir = std::filesystem::path(scene_file).parent_path();
    scene_ = parse_scene(scene_json, opts);
    // Decoding every frame: two threads; reference renders: one (its own GL context).
    for (int i = 0; i < 2; ++i) threads_.emplace_back([this] { decode_loop(); });
    ref_thread_ = std::thread([this] { reference_loop(); });
  }
  ~Verifier() { finish(); }

  void push(VerifyJob job) {
    std::lock_guard lock(mu_);
    (job.camera.is_null() ? jobs_ : ref_jobs_).push_back(std::move(job));
    cv_.notify_all();
  }
  std::size_t backlog() {
    std::lock_guard lock(mu_);
    return jobs_.size() + ref_jobs_.size();
  }
  void finish() {
    {
      std::lock_guard lock(mu_);
      if (done_) return;
      done_ = true;
      cv_.notify_all();
    }
    for (auto& t : threads_) t.join();
    ref_thread_.join();
  }

 private:
  std::optional<Image> decode(const VerifyJob& job) {
    try {
      Image img = job.jpeg                          ? decode_jpeg(job.png)
                  : job.format == FrameFormat::kPng ? decode_png(job.png)
                                                    : Image{job.width, job.height, job.bit_depth,
                                                            decode_raw_frame(job.png, job.width,
                                                                             job.height,
                                                                             job.bit_depth,
                                                                             job.format)};
      std::lock_guard lock(results_.mu);
      ++results_.decoded;
      if (img.width != job.width || img.height != job.height) {
        ++results_.size_mismatch;
        note_failure(results_, "request " + std::to_string(job.seq) + ": frame is " +
                                   std::to_string(img.width) + "x" + std::to_string(img.height));
        return std::nullopt;
      }
      return img;
    } catch (const std::exception& e) {
      std::lock_guard lock(results_.mu);
      ++results_.decode_failed;
      note_failure(results_, "request " + std::to_string(job.seq) + ": " + e.what());
      return std::nullopt;
    }
  }
  bool next(std::deque<VerifyJob>& q, VerifyJob* out) {
    std::unique_lock lock(mu_);
    cv_.wait(lock, [&] { return done_ || !q.empty(); });
    if (q.empty()) return false;
    *out = std::move(q.front());
    q.pop_front();
    return true;
  }
  void decode_loop() {
    VerifyJob job;
    while (next(jobs_, &job)) decode(job);
  }
  void reference_loop() {
    std::unique_ptr<Renderer> renderer;
    VerifyJob job;
    while (next(ref_jobs_, &job)) {
      const std::optional<Image> got = decode(job);
      if (!got) continue;
      try {
        if (!renderer) renderer = std::make_unique<Renderer>();
        const Camera cam = parse_camera(job.camera, "/camera", SceneLimits{});
        const Image want = renderer->render(scene_, {cam}).at(0).image;
        int max_diff = 0;
        for (std::size_t i = 0; i < want.rgb.size(); ++i) {
          max_diff = std::max(max_diff, std::abs(int(want.rgb[i]) - int(got->rgb[i])));
        }
        std::lock_guard lock(results_.mu);
        ++results_.ref_checked;
        results_.ref_max_diff = std::max(results_.ref_max_diff, max_diff);
        if (max_diff > tolerance_) {
          ++results_.ref_failed;
          note_failure(results_, "request " + std::to_string(job.seq) + " camera " +
                                     job.camera.value("name", "") + ": differs from the local " +
                                     "render by " + std::to_string(max_diff) + " levels");
        }
      } catch (const std::exception& e) {
        std::lock_guard lock(results_.mu);
        ++results_.ref_failed;
        note_failure(results_, std::string("reference render failed: ") + e.what());
      }
    }
  }

  Results& results_;
  int tolerance_;
  Scene scene_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<VerifyJob> jobs_, ref_jobs_;
  bool done_ = false;
  std::vector<std::thread> threads_;
  std::thread ref_thread_;
};

// ---- connections --------------------------------------------------------------

class Load;

// The id of each connection's scene.put, before its renders (ids from 1).
constexpr std::int64_t kScenePutId = -1;

class Conn : public std::enable_shared_from_this<Conn> {
 public:
  Conn(Load& load, asio::io_context& io, int index, TrafficClass& cls)
      : load_(load), socket_(io), index_(index), cls_(cls) {}
  void start(const tcp::resolver::results_type& endpoints);
  // Opens the connection (again after a failure), says hello, puts the scene.
  void connect();
  // Sends request `seq`, timed from `intended` (its scheduled time).
  void send_render(std::uint64_t seq, Clock::time_point intended);
  std::size_t inflight() const { return pending_.size(); }
  TrafficClass& traffic_class() const { return cls_; }
  int index() const { return index_; }
  // Answered requests and their frames (this connection's throughput).
  std::uint64_t ok_requests() const { return ok_requests_; }
  std::uint64_t ok_frames() const { return ok_frames_; }
  bool ready() const { return ready_ && !dead_; }
  // Still responsible for requests (answered or to be sent again).
  bool live() const { return !dead_; }
  void close() {
    closing_ = true;
    boost::system::error_code ignored;
    socket_.close(ignored);
  }

 private:
  struct Pending {
    std::uint64_t seq;
    Clock::time_point intended;
    json cameras;
    json params;  // as sent, to send again after a reconnect
  };
  void send_pending(Pending p);
  void write(std::vector<std::uint8_t> frame);
  void do_write();
  void read_header();
  void on_message(json msg, std::vector<std::uint8_t> binary);
  void fail(const std::string& why);
  // A transport failure: reconnect and send the unanswered requests again
  // (retries), or give up (fail) when the attempts are spent.
  void on_transport_error(const std::string& why);

  Load& load_;
  tcp::socket socket_;
  tcp::resolver::results_type endpoints_;
  // Handlers of an earlier socket (completing with an error after a
  // reconnect) carry an older generation and are ignored.
  std::uint64_t generation_ = 0;
  int attempt_ = 0;  // consecutive failed tries; reset by an answer
  bool closing_ = false;
  int index_;
  TrafficClass& cls_;
  std::uint64_t frame_no_ = 0;  // preview: this connection's frames so far (its orbit position)
  std::uint64_t ok_requests_ = 0, ok_frames_ = 0;
  bool ready_ = false, dead_ = false, writing_ = false;
  std::deque<std::vector<std::uint8_t>> writes_;
  std::array<std::uint8_t, kFrameHeaderSize> header_{};
  std::vector<std::uint8_t> body_;
  std::map<std::int64_t, Pending> pending_;
  std::int64_t next_id_ = 1;
};

class Load {
 public:
  Load(const LoadArgs& a, json scene_json, std::string scene_id,
       std::vector<std::unique_ptr<TrafficClass>> cls)
      : args(a),
        scene_id(std::move(scene_id)),
        scene_json(scene_json),
        classes(std::move(cls)),
        verifier(results, scene_json, a.scene_file, a.tolerance),
        rng(static_cast<std::uint64_t>(::getpid())) {}

  int run(const client::Endpoint& ep) {
    tcp::resolver resolver(io);
    const auto endpoints = resolver.resolve(ep.host, std::to_string(ep.port));
    start = Clock::now();
    int index = 0;
    for (auto& cls : classes) {
      for (int i = 0; i < cls->connections; ++i) {
        conns.push_back(std::make_shared<Conn>(*this, io, index++, *cls));
        conns.back()->start(endpoints);
      }
    }
    asio::steady_timer ticker(io);
    tick(ticker);
    io.run();
    verifier.finish();
    return 0;
  }

  // Called by a connection when it is ready (closed loop: starts its loop) or
  // when an answer arrived (closed loop: sends the next).
  void on_ready(Conn& c) {
    if (c.traffic_class().rate > 0) return;
    // Requests sent again after a reconnect count towards the pipeline.
    for (auto i = c.inflight(); i < static_cast<std::size_t>(c.traffic_class().pipeline); ++i) {
      maybe_send(c, Clock::now());
    }
  }
  void on_answer(Conn& c, bool busy) {
    const bool closed = c.traffic_class().rate <= 0;
    if (closed && busy && args.busy_backoff_ms > 0) {
      auto t = std::make_shared<asio::steady_timer>(io);
      t->expires_after(std::chrono::microseconds(static_cast<long long>(args.busy_backoff_ms * 1000)));
      t->async_wait([this, t, conn = c.shared_from_this()](const boost::system::error_code&) {
        maybe_send(*conn, Clock::now());
        maybe_stop();
      });
      return;
    }
    if (closed) maybe_send(c, Clock::now());
    maybe_stop();
  }
  bool sending_over() const {
    return stopping || (args.requests > 0 && total_sent >= static_cast<std::uint64_t>(args.requests));
  }
  void on_dead() { maybe_stop(); }
  // The timeline bucket of `now` (caller holds results.mu).
  Results::Bucket& bucket(Clock::time_point now) {
    const double ms = std::chrono::duration<double, std::milli>(now - start).count();
    return results.timeline[static_cast<long long>(ms / std::max(1.0, args.timeline_ms))];
  }

  const LoadArgs& args;
  std::string scene_id;
  json scene_json;  // stored by every connection on its server (Conn::start)
  std::vector<std::unique_ptr<TrafficClass>> classes;
  Results results;
  Verifier verifier;
  // One budget for the whole run: retries stay within ~10% of requests.
  client::RetryBudget budget;
  client::RetryPolicy policy;
  std::mt19937_64 rng;  // backoff jitter
  asio::io_context io;
  std::vector<std::shared_ptr<Conn>> conns;
  Clock::time_point start;
  std::uint64_t total_sent = 0;  // over all classes (--requests)
  bool stopping = false;
  Clock::time_point stop_at_deadline;

 private:
  void maybe_send(Conn& c, Clock::time_point intended) {
    if (sending_over() || !c.ready()) return;
    ++total_sent;
    c.send_render(c.traffic_class().next_seq++, intended);
  }
  void maybe_stop() {
    if (!sending_over()) return;
    for (auto& c : conns) {
      if (c->live() && c->inflight() > 0) return;  // answers (or retries) to come
    }
    for (auto& c : conns) c->close();
    io.stop();
  }
  void tick(asio::steady_timer& t) {
    const auto now = Clock::now();
    const double elapsed = std::chrono::duration<double>(now - start).count();
    if (!stopping && elapsed >= args.duration_s && args.requests == 0) {
      stopping = true;
      stop_at_deadline = now + std::chrono::milliseconds(static_cast<long long>(args.timeout_s * 1000));
    }
    if (stopping && now > stop_at_deadline) {
      // Answers that never came count as errors.
      std::lock_guard lock(results.mu);
      for (auto& c : conns) {
        const std::size_t n = c->live() ? c->inflight() : 0;
        results.errors["no_answer"] += n;
        if (n > 0) c->traffic_class().errors["no_answer"] += n;
      }
      for (auto& c : conns) c->close();
      io.stop();
      return;
    }
    bool open_loop = false;
    for (auto& cls : classes) {
      if (cls->rate <= 0) continue;
      open_loop = true;
      // Open loop: every request of the class due by now is sent, round robin
      // over its connections, timed from its own scheduled instant.
      const auto due = static_cast<std::uint64_t>(elapsed * cls->rate);
      while (cls->next_seq < due && !sending_over()) {
        const auto intended = start + std::chrono::duration_cast<Clock::duration>(
                                          std::chrono::duration<double>(cls->next_seq / cls->rate));
        Conn* c = nullptr;
        for (std::size_t k = 0; k < conns.size() && !c; ++k) {
          Conn& cand = *conns[(cls->rr++) % conns.size()];
          if (&cand.traffic_class() == cls.get() && cand.ready() &&
              cand.inflight() < static_cast<std::size_t>(cls->inflight_cap)) {
            c = &cand;
          }
        }
        ++total_sent;
        if (!c) {
          // Every connection is at its in-flight cap: the request is not
          // sent (counted, not hidden).
          ++cls->next_seq;
          std::lock_guard lock(results.mu);
          ++results.skipped;
          ++cls->skipped;
          continue;
        }
        c->send_render(cls->next_seq++, intended);
      }
    }
    progress(now, false);
    maybe_stop();
    t.expires_after(std::chrono::milliseconds(open_loop ? 2 : 50));
    t.async_wait([this, &t](const boost::system::error_code& ec) {
      if (!ec) tick(t);
    });
  }

 public:
  void progress(Clock::time_point now, bool final) {
    if (args.quiet) return;
    if (!final && now - last_progress < std::chrono::seconds(1)) return;
    last_progress = now;
    const double t = std::chrono::duration<double>(now - start).count();
    std::lock_guard lock(results.mu);
    std::uint64_t errs = 0;
    for (auto& [k, v] : results.errors) errs += v;
    std::fprintf(stderr,
                 "%sload %6.1fs  sent %llu  ok %llu  errors %llu  frames/s %.1f  p50 %.1f ms  "
                 "p99 %.1f ms  verify backlog %zu%s",
                 isatty(2) ? "\r" : "", t, (unsigned long long)results.sent,
                 (unsigned long long)results.ok, (unsigned long long)errs,
                 t > 0 ? results.frames / t : 0.0, results.latency.percentile_ms(0.5),
                 results.latency.percentile_ms(0.99), verifier.backlog(),
                 isatty(2) && !final ? "   " : "\n");
  }
  Clock::time_point last_progress{};
};

void Conn::start(const tcp::resolver::results_type& endpoints) {
  endpoints_ = endpoints;
  connect();
}

void Conn::connect() {
  const std::uint64_t gen = ++generation_;
  socket_ = tcp::socket(socket_.get_executor());
  ready_ = false;
  writing_ = false;
  writes_.clear();
  asio::async_connect(socket_, endpoints_,
                      [self = shared_from_this(), gen](const boost::system::error_code& ec,
                                                       const tcp::endpoint&) {
                        if (gen != self->generation_ || self->closing_) return;
                        if (ec) return self->on_transport_error("connect_failed");
                        self->socket_.set_option(tcp::no_delay(true));
                        self->read_header();
                        const LoadArgs& a = self->load_.args;
                        if (!a.token.empty() || a.frame_format != "png") {
                          json params = {{"protocol", 1}};
                          if (!a.token.empty()) params["token"] = a.token;
                          if (a.frame_format != "png") params["frame_format"] = a.frame_format;
                          json hello = {{"id", 0}, {"method", "hello"}, {"params", params}};
                          self->write(encode_frame(hello.dump()));
                        }
                        // The scene on this connection's own server (behind a
                        // load balancer each connection may reach another one;
                        // the same content again is a no-op): ready once it is
                        // stored.
                        json put = {{"id", kScenePutId},
                                    {"method", "scene.put"},
                                    {"params",
                                     {{"scene_id", self->load_.scene_id}, {"scene", self->load_.scene_json}}}};
                        self->write(encode_frame(put.dump()));
                      });
}

void Conn::send_render(std::uint64_t seq, Clock::time_point intended) {
  const PoseSource& poses = *cls_.pose_source;
  json params = {{"scene_id", load_.scene_id}};
  json cams;
  if (cls_.preview) {
    // As the preview page sends while the camera is dragged: one camera, a
    // new pose every frame (so the server infers motion), quality "auto".
    const double az = poses.azimuth + 0.7 * index_ + cls_.step_rad * static_cast<double>(frame_no_++);
    cams = json::array({poses.camera("view", az, poses.elevation, poses.radius)});
    params["quality"] = "auto";
    params["budget_ms"] = cls_.budget_ms;
  } else {
    cams = poses.cameras_for(seq, cls_.poses, cls_.cameras);
  }
  params["cameras"] = cams;
  {
    std::lock_guard lock(load_.results.mu);
    ++load_.results.sent;
    ++cls_.sent;
  }
  send_pending(Pending{seq, intended, std::move(cams), std::move(params)});
}

void Conn::send_pending(Pending p) {
  const std::int64_t id = next_id_++;
  const json req = {{"id", id}, {"method", "render"}, {"params", p.params}};
  pending_[id] = std::move(p);
  write(encode_frame(req.dump()));
}

void Conn::write(std::vector<std::uint8_t> frame) {
  writes_.push_back(std::move(frame));
  if (!writing_) do_write();
}

void Conn::do_write() {
  writing_ = true;
  asio::async_write(socket_, asio::buffer(writes_.front()),
                    [self = shared_from_this(), gen = generation_](const boost::system::error_code& ec,
                                                                   std::size_t) {
                      if (gen != self->generation_ || self->closing_) return;
                      if (ec) return self->on_transport_error("write_failed");
                      self->writes_.pop_front();
                      if (self->writes_.empty()) {
                        self->writing_ = false;
                      } else {
                        self->do_write();
                      }
                    });
}

void Conn::read_header() {
  asio::async_read(socket_, asio::buffer(header_),
                   [self = shared_from_this(), gen = generation_](const boost::system::error_code& ec,
                                                                  std::size_t) {
                     if (gen != self->generation_ || self->closing_) return;
                     if (ec) return self->on_transport_error("connection_lost");
                     FrameHeader h;
                     if (parse_frame_header(self->header_, 1ull << 31, &h) != HeaderStatus::kOk) {
                       return self->fail("bad_frame");
                     }
                     self->body_.resize(h.body_length());
                     asio::async_read(
                         self->socket_, asio::buffer(self->body_),
                         [self, h, gen](const boost::system::error_code& ec2, std::size_t) {
                           if (gen != self->generation_ || self->closing_) return;
                           if (ec2) return self->on_transport_error("connection_lost");
                           BoundedParse parsed = parse_json_bounded(
                               std::string_view(reinterpret_cast<const char*>(self->body_.data()),
                                                h.json_length),
                               JsonLimits{});
                           if (parsed.error || !parsed.value.is_object()) {
                             return self->fail("bad_json_response");
                           }
                           json msg = std::move(parsed.value);
                           std::vector<std::uint8_t> bin(self->body_.begin() + h.json_length,
                                                         self->body_.end());
                           self->on_message(std::move(msg), std::move(bin));
                           if (!self->dead_ && gen == self->generation_) self->read_header();
                         });
                   });
}

void Conn::on_message(json msg, std::vector<std::uint8_t> binary) {
  const auto now = Clock::now();
  const json id = msg.value("id", json());
  const bool ok = msg.value("ok", false);
  Results& r = load_.results;
  if (!ready_) {  // the answers to hello and to the connection's scene.put
    if (ok && id != json(kScenePutId)) return;  // hello: wait for the put
    if (!ok) return fail(msg["error"].value("code", "hello_failed"));
    ready_ = true;
    attempt_ = 0;
    // After a reconnect: the requests the lost connection never answered go
    // out again, each a retry the budget must allow (latency still counts
    // from each one's first scheduled time, so failover shows in it).
    std::map<std::int64_t, Pending> unanswered;
    unanswered.swap(pending_);
    std::uint64_t resent = 0, refused = 0;
    for (auto& [old_id, p] : unanswered) {
      if (load_.budget.try_spend()) {
        send_pending(std::move(p));
        ++resent;
      } else {
        ++refused;
      }
    }
    {
      std::lock_guard lock(r.mu);
      r.retries += resent;
      load_.bucket(now).retries += resent;
      r.budget_refused += refused;
      if (refused > 0) {
        r.errors["retry_budget_spent"] += refused;
        cls_.errors["retry_budget_spent"] += refused;
        load_.bucket(now).errors += refused;
      }
    }
    load_.on_ready(*this);
    return;
  }
  if (id == json(kScenePutId)) {  // a re-put after unknown_scene
    if (!ok) {
      std::lock_guard lock(r.mu);
      ++r.errors["reput_" + msg["error"].value("code", "failed")];
    }
    return;
  }
  if (!id.is_number_integer() || !pending_.count(id.get<std::int64_t>())) {
    // An error the server could not tie to a request (e.g. max_connections).
    std::lock_guard lock(r.mu);
    ++r.errors[ok ? "unexpected_response" : msg["error"].value("code", "unknown")];
    return;
  }
  const Pending p = std::move(pending_[id.get<std::int64_t>()]);
  pending_.erase(id.get<std::int64_t>());
  const double ms = std::chrono::duration<double, std::milli>(now - p.intended).count();
  bool busy = false;
  if (!ok) {
    const std::string code = msg["error"].value("code", "unknown");
    busy = code == "busy";
    if (code == "unknown_scene" && load_.budget.try_spend()) {
      // This connection reached a server without the scene (a balancer moved
      // it, or the server restarted): put it again, render again.
      json put = {{"id", kScenePutId},
                  {"method", "scene.put"},
                  {"params", {{"scene_id", load_.scene_id}, {"scene", load_.scene_json}}}};
      write(encode_frame(put.dump()));
      send_pending(p);
      std::lock_guard lock(r.mu);
      ++r.reputs;
      ++r.retries;
      ++load_.bucket(now).retries;
      return;
    }
    std::lock_guard lock(r.mu);
    ++r.errors[code];
    ++cls_.errors[code];
    ++load_.bucket(now).errors;
    if (busy) r.busy_latency.record_ms(ms);
  } else {
    std::optional<RenderResponse> res;
    std::string why;
    try {
      res = render_response_from_json(msg.value("result", json()), "/result");
    } catch (const ProtocolError& e) {
      why = e.what();
    }
    std::vector<VerifyJob> jobs;
    bool shape_ok = res && res->frames.size() == p.cameras.size();
    if (res && !shape_ok) why = "frames do not match the cameras";
    for (std::size_t i = 0; shape_ok && i < res->frames.size(); ++i) {
      const std::optional<Attachment>& att = res->frames[i].attachment;
      if (!att || att->length == 0 || att->offset > binary.size() ||
          att->length > binary.size() - att->offset) {
        shape_ok = false;
        why = "frame " + std::to_string(i) + " has no attachment inside the binary section";
        break;
      }
      VerifyJob job;
      job.png.assign(binary.begin() + att->offset, binary.begin() + att->offset + att->length);
      job.width = p.cameras[i]["width"];
      job.height = p.cameras[i]["height"];
      job.seq = p.seq;
      const std::string format = res->frames[i].format.value_or("png");
      job.jpeg = format == "jpeg";
      job.format = parse_frame_format(format).value_or(FrameFormat::kPng);
      job.bit_depth = res->frames[i].bit_depth.value_or(8);
      // Deterministic sample of requests for the reference comparison.
      const double u = static_cast<double>((p.seq * 0x9E3779B97F4A7C15ull) >> 11) * 0x1.0p-53;
      if (u < cls_.verify_fraction) job.camera = p.cameras[i];
      jobs.push_back(std::move(job));
    }
    {
      std::lock_guard lock(r.mu);
      if (!shape_ok) {
        ++r.errors["bad_frames"];
        ++cls_.errors["bad_frames"];
        note_failure(r, "request " + std::to_string(p.seq) + ": " + why);
      } else {
        ++r.ok;
        r.frames += res->frames.size();
        r.bytes += kFrameHeaderSize + body_.size();
        r.latency.record_ms(ms);
        Results::Bucket& b = load_.bucket(now);
        b.latency.record_ms(ms);
        ++b.ok;
        ++cls_.ok;
        cls_.frames += res->frames.size();
        cls_.bytes += kFrameHeaderSize + body_.size();
        cls_.latency.record_ms(ms);
        ++ok_requests_;
        ok_frames_ += res->frames.size();
        if (res->quality) {
          ++cls_.levels[static_cast<int>(res->quality->level)];
          if (res->quality->still) ++cls_.still_frames;
          if (res->quality->format == "jpeg") ++cls_.jpeg_frames;
        }
        const RenderTimings& t = res->timings;
        r.queue_ms.record_ms(t.queue_ms);
        r.render_ms.record_ms(t.render_ms);
        r.encode_ms.record_ms(t.encode_ms);
        r.server_ms.record_ms(t.server_ms);
      }
    }
    for (auto& j : jobs) load_.verifier.push(std::move(j));
  }
  load_.on_answer(*this, busy);
}

void Conn::fail(const std::string& why) {
  if (dead_) return;
  dead_ = true;
  {
    std::lock_guard lock(load_.results.mu);
    if (!load_.stopping || !pending_.empty()) {
      ++load_.results.errors[why];
      ++cls_.errors[why];
    }
    load_.results.errors["no_answer"] += pending_.size();
    if (!pending_.empty()) cls_.errors["no_answer"] += pending_.size();
    load_.bucket(Clock::now()).errors += pending_.size();
  }
  pending_.clear();
  close();
  load_.on_dead();
}

void Conn::on_transport_error(const std::string& why) {
  if (dead_) return;
  // Nothing more to send or await: the run is over for this connection.
  if (load_.sending_over() && pending_.empty()) return fail(why);
  if (++attempt_ >= load_.args.max_attempts) return fail(why);
  boost::system::error_code ignored;
  socket_.close(ignored);
  ready_ = false;
  ++generation_;  // the old socket's handlers are stale from here on
  {
    std::lock_guard lock(load_.results.mu);
    ++load_.results.reconnects;
  }
  auto timer = std::make_shared<asio::steady_timer>(socket_.get_executor());
  timer->expires_after(client::backoff_delay(load_.policy, attempt_, load_.rng));
  timer->async_wait([self = shared_from_this(), timer](const boost::system::error_code&) {
    if (!self->dead_ && !self->closing_) self->connect();
  });
}

// The classes of a run: the mix's preview and batch classes, or one class
// ("load") from --connections, --rate, --cameras and --poses.
std::vector<std::unique_ptr<TrafficClass>> make_classes(const LoadArgs& a, const json& scene_json) {
  std::vector<std::unique_ptr<TrafficClass>> out;
  const json& cam = scene_json.at("cameras").at(0);
  if (a.preview_connections > 0) {
    auto c = std::make_unique<TrafficClass>();
    c->name = "preview";
    c->connections = a.preview_connections;
    c->preview = true;
    c->budget_ms = a.preview_budget_ms;
    c->step_rad = a.preview_step_deg * std::numbers::pi / 180.0;
    c->pose_source.emplace(cam, a.preview_size);
    c->verify_fraction = 0;  // interactive frames are reduced-accuracy by design: decoded only
    out.push_back(std::move(c));
  }
  if (a.batch_connections > 0) {
    auto c = std::make_unique<TrafficClass>();
    c->name = "batch";
    c->connections = a.batch_connections;
    c->rate = a.batch_rate;
    c->pipeline = a.batch_pipeline;
    c->inflight_cap = a.inflight_per_connection;
    c->cameras = a.batch_cameras;
    c->poses = "orbit";
    c->pose_source.emplace(cam, a.batch_size);
    c->verify_fraction = a.verify_fraction;
    out.push_back(std::move(c));
  }
  if (out.empty()) {
    auto c = std::make_unique<TrafficClass>();
    c->name = "load";
    c->connections = a.connections;
    c->rate = a.rate;
    c->pipeline = a.pipeline;
    c->inflight_cap = a.inflight_per_connection;
    c->cameras = a.cameras;
    c->poses = a.poses;
    c->pose_source.emplace(cam, a.size);
    c->verify_fraction = a.verify_fraction;
    out.push_back(std::move(c));
  }
  return out;
}

json histogram_json(const LatencyHistogram& h) {
  return {{"count", h.count()},
          {"mean", h.mean_ms()},
          {"p50", h.percentile_ms(0.5)},
          {"p90", h.percentile_ms(0.9)},
          {"p99", h.percentile_ms(0.99)},
          {"p999", h.percentile_ms(0.999)},
          {"max", h.max_ms()}};
}

}  // namespace

int run_load(const LoadArgs& args) {
  const client::Endpoint ep = client::parse_endpoint(args.server);
  std::ifstream in(args.scene_file);
  if (!in) throw std::runtime_error("cannot read scene file " + args.scene_file);
  json scene_json = json::parse(in);
  if (!scene_json.contains("cameras") || scene_json["cameras"].empty()) {
    throw std::runtime_error(args.scene_file + " has no camera to derive poses from");
  }
  // Store the scene once under a per-run id; every request renders it by id.
  const std::string scene_id = "load-" + std::to_string(::getpid());
  // (With retries: the server, or the balancer's first pick, may be down.)
  client::ResilientOptions ropts;
  ropts.policy.max_attempts = args.max_attempts;
  ropts.receive_timeout = std::chrono::milliseconds(static_cast<long long>(args.timeout_s * 1000));
  ropts.token = args.token;
  client::ResilientClient(ep, nullptr, ropts).scene_put(scene_id, scene_json);

  Load load(args, scene_json, scene_id, make_classes(args, scene_json));
  load.run(ep);
  const double wall = std::chrono::duration<double>(Clock::now() - load.start).count();
  load.progress(Clock::now(), true);

  try {
    // Best effort: behind a balancer this reaches one server; the copies the
    // other connections stored age out of their servers' scene stores.
    client::Client c;
    c.connect(ep.host, ep.port);
    if (!args.token.empty()) c.call("hello", {{"protocol", 1}, {"token", args.token}});
    c.scene_delete(scene_id);
  } catch (const std::runtime_error& e) {
    std::fprintf(stderr, "beamcast load: could not delete the run's scene: %s\n", e.what());
  }

  Results& r = load.results;
  std::uint64_t errors = 0;
  for (auto& [k, v] : r.errors) errors += v;
  const bool verified = r.decode_failed == 0 && r.size_mismatch == 0 && r.ref_failed == 0 &&
                        r.decoded == r.frames;
  // Per class: throughput, latency, errors, and each connection's throughput
  // with the max/min ratio (fairness; a connection that got nothing makes it
  // infinite, reported as null).
  json classes = json::array();
  for (const auto& cls : load.classes) {
    json per_conn = json::array();
    double lo = 0, hi = 0;
    bool first = true;
    for (const auto& c : load.conns) {
      if (&c->traffic_class() != cls.get()) continue;
      const double fps = c->ok_frames() / wall;
      per_conn.push_back({{"connection", c->index()},
                          {"requests", c->ok_requests()},
                          {"frames", c->ok_frames()},
                          {"frames_per_s", fps}});
      lo = first ? fps : std::min(lo, fps);
      hi = first ? fps : std::max(hi, fps);
      first = false;
    }
    std::uint64_t cls_errors = 0;
    for (auto& [k, v] : cls->errors) cls_errors += v;
    json c = {{"name", cls->name},
              {"connections", cls->connections},
              {"loop", cls->rate > 0 ? "open" : "closed"},
              {"rate", cls->rate},
              {"pipeline", cls->pipeline},
              {"size", cls->pose_source->size},
              {"cameras_per_request", cls->preview       ? json(1)
                                      : cls->cameras > 0 ? json(cls->cameras)
                                                         : json("mix 1/4")},
              {"quality", cls->preview ? "auto" : "full"},
              {"requests", {{"sent", cls->sent}, {"ok", cls->ok}, {"errors", cls_errors},
                            {"not_sent", cls->skipped}}},
              {"errors_by_code", cls->errors},
              {"frames", cls->frames},
              {"frames_per_s", cls->frames / wall},
              {"requests_per_s", cls->ok / wall},
              {"latency_ms", histogram_json(cls->latency)},
              {"per_connection", per_conn},
              {"fairness_max_over_min", lo > 0 ? json(hi / lo) : json(nullptr)}};
    if (cls->preview) {
      json levels = json::object();
      for (auto& [lvl, n] : cls->levels) levels[std::to_string(lvl)] = n;
      c["preview"] = {{"budget_ms", cls->budget_ms},
                      {"still_frames", cls->still_frames},
                      {"jpeg_frames", cls->jpeg_frames},
                      {"frames_by_level", levels}};
    }
    classes.push_back(std::move(c));
  }
  // Retries and the timeline (answers, errors and retries per bucket of
  // --timeline-ms, with the bucket's latency percentiles): a failover shows
  // where it happened.
  const json retries = {
      {"requests_sent_again", r.retries},
      {"reconnects", r.reconnects},
      {"scene_reputs", r.reputs},
      {"refused_by_budget", r.budget_refused},
      {"max_attempts", args.max_attempts},
      {"amplification", r.sent > 0 ? static_cast<double>(r.sent + r.retries) / r.sent : 1.0}};
  json timeline = json::array();
  for (const auto& [k, b] : r.timeline) {
    timeline.push_back({{"t_s", k * args.timeline_ms / 1000.0},
                        {"ok", b.ok},
                        {"errors", b.errors},
                        {"retries", b.retries},
                        {"p50_ms", b.latency.percentile_ms(0.5)},
                        {"p99_ms", b.latency.percentile_ms(0.99)},
                        {"max_ms", b.latency.max_ms()}});
  }
  const bool mix = args.preview_connections > 0 || args.batch_connections > 0;
  json out = {
      {"server", args.server},
      {"mode", mix ? "mix" : args.rate > 0 ? "open" : "closed"},
      {"connections", args.connections},
      {"rate", args.rate},
      {"size", args.size},
      {"poses", args.poses},
      {"cameras_per_request", args.cameras > 0 ? json(args.cameras) : json("mix 1/4")},
      {"duration_s", wall},
      {"requests", {{"sent", r.sent}, {"ok", r.ok}, {"errors", errors}, {"not_sent", r.skipped}}},
      {"errors_by_code", r.errors},
      {"retries", retries},
      {"timeline_ms", args.timeline_ms},
      {"timeline", timeline},
      {"frames", r.frames},
      {"frames_per_s", r.frames / wall},
      {"requests_per_s", r.ok / wall},
      {"mb_per_s", r.bytes / wall / 1e6},
      {"latency_ms", histogram_json(r.latency)},
      {"busy_latency_ms", histogram_json(r.busy_latency)},
      {"server_timings_ms",
       {{"queue", histogram_json(r.queue_ms)},
        {"render", histogram_json(r.render_ms)},
        {"encode", histogram_json(r.encode_ms)},
        {"server", histogram_json(r.server_ms)}}},
      {"verify",
       {{"decoded", r.decoded},
        {"decode_failed", r.decode_failed},
        {"size_mismatch", r.size_mismatch},
        {"reference_checked", r.ref_checked},
        {"reference_failed", r.ref_failed},
        {"reference_max_diff", r.ref_max_diff},
        {"tolerance", args.tolerance},
        {"all_frames_correct", verified},
        {"failures", r.failures}}},
      {"classes", classes}};
  if (args.json_out) {
    std::printf("%s\n", out.dump(2).c_str());
  } else {
    const json& l = out["latency_ms"];
    if (mix) {
      std::printf("beamcast load: mix, %.1f s\n", wall);
    } else {
      std::printf("beamcast load: %s loop, %d connections, %.1f s, %dx%d\n",
                  args.rate > 0 ? "open" : "closed", args.connections, wall, args.size, args.size);
    }
    std::printf("  requests  sent %llu  ok %llu  errors %llu  not sent %llu\n",
                (unsigned long long)r.sent, (unsigned long long)r.ok,
                (unsigned long long)errors, (unsigned long long)r.skipped);
    for (auto& [k, v] : r.errors) std::printf("    error %-20s %llu\n", k.c_str(), (unsigned long long)v);
    std::printf("  retries  %llu requests sent again (amplification %.3f), %llu reconnects, "
                "%llu scenes put again, %llu refused by the budget\n",
                (unsigned long long)r.retries, retries["amplification"].get<double>(),
                (unsigned long long)r.reconnects, (unsigned long long)r.reputs,
                (unsigned long long)r.budget_refused);
    std::printf("  throughput  %.1f frames/s  %.1f requests/s  %.2f MB/s\n", r.frames / wall,
                r.ok / wall, r.bytes / wall / 1e6);
    std::printf("  latency ms  p50 %.1f  p90 %.1f  p99 %.1f  p99.9 %.1f  max %.1f\n",
                l["p50"].get<double>(), l["p90"].get<double>(), l["p99"].get<double>(),
                l["p999"].get<double>(), l["max"].get<double>());
    std::printf("  server ms (mean)  queue %.1f  render %.1f  encode %.1f  total %.1f\n",
                r.queue_ms.mean_ms(), r.render_ms.mean_ms(), r.encode_ms.mean_ms(),
                r.server_ms.mean_ms());
    std::printf("  verify  %llu/%llu frames decoded, %llu compared with a local render (max "
                "diff %d, tolerance %d): %s\n",
                (unsigned long long)r.decoded, (unsigned long long)r.frames,
                (unsigned long long)r.ref_checked, r.ref_max_diff, args.tolerance,
                verified ? "all correct" : "FAILURES");
    for (auto& f : r.failures) std::printf("    %s\n", f.c_str());
    for (const json& c : classes) {
      const json& cl = c["latency_ms"];
      std::printf("  class %s: %d connections, %s loop, %s cameras at %d px, quality %s\n",
                  c["name"].get<std::string>().c_str(), c["connections"].get<int>(),
                  c["loop"].get<std::string>().c_str(), c["cameras_per_request"].dump().c_str(),
                  c["size"].get<int>(), c["quality"].get<std::string>().c_str());
      std::printf("    %.1f frames/s  %.2f requests/s  ok %llu  errors %llu\n",
                  c["frames_per_s"].get<double>(), c["requests_per_s"].get<double>(),
                  (unsigned long long)c["requests"]["ok"].get<std::uint64_t>(),
                  (unsigned long long)c["requests"]["errors"].get<std::uint64_t>());
      for (auto& [k, v] : c["errors_by_code"].items()) {
        std::printf("      error %-20s %llu\n", k.c_str(), (unsigned long long)v.get<std::uint64_t>());
      }
      std::printf("    latency ms  p50 %.1f  p90 %.1f  p99 %.1f  max %.1f\n",
                  cl["p50"].get<double>(), cl["p90"].get<double>(), cl["p99"].get<double>(),
                  cl["max"].get<double>());
      if (c.contains("preview")) {
        std::printf("    preview  %llu interactive (JPEG) and %llu still frames, by level %s\n",
                    (unsigned long long)c["preview"]["jpeg_frames"].get<std::uint64_t>(),
                    (unsigned long long)c["preview"]["still_frames"].get<std::uint64_t>(),
                    c["preview"]["frames_by_level"].dump().c_str());
      }
      std::printf("    per connection frames/s");
      for (const json& pc : c["per_connection"]) std::printf(" %.1f", pc["frames_per_s"].get<double>());
      const json& f = c["fairness_max_over_min"];
      if (f.is_null()) {
        std::printf("  (max/min: a connection got no frame)\n");
      } else {
        std::printf("  (max/min %.3f)\n", f.get<double>());
      }
    }
  }
  return verified ? 0 : 3;
}

}  // namespace beamcast::bench
