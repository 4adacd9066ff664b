#include "server/request_handler.hpp"

#include <algorithm>
#include <cstdio>
#include <optional>

#include "protocol/request.hpp"
#include "protocol/render_request.hpp"
#include "protocol/scene_json.hpp"
#include "render/pass_plan.hpp"
#include "server/auth.hpp"
#include "server/settings.hpp"
#include "server/session.hpp"
#include "render/accuracy_controller.hpp"
#include "server/render_result.hpp"
#include "server/connection.hpp"

namespace beamcast {
namespace {

using Clock = std::chrono::steady_clock;
using json = nlohmann::json;

[[noreturn]] void fail(std::string code, std::string path, std::string message) {
  throw ProtocolError(ErrorInfo{std::move(code), std::move(message), std::move(path)});
}

// Milliseconds on the steady clock: the accuracy controller's time axis.
double steady_ms(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(t.time_since_epoch()).count();
}

double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

SceneLoadOptions load_options(const ServerCore& core) {
  SceneLoadOptions opts;
  opts.assets_dir = core.config.assets_dir;
  opts.limits = core.config.scene_limits;
  return opts;
}

const json& required_object(const json& params, const char* key) {
  auto it = params.find(key);
  if (it == params.end()) fail("missing_field", std::string("/params/") + key, std::string(key) + " is required");
  if (!it->is_object()) fail("wrong_type", std::string("/params/") + key, std::string(key) + " must be an object");
  return *it;
}

// hello's params.frame_format (PROTOCOL.md, "Frame formats"), if present.
std::optional<FrameFormat> hello_frame_format(const json& params) {
  const auto it = params.find("frame_format");
  if (it == params.end()) return std::nullopt;
  std::string names;
  for (const std::string& n : frame_format_names()) names += (names.empty() ? "\"" : ", \"") + n + "\"";
  if (!it->is_string()) {
    fail("wrong_type", "/params/frame_format", "frame_format must be a string: one of " + names);
  }
  const auto f = parse_frame_format(it->get_ref<const std::string&>());
  if (!f) {
    fail("invalid_value", "/params/frame_format",
         "unknown frame format (this server offers " + names + ")");
  }
  return f;
}

json method_names();  // the dispatch table's, below

// `format`: the connection's frame format after this hello.
json hello_result(const ServerCore& core, const json& params, FrameFormat format) {
  allow_params(params, {"protocol", "client", "token", "frame_format"}, "hello");
  if (auto c = params.find("client"); c != params.end() && !c->is_string()) {
    fail("wrong_type", "/params/client", "client must be a string (\"name/version\")");
  }
  if (auto p = params.find("protocol"); p != params.end()) {
    if (read_protocol_number(*p) != kProtocolVersion) {
      fail("unsupported_protocol", "/params/protocol",
           "this server speaks protocol " + std::to_string(kProtocolVersion));
    }
  }
  json passes = json::array();
  for (const PassDecl& pass : pass_catalog()) passes.push_back(pass.name);
  json capabilities = {{"formats", {"png", "jpeg"}},
                       {"frame_formats", frame_format_names()},
                       {"png_encoder", core.config.png.encoder == PngEncoder::kLibdeflate
                                           ? "libdeflate"
                                           : "libpng"},
                       {"quality", {"full", "auto"}},
                       {"video", {{"codecs", {"vp8", "vp9", "av1"}},
                                  {"bitrate_kbps", core.config.preview_bitrate_kbps},
                                  {"bit_depths", {8, 10}},
                                  {"bit_depth_setting", core.config.preview_bit_depth},
                                  {"band_rows", core.config.preview_band_rows}}},
                       {"encodings", {"binary", "base64"}},
                       {"batch_window_ms", core.config.batch_window_ms},
                       {"stream", true},
                       {"scheduling", {{"classes", {"interactive", "batch"}}, {"slice_views", core.config.slice_views}, {"slice_pixels", core.config.slice_pixels}, {"hold_batch_encodes", core.config.hold_batch_encodes}, {"encode_threads", core.config.encode_threads}}},
                       {"passes", passes}};
  capabilities.update(scene_capabilities());
  return {{"protocol", kProtocolVersion},
          {"server", "beamcast-server 0.1.0"},
          {"renderer", core.renderer_description},
          {"frame_format", frame_format_name(format)},
          {"methods", method_names()},
          {"capabilities", capabilities},
          {"limits", limits_json(core.config)}};
}

// stats' params.format: "json" (default), "prometheus" or "health".
std::string stats_format(const json& params) {
  allow_params(params, {"format"}, "stats");
  const auto it = params.find("format");
  if (it == params.end()) return "json";
  if (!it->is_string() || (*it != "json" && *it != "prometheus" && *it != "health")) {
    fail("invalid_value", "/params/format", "format must be \"json\", \"prometheus\" or \"health\"");
  }
  return it->get<std::string>();
}

// `path`: where the scene came from in the request (for limit_exceeded).
json store_scene(ServerCore& core, const std::string& id, json scene_json, Scene scene,
                 const char* path) {
  auto stored = std::make_shared<StoredScene>();
  stored->bytes = scene_json.dump().size();
  // The store never holds more than max_scene_store_bytes: a scene larger than
  // the whole store is refused (evicting everything would not make it fit).
  if (stored->bytes > core.config.max_scene_store_bytes) {
    fail("limit_exceeded", path,
         "the scene takes " + std::to_string(stored->bytes) +
             " bytes as stored JSON, over the limit max_scene_store_bytes = " +
             std::to_string(core.config.max_scene_store_bytes));
  }
  stored->json = std::move(scene_json);
  stored->scene = std::move(scene);
  const std::uint64_t bytes = stored->bytes;
  const auto evicted = core.scenes.put(id, std::move(stored));
  return {{"scene_id", id}, {"bytes", bytes}, {"evicted", evicted}};
}

// A request's error answer, counted and logged under `method`.
void answer_error(ServerCore& core, Connection& session, const json& id, const std::string& method,
                  const ErrorInfo& error) {
  core.metrics.count_request(method, false);
  log_request(core, id, method, error.code);
  session.send_error(id, error);
}

RenderLimits render_limits(const ServerCore& core) {
  return {load_options(core), core.config.max_request_cost};
}

// quality "auto": this frame's level, from the connection's accuracy controller.
struct InteractiveFrame {
  ControllerDecision decision;
  AccuracyLevel level;
  std::size_t ladder_size = 0;
  double budget_ms = 0.0;
};

// Costs are per scene content: a new scene (or new render settings) starts a
// new controller. A stored scene is keyed by its entry (scene.put/update make
// a new one), an inline scene by its JSON.
std::string controller_key(const ResolvedRender& r) {
  const auto text = [](const json& j) {
    return j.dump(-1, ' ', false, json::error_handler_t::replace);
  };
  const RenderParams& rp = r.params;
  return (rp.scene_id ? "id:" + *rp.scene_id + "@" +
                            std::to_string(reinterpret_cast<std::uintptr_t>(r.stored.get()))
                      : "inline:" + text(r.scene_json())) +
         "|" + (rp.output ? text(*rp.output) : "");
}

// The controller's step for a quality "auto" frame, under the connection's
// lock: the level, and the scene at that level. None for a full-quality render.
std::optional<InteractiveFrame> step_controller(Connection& session, Clock::time_point arrived,
                                                ResolvedRender* r) {
  if (!r->params.quality) return std::nullopt;
  const QualityParams& q = *r->params.quality;
  const std::string key = controller_key(*r);
  InteractiveFrame f;
  {
    InteractiveState& st = session.interactive();
    std::lock_guard lock(st.mu);
    if (!st.controller || st.scene_key != key) {
      st.controller = std::make_unique<AccuracyController>(preview_ladder(*r->scene), ControllerConfig{});
      st.scene_key = key;
    }
    st.controller->set_budget(q.budget_ms);
    st.controller->set_still_ms(q.still_ms);
    const Motion motion = q.motion == "moving"  ? Motion::kMoving
                          : q.motion == "still" ? Motion::kStill
                                                : Motion::kInfer;
    f.decision = st.controller->decide(steady_ms(arrived), pose_key(r->cameras), motion);
    f.level = st.controller->ladder()[f.decision.level];
    f.ladder_size = st.controller->ladder().size();
  }
  f.budget_ms = q.budget_ms;
  if (f.decision.level != 0) {
    auto copy = std::make_shared<Scene>(*r->scene);
    apply_accuracy_level(f.level, copy.get());
    r->scene = std::move(copy);
  }
  return f;
}

// The render's answer: each streamed part and the final result, sent on the
// connection with the render's metrics, log line and quality report.
struct RenderReply {
  ServerCore& core;
  std::shared_ptr<Connection> session;
  json id;
  Clock::time_point arrived;
  std::optional<InteractiveFrame> frame;
  std::optional<VideoParams> video;
  bool jpeg = false;
  int jpeg_quality = 0;
  WorkClass work_class = WorkClass::kBatch;
  RenderResultContext ctx;

