#include "server/request_handler.hpp"

#include <algorithm>
#include <cstdio>
#include <optional>

#include "protocol/request.hpp"
#include "protocol/request_cost.hpp"
#include "protocol/scene_json.hpp"
#include "render/pass_plan.hpp"
#include "server/auth.hpp"
#include "server/limits.hpp"
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

// Parses a scene that sits at `prefix` within the request.
Scene parse_scene_at(const ServerCore& core, const json& scene_json, std::string_view prefix) {
  try {
    return parse_scene(scene_json, load_options(core));
  } catch (const ProtocolError& e) {
    throw ProtocolError(with_path_prefix(e.info(), prefix));
  }
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
                       {"video", {{"codecs", {"vp8", "vp9"}},
                                  {"bitrate_kbps", core.config.preview_bitrate_kbps},
                                  {"min_bitrate_kbps", kMinVideoBitrateKbps},
                                  {"max_bitrate_kbps", kMaxVideoBitrateKbps}}},
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
          {"methods", request_methods()},
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

// max_request_cost (PROTOCOL.md, "Request cost"): the render's estimated
// work against the limit before anything is queued, for inline and stored
// scenes alike. The path is the dominant term's field within the request.
double check_request_cost(const ServerCore& core, const Scene& scene,
                          const std::vector<Camera>& cameras, const RenderParams& rp) {
  const RequestCost cost = estimate_request_cost(scene, cameras);
  if (cost.total <= static_cast<double>(core.config.max_request_cost)) return cost.total;
  const CostTerm* top = cost.dominant();
  const bool per_pixel = top->path == "/cameras";
  std::string path = rp.scene_id ? "/params/scene_id" : "/params/scene" + top->path;
  if (per_pixel && rp.cameras) path = "/params/cameras";
  if (per_pixel && rp.output && rp.output->contains("supersample")) {
    path = "/params/output/supersample";
  }
  char total[32];
  std::snprintf(total, sizeof total, "%.0f", cost.total);
  fail("limit_exceeded", path,
       std::string("the render's estimated cost is ") + total + " (" + cost.breakdown() +
           "), over the limit max_request_cost = " +
           std::to_string(core.config.max_request_cost) +
           ": fewer photons, pixels, cameras or samples (PROTOCOL.md, \"Request cost\")");
}

void handle_render(ServerCore& core, const std::shared_ptr<Connection>& session, const json& id,
                   const json& params, Clock::time_point arrived) {
  const RenderParams rp = parse_render_params(params, core.config.scene_limits);
  std::shared_ptr<const Scene> scene;
  const json* scene_json = nullptr;
  std::shared_ptr<const StoredScene> stored;
  if (rp.scene) {
    scene = std::make_shared<const Scene>(parse_scene_at(core, *rp.scene, "/params/scene"));
    scene_json = &*rp.scene;
  } else {
    stored = core.scenes.get(*rp.scene_id);
    if (!stored) fail("unknown_scene", "/params/scene_id", "no stored scene \"" + *rp.scene_id + "\"");
    scene = std::shared_ptr<const Scene>(stored, &stored->scene);  // keeps the entry alive
    scene_json = &stored->json;
  }
  if (rp.output) {
    json merged = scene_json->value("output", json::object());
    merged.merge_patch(*rp.output);
    auto copy = std::make_shared<Scene>(*scene);
    copy->output = parse_output_settings(merged, "/params/output");
    scene = std::move(copy);
  }
  std::vector<Camera> cameras = rp.cameras ? *rp.cameras : scene->cameras;
  check_supersampled_size(cameras, scene->output.supersample, core.config.scene_limits,
                          rp.output && rp.output->contains("supersample")
                              ? "/params/output/supersample"
                              : (rp.cameras ? "/params/cameras" : "/params/scene/output/supersample"));
  const double estimated_cost = check_request_cost(core, *scene, cameras, rp);
  if (rp.atlas) {
    // The composed image is a frame too: same limits as every camera.
    std::vector<std::pair<int, int>> sizes;
    for (const Camera& c : cameras) sizes.emplace_back(c.width, c.height);
    const AtlasGrid g = atlas_grid(sizes);
    check_frame_size(g.width(), g.height(), core.config.scene_limits, "/params/atlas",
                     "/params/atlas", "the atlas");
  }

  // A video stream is one picture a frame.
  const std::optional<VideoParams> video = rp.quality ? rp.quality->video : std::nullopt;
  if (video && (cameras.size() != 1 || rp.atlas)) {
    fail("invalid_value", "/params/video", "video frames need exactly one camera and no atlas");
  }
  // quality "auto": the connection's accuracy controller picks this frame's level.
  std::optional<ControllerDecision> decision;
  AccuracyLevel level;
  std::size_t ladder_size = 0;
  double budget_ms = 0.0;
  if (rp.quality) {
    const QualityParams& q = *rp.quality;
    InteractiveState& st = session->interactive();
    std::lock_guard lock(st.mu);
    // Costs are per scene content: a new scene (or new render settings) starts
    // a new controller. Inline scenes are keyed by their JSON.
    const auto text = [](const json& j) {
      return j.dump(-1, ' ', false, json::error_handler_t::replace);
    };
    // A stored scene is keyed by its entry: scene.put/update make a new one.
    const std::string key = (rp.scene_id ? "id:" + *rp.scene_id + "@" +
                                               std::to_string(reinterpret_cast<std::uintptr_t>(stored.get()))
                                         : "inline:" + text(*scene_json)) +
                            "|" + (rp.output ? text(*rp.output) : "");
    if (!st.controller || st.scene_key != key) {
      ControllerConfig cfg;
      st.controller =
          std::make_unique<AccuracyController>(preview_ladder(*scene), cfg);
      st.scene_key = key;
    }
    st.controller->set_budget(q.budget_ms);
    st.controller->set_still_ms(q.still_ms);
    const Motion motion = q.motion == "moving"  ? Motion::kMoving
                          : q.motion == "still" ? Motion::kStill
                                                : Motion::kInfer;
    decision = st.controller->decide(steady_ms(arrived), pose_key(cameras), motion);
    level = st.controller->ladder()[decision->level];
    ladder_size = st.controller->ladder().size();
    budget_ms = q.budget_ms;
    if (decision->level != 0) {
      auto copy = std::make_shared<Scene>(*scene);
      apply_accuracy_level(level, copy.get());
      scene = std::move(copy);
    }
  }

  if (!session->try_begin_render()) {
    fail("busy", "", "max_inflight_per_connection (" +
                         std::to_string(core.config.max_inflight_per_connection) +
                         ") requests already in flight on this connection; retry later");
  }
  RenderJob job;
  job.scene = scene;
  job.cameras = cameras;
  job.client_alive = session->alive_flag();
  job.atlas = rp.atlas;
  job.frame_format = session->frame_format();
  job.arrived = arrived;
  job.deadline = arrived + std::chrono::milliseconds(core.config.max_render_ms);
  job.scene_path = rp.scene ? "/params/scene" : "/params/scene_id";
  // Scheduling (PROTOCOL.md, "Scheduling"): the preview's frames before batch
  // work; connections of one class in turn.
  job.work_class = decision ? WorkClass::kInteractive : WorkClass::kBatch;
  job.client = session->id();
  job.cost = estimated_cost;
  job.options.max_batch_views = core.config.slice_views;
  job.options.max_batch_pixels = core.config.slice_pixels;
  if (decision) {
    job.options.resolution_scale = decision->still ? 1.0 : level.scale;
    job.jpeg = !decision->still && rp.quality->jpeg && !video;
    job.jpeg_quality = level.jpeg_quality;
    // A moving video frame comes back as raw samples, encoded in `done`.
    if (video && !decision->still) job.frame_format = FrameFormat::kRaw;
  }
  // Only an unmodified stored scene at full quality may share a render with
  // other requests (a batch renders with one set of options); a streamed
  // render never does.
  if (stored && !rp.output && !decision && !rp.stream) job.batch_key = stored.get();
  auto ctx = std::make_shared<RenderResultContext>();
  ctx->cameras = cameras;
  ctx->planned_passes = plan_passes(*scene);
  ctx->bit_depth = scene->output.bit_depth;
  ctx->base64 = rp.base64;
  ctx->stream = rp.stream;
  // One response message: the whole result, or one part of a streamed one.
  // Parts and the final message never run concurrently (RenderService).
  auto send_result = [&core, session, id, arrived, ctx](const RenderOutcome& out) {
    ctx->server_ms = ms_since(arrived);
    std::vector<std::uint8_t> binary;
    json result = to_json(build_render_response(out, *ctx, &binary));
    core.stats.count_frames(out.frames.size());
    for (const FrameResult& fr : out.frames) core.metrics.add_gpu_ms(fr.gpu_ms);
    json timings = result["timings"];
    session->send(ok_response(id, std::move(result)), std::move(binary));
    return timings;
  };
  if (rp.stream) {
    job.on_part = [send_result](RenderOutcome&& part) { send_result(part); };
  }
  job.done = [&core, session, id, arrived, ctx, send_result, decision, level, ladder_size,
              budget_ms, jpeg = job.jpeg, jpeg_quality = job.jpeg_quality,
              work_class = job.work_class, video](RenderOutcome&& out) mutable {
    // The render ends after its answer is queued, on every path out of here
    // (Connection::end_render): ending it first left a window in which an
    // idle timeout closed the connection under the answer.
    struct EndRender {
      Connection& c;
      ~EndRender() { c.end_render(); }
    } end_render{*session};
    if (out.dropped) return;
    // Video: this frame's encode and send under the stream's lock.
    std::unique_lock<std::mutex> video_order;
    std::optional<VideoFrameReport> video_frame;
    if (video && !out.error) {
      VideoStream& vs = session->interactive().video;
      video_order = std::unique_lock(vs.mu);
      note_video_request(vs, *video);
      if (!decision->still) {
        try {
          video_frame = encode_video_frame(vs, *video, core.config.preview_bitrate_kbps,
                                           ctx->cameras[0].width, ctx->cameras[0].height,
                                           ctx->bit_depth, steady_ms(arrived), &out);
          ctx->video_codec = video_frame->codec;
        } catch (const std::exception& e) {
          out.error = ErrorInfo{"internal", std::string("video encode failed: ") + e.what(), ""};
        }
      }
    }
    if (out.error) {
      core.metrics.count_request("render", false);
      log_request(core, id, "render", out.error->code);
      session->send_error(id, *out.error);
      return;
    }
    if (decision) {
      // What this frame cost the server: rendering (with read-back) and encoding.
      const double frame_ms = out.render_ms + out.encode_wall_ms;
      {
        InteractiveState& st = session->interactive();
        std::lock_guard lock(st.mu);
        if (st.controller) {
          st.controller->observe(decision->level, frame_ms, steady_ms(Clock::now()));
        }
      }
      ctx->quality =
          quality_report(*decision, level, ladder_size, budget_ms, jpeg, jpeg_quality, frame_ms);
      if (video_frame) set_video_report(*video_frame, &*ctx->quality);
    }
    core.metrics.count_request("render", true);
    core.metrics.observe(Metrics::kQueue, out.queue_ms);
    core.metrics.observe_class_wait(static_cast<int>(work_class), out.queue_ms);
    core.metrics.observe(Metrics::kRender, out.render_ms);
    core.metrics.observe(Metrics::kEncode, out.encode_wall_ms);
    core.metrics.observe(Metrics::kTotal, ms_since(arrived));
    const json timings = send_result(out);
    log_request(core, id, "render", "ok", timings);
  };
  if (!core.renders->submit(std::move(job))) {
    fail("busy", "", "the server has max_inflight_total (" +
                         std::to_string(core.config.max_inflight_total) +
                         ") renders in flight; retry later");
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
    core.metrics.count_request(method, false);
    log_request(core, id, method, e.info().code);
    session.send_error(id, e.info());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "beamcast-server: internal error: %s\n", e.what());
    core.metrics.count_request(method, false);
    session.send_error(id, ErrorInfo{"internal", e.what(), ""});
  }
}