  // One response message: the whole result, or one part of a streamed one.
  // Parts and the final message never run concurrently (RenderService).
  json send(const RenderOutcome& out) {
    ctx.server_ms = ms_since(arrived);
    std::vector<std::uint8_t> binary;
    json result = to_json(build_render_response(out, ctx, &binary));
    core.stats.count_frames(out.frames.size());
    for (const FrameResult& fr : out.frames) core.metrics.add_gpu_ms(fr.gpu_ms);
    json timings = result["timings"];
    session->send(ok_response(id, std::move(result)), std::move(binary));
    return timings;
  }

  // Video: this frame's encode, under the stream's lock (held by `order`).
  std::optional<VideoFrameReport> encode_video(RenderOutcome* out,
                                               std::unique_lock<std::mutex>* order) {
    if (!video || out->error) return std::nullopt;
    VideoStream& vs = session->interactive().video;
    *order = std::unique_lock(vs.mu);
    note_video_request(vs, *video);
    if (frame->decision.still) return std::nullopt;
    try {
      VideoFrameReport report =
          encode_video_frame(vs, *video, core.config.preview_bitrate_kbps,
                             core.config.preview_bit_depth, core.config.preview_band_rows,
                             ctx.cameras[0].width,
                             ctx.cameras[0].height, ctx.bit_depth, steady_ms(arrived),
                             frame->budget_ms, out);
      ctx.video_codec = report.codec;
      return report;
    } catch (const std::exception& e) {
      out->error = ErrorInfo{"internal", std::string("video encode failed: ") + e.what(), ""};
      return std::nullopt;
    }
  }