// Whether handling `req` may read asset files: a render or scene.put with an
// inline scene that names one, or any scene.update (it parses the stored
// scene again).
bool reads_asset_files(const Request& req) {
  if (req.method == "scene.update") return true;
  if (req.method != "render" && req.method != "scene.put") return false;
  const auto it = req.params.find("scene");
  return it != req.params.end() && scene_reads_files(*it);
}

// The method's work, once the request is parsed, authenticated and admitted.
void run_method(ServerCore& core, const std::shared_ptr<Connection>& session, Request& req,
                const json& id, const std::string& method, Clock::time_point arrived) {
  const json& params = req.params;
  if (req.method == "hello") {
    const std::optional<FrameFormat> format = hello_frame_format(params);
    json result = hello_result(core, params, format.value_or(session->frame_format()));
    // Only a hello that succeeded (token and protocol) authenticates, or
    // sets the frame format.
    if (token_required(core.config)) session->set_authenticated();
    if (format) session->set_frame_format(*format);
    session->send(ok_response(id, std::move(result)));
  } else if (req.method == "ping") {
    json result = json::object();
    result["echo"] = std::move(req.params);  // moved: a large ping's document is not copied
    session->send(ok_response(id, std::move(result)));
  } else if (req.method == "stats" && stats_format(params) == "prometheus") {
    // The Prometheus exposition (server/metrics.hpp) inside a JSON response.
    session->send(ok_response(id, {{"format", "prometheus"},
                                   {"text", core.metrics.prometheus(sample_gauges(core))}}));
  } else if (req.method == "stats" && stats_format(params) == "health") {
    session->send(ok_response(
        id, health_json(core.shutting_down.load(), sample_gauges(core), core.renderer_description)));
  } else if (req.method == "stats") {
    json s = core.stats.to_json();
    s["inflight"] = core.renders->inflight();
    s["queue_depth"] = core.renders->queued();
    s["renders_dropped"] = core.renders->dropped();
    s["renders_cancelled"] = core.renders->cancelled();
    s["slices_dropped"] = core.renders->slices_dropped();
    s["turns"] = core.renders->turns_taken();
    s["queue_depth_by_class"] = {
        {"interactive", core.renders->queued(WorkClass::kInteractive)},
        {"batch", core.renders->queued(WorkClass::kBatch)}};
    s["renderer_rebuilds"] = core.renders->renderer_rebuilds();
    s["scene_cache"] = scene_cache_json(core.renders->scene_cache());
    s["encode_threads"] = core.config.encode_threads;
    s["scenes"] = {{"count", core.scenes.count()}, {"bytes", core.scenes.bytes()}};
    session->send(ok_response(id, std::move(s)));
  } else if (req.method == "render") {
    handle_render(core, session, id, params, arrived);
  } else if (req.method == "scene.put") {
    allow_params(params, {"scene_id", "scene"}, "scene.put");
    const std::string sid = parse_scene_id(params, "/params/scene_id");
    const json& sj = required_object(params, "scene");
    Scene scene = parse_scene_at(core, sj, "/params/scene");
    session->send(ok_response(id, store_scene(core, sid, sj, std::move(scene), "/params/scene")));
  } else if (req.method == "scene.update") {
    allow_params(params, {"scene_id", "patch"}, "scene.update");
    const std::string sid = parse_scene_id(params, "/params/scene_id");
    const json& patch = required_object(params, "patch");
    auto stored = core.scenes.get(sid);
    if (!stored) fail("unknown_scene", "/params/scene_id", "no stored scene \"" + sid + "\"");
    json merged = stored->json;
    merged.merge_patch(patch);
    Scene scene = parse_scene_at(core, merged, "/params/patch");
    session->send(ok_response(
        id, store_scene(core, sid, std::move(merged), std::move(scene), "/params/patch")));
  } else if (req.method == "scene.list") {
    allow_params(params, {}, "scene.list");
    session->send(ok_response(id, {{"scenes", core.scenes.ids()},
                                   {"count", core.scenes.count()},
                                   {"bytes", core.scenes.bytes()}}));
  } else if (req.method == "scene.get") {
    allow_params(params, {"scene_id"}, "scene.get");
    const std::string sid = parse_scene_id(params, "/params/scene_id");
    auto stored = core.scenes.get(sid);
    if (!stored) fail("unknown_scene", "/params/scene_id", "no stored scene \"" + sid + "\"");
    session->send(ok_response(id, {{"scene_id", sid}, {"scene", stored->json}}));
  } else if (req.method == "scene.delete") {
    allow_params(params, {"scene_id"}, "scene.delete");
    const std::string sid = parse_scene_id(params, "/params/scene_id");
    if (!core.scenes.erase(sid)) fail("unknown_scene", "/params/scene_id", "no stored scene \"" + sid + "\"");
    session->send(ok_response(id, {{"deleted", true}}));
  } else {
    fail("unknown_method", "/method",
         "unknown method \"" + req.method + "\" (" + request_methods_text() + ")");
  }
  if (method != "render") {  // render is counted when its answer is ready
    core.metrics.count_request(method, true);
    log_request(core, id, method, "ok");
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
  answering_errors(core, *session, id, method, [&] {
    Request req = read(&id);
    // Count unknown methods under one key: client-chosen strings must not grow the map.
    const bool known = is_request_method(req.method);
    method = known ? req.method : "(unknown)";
    core.stats.count_request(method);
    check_request_token(core.config, req.method, req.params, session->authenticated());
    const bool mutating = req.method == "render" || req.method.starts_with("scene.");
    if (mutating && core.shutting_down.load()) {
      fail("shutting_down", "", "the server is shutting down and takes no new work");
    }
    if (resume && core.loaders && reads_asset_files(req)) {
      load = std::move(req);
      return;
    }
    run_method(core, session, req, id, method, arrived);
  });
  if (!load) return true;
  // Reading a mesh, SLIM or volume file takes up to a second (a 14 MB OBJ:
  // 0.15-0.2 s; files are limited by max_mesh_triangles, max_slim_spheres,
  // max_volume_voxels): on a loader thread, so this network thread's other
  // connections are answered meanwhile. The connection reads its next
  // message once `resume` has run, so its requests are handled in order.
  core.loading.fetch_add(1);
  core.loaders->post([&core, session, req = std::make_shared<Request>(std::move(*load)),
                      id = std::move(id), method, arrived, resume = std::move(resume)] {
    answering_errors(core, *session, id, method,
                     [&] { run_method(core, session, *req, id, method, arrived); });
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