  // The controller learns what this frame cost the server: rendering (with
  // read-back) and encoding; the response reports the level.
  void report_quality(const RenderOutcome& out, const std::optional<VideoFrameReport>& video_frame) {
    const double frame_ms = out.render_ms + out.encode_wall_ms;
    {
      InteractiveState& st = session->interactive();
      std::lock_guard lock(st.mu);
      if (st.controller) st.controller->observe(frame->decision.level, frame_ms, steady_ms(Clock::now()));
    }
    ctx.quality = quality_report(frame->decision, frame->level, frame->ladder_size, frame->budget_ms,
                                 jpeg, jpeg_quality, frame_ms);
    if (video_frame) set_video_report(*video_frame, &*ctx.quality);
  }

  void done(RenderOutcome&& out) {
    // The render ends after its answer is queued, on every path out of here
    // (Connection::end_render): ending it first left a window in which an
    // idle timeout closed the connection under the answer.
    struct EndRender {
      Connection& c;
      ~EndRender() { c.end_render(); }
    } end_render{*session};
    if (out.dropped) return;
    std::unique_lock<std::mutex> video_order;
    const std::optional<VideoFrameReport> video_frame = encode_video(&out, &video_order);
    if (out.error) {
      core.metrics.count_request("render", false);
      log_request(core, id, "render", out.error->code);
      session->send_error(id, *out.error);
      return;
    }
    if (frame) report_quality(out, video_frame);
    core.metrics.count_request("render", true);
    core.metrics.observe(Metrics::kQueue, out.queue_ms);
    core.metrics.observe_class_wait(static_cast<int>(work_class), out.queue_ms);
    core.metrics.observe(Metrics::kRender, out.render_ms);
    core.metrics.observe(Metrics::kEncode, out.encode_wall_ms);
    core.metrics.observe(Metrics::kTotal, ms_since(arrived));
    const json timings = send(out);
    log_request(core, id, "render", "ok", timings);
  }
};

// The job for a resolved render, without its answer callbacks.
RenderJob make_render_job(const ServerCore& core, Connection& session, const ResolvedRender& r,
                          const std::optional<InteractiveFrame>& frame, Clock::time_point arrived) {
  RenderJob job;
  job.scene = r.scene;
  job.cameras = r.cameras;
  job.client_alive = session.alive_flag();
  job.atlas = r.params.atlas;
  job.frame_format = session.frame_format();
  job.arrived = arrived;
  job.deadline = arrived + std::chrono::milliseconds(core.config.max_render_ms);
  job.scene_path = r.scene_path();
  // Scheduling (PROTOCOL.md, "Scheduling"): the preview's frames before batch
  // work; connections of one class in turn.
  job.work_class = frame ? WorkClass::kInteractive : WorkClass::kBatch;
  job.client = session.id();
  job.cost = r.cost;
  job.options.max_batch_views = core.config.slice_views;
  job.options.max_batch_pixels = core.config.slice_pixels;
  if (frame) {
    job.options.resolution_scale = frame->decision.still ? 1.0 : frame->level.scale;
    job.jpeg = !frame->decision.still && r.params.quality->jpeg && !r.video;
    job.jpeg_quality = frame->level.jpeg_quality;
    // A moving video frame comes back as raw samples, encoded in `done`.
    if (r.video && !frame->decision.still) job.frame_format = FrameFormat::kRaw;
  }
  // Only an unmodified stored scene at full quality may share a render with
  // other requests (a batch renders with one set of options); a streamed
  // render never does.
  if (r.stored && !r.params.output && !frame && !r.params.stream) job.batch_key = r.stored.get();
  return job;
}

// The job's answer: a RenderReply shared by its part and done callbacks.
void attach_reply(ServerCore& core, const std::shared_ptr<Connection>& session, const json& id,
                  const ResolvedRender& r, std::optional<InteractiveFrame> frame,
                  Clock::time_point arrived, RenderJob* job) {
  auto reply = std::make_shared<RenderReply>(RenderReply{
      core, session, id, arrived, std::move(frame), r.video, job->jpeg, job->jpeg_quality,
      job->work_class, RenderResultContext{}});
  reply->ctx.cameras = r.cameras;
  reply->ctx.planned_passes = plan_passes(*r.scene);
  reply->ctx.bit_depth = r.scene->output.bit_depth;
  reply->ctx.base64 = r.params.base64;
  reply->ctx.stream = r.params.stream;
  if (r.params.stream) {
    job->on_part = [reply](RenderOutcome&& part) { reply->send(part); };
  }
  job->done = [reply](RenderOutcome&& out) { reply->done(std::move(out)); };
}

void handle_render(ServerCore& core, const std::shared_ptr<Connection>& session, const json& id,
                   const json& params, Clock::time_point arrived) {
  ResolvedRender r = resolve_render(params, render_limits(core), [&core](const std::string& sid) {
    return core.scenes.get(sid);
  });
  std::optional<InteractiveFrame> frame = step_controller(*session, arrived, &r);
  if (!session->try_begin_render()) {
    fail("busy", "", "max_inflight_per_connection (" +
                         std::to_string(core.config.max_inflight_per_connection) +
                         ") requests already in flight on this connection; retry later");
  }
  RenderJob job = make_render_job(core, *session, r, frame, arrived);
  attach_reply(core, session, id, r, std::move(frame), arrived, &job);
  if (!core.renders->submit(std::move(job))) {
    // The job, and with it its `done`, is gone: the render admitted above
    // ends here, after its answer (Connection::end_render).
    answer_error(core, *session, id, "render",
                 {"busy",
                  "the server has max_inflight_total (" +
                      std::to_string(core.config.max_inflight_total) +
                      ") renders in flight; retry later",
                  ""});
    session->end_render();
  }
}

}  // namespace

bool reserve_request_memory(ServerCore& core, Connection& connection, std::uint64_t message_bytes,
                            MemoryBudget::Reservation* reservation) {
  ErrorInfo refused;
  if (core.request_memory.try_reserve(message_bytes, reservation, &refused)) return true;
  connection.send_error(nullptr, refused);
  return false;
}

namespace {

// Runs `fn`, answering what it throws: a ProtocolError as the client's error,
// anything else as `internal`.
template <class Fn>
void answering_errors(ServerCore& core, Connection& session, const json& id,
                      const std::string& method, Fn&& fn) {
  try {
    fn();
  } catch (const ProtocolError& e) {
    answer_error(core, session, id, method, e.info());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "beamcast-server: internal error: %s\n", e.what());
    core.metrics.count_request(method, false);
    session.send_error(id, ErrorInfo{"internal", e.what(), ""});
  }
}

// One request's method call, once parsed, authenticated and admitted.
struct MethodCall {
  ServerCore& core;
  const std::shared_ptr<Connection>& session;
  Request& req;
  const json& id;
  Clock::time_point arrived;
};

void run_hello(MethodCall& c) {
  const std::optional<FrameFormat> format = hello_frame_format(c.req.params);
  json result = hello_result(c.core, c.req.params, format.value_or(c.session->frame_format()));
  // Only a hello that succeeded (token and protocol) authenticates, or
  // sets the frame format.
  if (token_required(c.core.config)) c.session->set_authenticated();
  if (format) c.session->set_frame_format(*format);
  c.session->send(ok_response(c.id, std::move(result)));
}

void run_ping(MethodCall& c) {
  json result = json::object();
  result["echo"] = std::move(c.req.params);  // moved: a large ping's document is not copied
  c.session->send(ok_response(c.id, std::move(result)));
}

void run_stats(MethodCall& c) {
  ServerCore& core = c.core;
  const std::string format = stats_format(c.req.params);
  if (format == "prometheus") {
    // The Prometheus exposition (server/metrics.hpp) inside a JSON response.
    c.session->send(ok_response(c.id, {{"format", "prometheus"},
                                       {"text", core.metrics.prometheus(sample_gauges(core))}}));
    return;
  }
  if (format == "health") {
    c.session->send(ok_response(
        c.id, health_json(core.shutting_down.load(), sample_gauges(core), core.renderer_description)));
    return;
  }
  json s = core.stats.to_json();
  s["inflight"] = core.renders->inflight();
  s["queue_depth"] = core.renders->queued();
  s["renders_dropped"] = core.renders->dropped();
  s["renders_cancelled"] = core.renders->cancelled();
  s["slices_dropped"] = core.renders->slices_dropped();
  s["turns"] = core.renders->turns_taken();
  s["queue_depth_by_class"] = {{"interactive", core.renders->queued(WorkClass::kInteractive)},
                               {"batch", core.renders->queued(WorkClass::kBatch)}};
  s["renderer_rebuilds"] = core.renders->renderer_rebuilds();
  s["scene_cache"] = scene_cache_json(core.renders->scene_cache());
  s["encode_threads"] = core.config.encode_threads;
  s["settings"] = settings_json(core.config);
  s["scenes"] = {{"count", core.scenes.count()}, {"bytes", core.scenes.bytes()}};
  c.session->send(ok_response(c.id, std::move(s)));
}

void run_render(MethodCall& c) { handle_render(c.core, c.session, c.id, c.req.params, c.arrived); }

// A stored scene named by params.scene_id; unknown_scene if none.
std::shared_ptr<const StoredScene> stored_scene(ServerCore& core, const std::string& sid) {
  auto stored = core.scenes.get(sid);
  if (!stored) fail("unknown_scene", "/params/scene_id", "no stored scene \"" + sid + "\"");
  return stored;
}

void run_scene_put(MethodCall& c) {
  const json& params = c.req.params;
  allow_params(params, {"scene_id", "scene"}, "scene.put");
  const std::string sid = parse_scene_id(params, "/params/scene_id");
  const json& sj = required_object(params, "scene");
  Scene scene = parse_scene_at(sj, load_options(c.core), "/params/scene");
  c.session->send(ok_response(c.id, store_scene(c.core, sid, sj, std::move(scene), "/params/scene")));
}

void run_scene_update(MethodCall& c) {
  const json& params = c.req.params;
  allow_params(params, {"scene_id", "patch"}, "scene.update");
  const std::string sid = parse_scene_id(params, "/params/scene_id");
  const json& patch = required_object(params, "patch");
  json merged = stored_scene(c.core, sid)->json;
  merged.merge_patch(patch);
  Scene scene = parse_scene_at(merged, load_options(c.core), "/params/patch");
  c.session->send(ok_response(
      c.id, store_scene(c.core, sid, std::move(merged), std::move(scene), "/params/patch")));
}

void run_scene_get(MethodCall& c) {
  allow_params(c.req.params, {"scene_id"}, "scene.get");
  const std::string sid = parse_scene_id(c.req.params, "/params/scene_id");
  auto stored = stored_scene(c.core, sid);
  c.session->send(ok_response(c.id, {{"scene_id", sid}, {"scene", stored->json}}));
}

void run_scene_list(MethodCall& c) {
  allow_params(c.req.params, {}, "scene.list");
  ServerCore& core = c.core;
  c.session->send(ok_response(c.id, {{"scenes", core.scenes.ids()},
                                     {"count", core.scenes.count()},
                                     {"bytes", core.scenes.bytes()}}));
}

void run_scene_delete(MethodCall& c) {
  allow_params(c.req.params, {"scene_id"}, "scene.delete");
  const std::string sid = parse_scene_id(c.req.params, "/params/scene_id");
  if (!c.core.scenes.erase(sid)) {
    fail("unknown_scene", "/params/scene_id", "no stored scene \"" + sid + "\"");
  }
  c.session->send(ok_response(c.id, {{"deleted", true}}));
}

// Which requests of a method may read asset files (then handled on a loader
// thread when the caller allows): never, those whose params.scene names
// files (scene_reads_files), or always (scene.update parses the stored scene
// again).
enum class FileReads { kNever, kInlineScene, kAlways };

// The methods (PROTOCOL.md, "Methods") with what the dispatcher does before
// running them.
struct MethodEntry {
  std::string_view name;
  void (*run)(MethodCall&);
  FileReads file_reads = FileReads::kNever;
  bool presents_token = false;  // checks params.token itself (hello); others need an authenticated connection
  bool refused_when_stopping = false;  // shutting_down while the server stops (new work)
  bool counted_when_answered = false;  // metrics and log line when its answer is ready (render)
};

constexpr MethodEntry kMethodTable[] = {
    {.name = "hello", .run = run_hello, .presents_token = true},
    {.name = "ping", .run = run_ping},
    {.name = "render",
     .run = run_render,
     .file_reads = FileReads::kInlineScene,
     .refused_when_stopping = true,
     .counted_when_answered = true},
    {.name = "scene.put",
     .run = run_scene_put,
     .file_reads = FileReads::kInlineScene,
     .refused_when_stopping = true},
    {.name = "scene.update",
     .run = run_scene_update,
     .file_reads = FileReads::kAlways,
     .refused_when_stopping = true},
    {.name = "scene.get", .run = run_scene_get, .refused_when_stopping = true},
    {.name = "scene.list", .run = run_scene_list, .refused_when_stopping = true},
    {.name = "scene.delete", .run = run_scene_delete, .refused_when_stopping = true},
    {.name = "stats", .run = run_stats},
};

// The table is protocol's method list (kRequestMethods), in its order.
constexpr bool table_matches_protocol() {
  if (std::size(kMethodTable) != kRequestMethods.size()) return false;
  for (std::size_t i = 0; i < kRequestMethods.size(); ++i) {
    if (kMethodTable[i].name != kRequestMethods[i]) return false;
  }
  return true;
}
static_assert(table_matches_protocol(), "kMethodTable must list protocol/request.hpp's methods in order");

const MethodEntry* find_method(std::string_view name) {
  for (const MethodEntry& m : kMethodTable) {
    if (m.name == name) return &m;
  }
  return nullptr;
}

json method_names() {
  json names = json::array();
  for (const MethodEntry& m : kMethodTable) names.push_back(std::string(m.name));
  return names;
}

// Whether handling `req` may read asset files.
bool reads_asset_files(const MethodEntry& m, const Request& req) {
  if (m.file_reads != FileReads::kInlineScene) return m.file_reads == FileReads::kAlways;
  const auto it = req.params.find("scene");
  return it != req.params.end() && scene_reads_files(*it);
}

// The method's work, once the request is parsed, authenticated and admitted.
void run_method(ServerCore& core, const std::shared_ptr<Connection>& session, Request& req,
                const json& id, const MethodEntry& m, Clock::time_point arrived) {
  MethodCall call{core, session, req, id, arrived};
  m.run(call);
  if (!m.counted_when_answered) {
    core.metrics.count_request(std::string(m.name), true);
    log_request(core, id, std::string(m.name), "ok");
  }
}

}  // namespace

namespace {

// handle_message and handle_request: `read` gives the request (parsing it,
// which may throw) and sets the id to echo.
bool handle_read(ServerCore& core, const std::shared_ptr<Connection>& session,
                 const std::function<Request(json*)>& read, Clock::time_point arrived,
                 std::function<void()> resume) {
  // Time spent here is not the client's (MessageClock).
  struct HandlingTime {
    ServerCore& core;
    Clock::time_point start = Clock::now();
    ~HandlingTime() {
      core.handling_ns.fetch_add(
          std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - start).count());
    }
  } handling{core};
  json id;
  std::string method = "(invalid)";  // metrics key: a known method or a fixed placeholder
  std::optional<Request> load;       // handled on core.loaders
  const MethodEntry* entry = nullptr;  // load's method
  answering_errors(core, *session, id, method, [&] {
    Request req = read(&id);
    // Count unknown methods under one key: client-chosen strings must not grow the map.
    const MethodEntry* m = find_method(req.method);
    method = m ? req.method : "(unknown)";
    core.stats.count_request(method);
    check_request_token(core.config, m && m->presents_token, req.params, session->authenticated());
    if (!m) {
      fail("unknown_method", "/method",
           "unknown method \"" + req.method + "\" (" + request_methods_text() + ")");
    }
    if (m->refused_when_stopping && core.shutting_down.load()) {
      fail("shutting_down", "", "the server is shutting down and takes no new work");
    }
    if (resume && core.loaders && reads_asset_files(*m, req)) {
      load = std::move(req);
      entry = m;
      return;
    }
    run_method(core, session, req, id, *m, arrived);
  });
  if (!load) return true;
  // Reading a mesh, SLIM or volume file takes up to a second (a 14 MB OBJ:
  // 0.15-0.2 s; files are limited by max_mesh_triangles, max_slim_spheres,
  // max_volume_voxels): on a loader thread, so this network thread's other
  // connections are answered meanwhile. The connection reads its next
  // message once `resume` has run, so its requests are handled in order.
  core.loading.fetch_add(1);
  core.loaders->post([&core, session, req = std::make_shared<Request>(std::move(*load)),
                      id = std::move(id), method, entry, arrived, resume = std::move(resume)] {
    answering_errors(core, *session, id, method,
                     [&] { run_method(core, session, *req, id, *entry, arrived); });
    core.loading.fetch_sub(1);
    resume();
  });
  return false;
}

}  // namespace

bool handle_message(ServerCore& core, const std::shared_ptr<Connection>& session,
                    std::string_view json_text, Clock::time_point arrived,
                    std::function<void()> resume) {
  return handle_read(
      core, session,
      [&](json* id) { return parse_request(json_text, id, core.config.json_limits); }, arrived,
      std::move(resume));
}

bool handle_request(ServerCore& core, const std::shared_ptr<Connection>& session, Request request,
                    Clock::time_point arrived, std::function<void()> resume) {
  return handle_read(
      core, session,
      [&](json* id) {
        *id = request.id;
        return std::move(request);
      },
      arrived, std::move(resume));
}

}  // namespace beamcast
