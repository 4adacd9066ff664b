#include "server/settings.hpp"

#include <limits>
#include <type_traits>

#include "protocol/medium.hpp"
#include "protocol/media/mesh.hpp"
#include "protocol/request.hpp"
#include "protocol/scene_json.hpp"
#include "protocol/volume.hpp"
#include "render/pass_plan.hpp"
#include "server/http_server.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

constexpr std::int64_t kI32 = std::numeric_limits<std::int32_t>::max();
constexpr std::int64_t kI64 = std::numeric_limits<std::int64_t>::max();

// An integer row whose value is the ServerConfig member F.
#define INTEGER(N, K, F, LO, HI, H)                                                        \
  Setting {                                                                               \
    .name = N, .kind = K, .type = SettingType::kInteger, .min = LO, .max = HI, .help = H, \
    .get = [](const ServerConfig& c) -> json { return c.F; },                             \
    .set = [](ServerConfig& c, const json& v) {                                           \
      c.F = static_cast<decltype(c.F)>(v.get<std::int64_t>());                            \
    }                                                                                     \
  }
#define LIMIT(N, F, LO, HI, H) INTEGER(N, SettingKind::kLimit, F, LO, HI, H)
#define OPTION(N, F, LO, HI, H) INTEGER(N, SettingKind::kOption, F, LO, HI, H)
// A text option whose value is the ServerConfig member F.
#define TEXT(N, F, H)                                                               \
  Setting {                                                                         \
    .name = N, .type = SettingType::kText, .help = H,                               \
    .get = [](const ServerConfig& c) -> json { return c.F; },                       \
    .set = [](ServerConfig& c, const json& v) { c.F = v.get<std::string>(); }       \
  }
// A flag that sets the ServerConfig member F to V when given.
#define FLAG(N, F, V, H)                                                 \
  Setting {                                                              \
    .name = N, .type = SettingType::kFlag, .help = H,                    \
    .get = [](const ServerConfig& c) -> json { return c.F == V; },       \
    .set = [](ServerConfig& c, const json& v) {                          \
      if (v.get<bool>()) c.F = V;                                        \
    }                                                                    \
  }
// A bound compiled in: the constant V, or the server's scene limit F.
#define FIXED(N, V, H)                                                                        \
  Setting {                                                                                  \
    .name = N, .kind = SettingKind::kFixed,                                                  \
    .type = std::is_floating_point_v<decltype(V)> ? SettingType::kNumber : SettingType::kInteger, \
    .help = H, .get = [](const ServerConfig&) -> json { return V; }                          \
  }
#define FIXED_SCENE(N, F, H)                                                          \
  Setting {                                                                          \
    .name = N, .kind = SettingKind::kFixed,                                          \
    .type = std::is_floating_point_v<decltype(SceneLimits{}.F)> ? SettingType::kNumber \
                                                               : SettingType::kInteger, \
    .help = H, .get = [](const ServerConfig& c) -> json { return c.scene_limits.F; } \
  }

const char* png_filter_name(const PngSettings& p) {
  if (p.encoder == PngEncoder::kLibpng) {
    switch (p.libpng_filters) {
      case 0x08: return "none";
      case 0x10: return "sub";
      case 0x20: return "up";
      case 0x80: return "paeth";
      default: return "adaptive";
    }
  }
  return p.row_filter == PngRowFilter::kNone ? "none" : p.row_filter == PngRowFilter::kUp ? "up" : "sub";
}

void set_png_filter(PngSettings& p, const std::string& f) {
  // libpng's PNG_FILTER_* masks; libdeflate's encoder writes one filter type.
  p.libpng_filters = f == "none" ? 0x08 : f == "sub" ? 0x10 : f == "up" ? 0x20 : f == "paeth" ? 0x80 : 0xF8;
  p.row_filter = f == "none" ? PngRowFilter::kNone : f == "up" ? PngRowFilter::kUp : PngRowFilter::kSub;
}

}  // namespace

std::string Setting::option() const {
  std::string o = "--" + std::string(name);
  for (char& ch : o) {
    if (ch == '_') ch = '-';
  }
  return o;
}

const std::vector<Setting>& settings_table() {
  static const std::vector<Setting> kTable = {
      // How the server runs.
      TEXT("bind", bind, "Address to listen on"),
      Setting{.name = "token",
              .type = SettingType::kText,
              .help = "Shared token clients must send in hello (params.token); required to bind a "
                      "non-loopback address",
              .env = "BEAMCAST_TOKEN",
              .secret = true,
              .get = [](const ServerConfig& c) -> json { return c.token; },
              .set = [](ServerConfig& c, const json& v) { c.token = v.get<std::string>(); }},
      FLAG("insecure_no_token", insecure_no_token, true,
           "Allow a non-loopback bind without a token (anyone who can reach the port may "
           "render; docs/security.md)"),
      OPTION("port", port, 0, 65535, "TCP port; 0 picks a free one (printed on the first line)"),
      OPTION("http_port", http_port, -1, 65535,
             "HTTP port of the preview page and WebSocket (same address as --bind); "
             "0 picks a free one, -1 turns HTTP off"),
      TEXT("tls_cert", tls_cert_file,
           "PEM certificate (chain) file: serve the HTTP listener as HTTPS and WSS (the BCP1 TCP "
           "port stays plain); needs --tls-key"),
      TEXT("tls_key", tls_key_file, "PEM private key file of --tls-cert"),
      OPTION("device", device_index, -1, 1023, "EGL device index (-1: automatic)"),
      Setting{.name = "platform",
              .type = SettingType::kText,
              .choices = {"auto", "device", "surfaceless"},
              .help = "EGL platform: auto, device or surfaceless",
              .get = [](const ServerConfig& c) -> json { return c.egl_platform; },
              .set = [](ServerConfig& c, const json& v) { c.egl_platform = v.get<std::string>(); }},
      OPTION("render_workers", render_workers, 1, 64, "Render threads, each with a GL context"),
      OPTION("encode_threads", encode_threads, 0, 256,
             "Frame encoding threads; 0: the cores less the render workers and network threads, "
             "at least 2 (hello and stats report the number)"),
      OPTION("network_threads", network_threads, 1, 64, "Threads running connections"),
      OPTION("batch_window_ms", batch_window_ms, 0, 10000,
             "Batch renders of one stored scene arriving within this window into one multi-view "
             "pass (0: off)"),
      OPTION("slice_views", slice_views, 1, 64,
             "Cameras per slice of a render (one GPU batch; the scheduler runs other work between "
             "slices)"),
      OPTION("slice_pixels", slice_pixels, 1, std::int64_t{1} << 30,
             "Pixels per slice at most (cameras x width x height; at least one camera)"),
      FLAG("no_encode_hold", hold_batch_encodes, false,
           "Let batch frames' encodes run while an interactive frame renders"),
      OPTION("preview_bitrate", preview_bitrate_kbps, kMinVideoBitrateKbps, kMaxVideoBitrateKbps,
             "Target bitrate in kbit/s of the preview's video stream (render param \"video\") "
             "when a request names none"),
      OPTION("preview_band_rows", preview_band_rows, 64, kAv1FullSpeedRows,
             "AV1 preview frames whose shorter side is over this many rows go as horizontal bands "
             "of at most this many to clients that stack them (libaom 3.6 runs pictures of 1080 rows "
             "at speed 7, poorly at 10 bits)"),
      Setting{.name = "preview_bit_depth",
              .type = SettingType::kText,
              .choices = {"auto", "8", "10"},
              .help = "Sample depth of AV1 preview streams for clients that decode 10 bits: auto "
                      "(10 up to 2^19 pixels a frame on 4 cores or more, else 8), 8 or 10 (a shorter side under "
                      "1080 pixels, or in bands; a stream too slow at 10 bits goes on at 8)",
              .get = [](const ServerConfig& c) -> json { return c.preview_bit_depth; },
              .set = [](ServerConfig& c, const json& v) { c.preview_bit_depth = v.get<std::string>(); }},
      Setting{.name = "png_encoder",
              .type = SettingType::kText,
              .choices = {"libdeflate", "libpng"},
              .help = "PNG encoder of still frames: libdeflate, or libpng (the setting before "
                      "issue 39, with level 2; docs/performance.md, \"Frame encoders\")",
              .get = [](const ServerConfig& c) -> json {
                return c.png.encoder == PngEncoder::kLibpng ? "libpng" : "libdeflate";
              },
              .set = [](ServerConfig& c, const json& v) {
                c.png.encoder = v == "libpng" ? PngEncoder::kLibpng : PngEncoder::kLibdeflate;
              }},
      Setting{.name = "png_level",
              .type = SettingType::kInteger,
              .min = 0,
              .max = 12,
              .help = "Compression level of PNG frames: libdeflate 0..12 (default 1), libpng "
                      "(zlib) 0..9 (default 2)",
              .get = [](const ServerConfig& c) -> json { return c.png.level; },
              .set = [](ServerConfig& c, const json& v) { c.png.level = v.get<int>(); }},
      Setting{.name = "png_filter",
              .type = SettingType::kText,
              .choices = {"none", "sub", "up", "paeth", "adaptive"},
              .help = "PNG row filter: none, sub or up; libpng also paeth or adaptive",
              .get = [](const ServerConfig& c) -> json { return png_filter_name(c.png); },
              .set = [](ServerConfig& c, const json& v) {
                set_png_filter(c.png, v.get<std::string>());
              }},
      Setting{.name = "assets",
              .type = SettingType::kText,
              .help = "Directory scenes' mesh and volume files are read from",
              .get = [](const ServerConfig& c) -> json { return c.assets_dir.string(); },
              .set = [](ServerConfig& c, const json& v) { c.assets_dir = v.get<std::string>(); }},
      FLAG("no_demo", preload_demo, false, "Do not preload the scene 'demo'"),
      FLAG("quiet_requests", request_log, false,
           "No per-request log lines on stderr (one JSON object per answered request)"),
      OPTION("drain_timeout_ms", drain_timeout_ms, 0, 3600000,
             "On SIGINT/SIGTERM: how long in-flight work may finish before the server exits"),

      // What a request may ask for (PROTOCOL.md, "Limits").
      LIMIT("max_message_bytes", max_message_bytes, 12, kI32,
                     "Largest request (JSON + binary) in bytes: message_too_large"),
      LIMIT("max_request_memory_bytes", max_request_memory_bytes, 1, kI64,
                     "Estimated memory (40 x message bytes) of the requests being read and "
                     "parsed, server-wide: busy (limit_exceeded for one request over it)"),
      LIMIT("max_json_depth", json_limits.max_depth, 1, 100000,
                     "Deepest nesting of objects and arrays in a request (the request is 1)"),
      LIMIT("max_json_values", json_limits.max_values, 1, kI64,
                     "Most JSON values (objects, arrays, scalars) in one request"),
      LIMIT("max_width", scene_limits.max_width, 1, 65536,
                     "Widest frame rendered or composed (cameras, defaults, rigs, atlases)"),
      LIMIT("max_height", scene_limits.max_height, 1, 65536,
                     "Tallest frame rendered or composed"),
      LIMIT("max_pixels", scene_limits.max_pixels, 1, kI64,
                     "Most pixels in one frame (width x height)"),
      LIMIT("max_cameras", scene_limits.max_cameras, 1, 65536,
                     "Most cameras in one render after overrides and rig expansion"),
      LIMIT("max_beams", scene_limits.max_beams, 0, kI32, "Most beams in a scene"),
      LIMIT("max_occluders", scene_limits.max_occluders, 0, kI32,
                     "Most occluders in a scene"),
      LIMIT("max_lights", scene_limits.max_lights, 0, kI32, "Most lights in a scene"),
      LIMIT("max_photons", scene_limits.max_photons, 0, kI64,
                     "Most photons a scene may ask for (gi.photons + gi.caustic_photons)"),
      LIMIT("max_shadow_texels", scene_limits.max_shadow_texels, 0, kI64,
                     "Most shadow-map texels of a lit scene's direct light (points x 6 x "
                     "gi.shadow_size^2)"),
      LIMIT("max_volume_voxels", scene_limits.max_volume_voxels, 0, kI64,
                     "Most voxels of a scene's volumes, summed (2 bytes each)"),
      LIMIT("max_mesh_triangles", scene_limits.max_mesh_triangles, 0, kI64,
                     "Most mesh triangles in a scene, all meshes together"),
      LIMIT("max_slim_spheres", scene_limits.max_slim_spheres, 0, kI64,
                     "Most SLIM support spheres in a scene, all slim occluders together"),
      LIMIT("max_request_cost", max_request_cost, 1, kI64,
                     "Largest estimated cost of one render (about ms on the reference machine; "
                     "PROTOCOL.md, \"Request cost\"): limit_exceeded with the estimate"),
      LIMIT("max_inflight_per_connection", max_inflight_per_connection, 1, 1 << 20,
                     "Unanswered requests one connection may have: busy"),
      LIMIT("max_inflight_total", max_inflight_total, 1, 1 << 20,
                     "Renders in flight on the whole server: busy"),
      LIMIT("max_connections", max_connections, 1, 1 << 20,
                     "Open connections (TCP and WebSocket); one more gets busy and is closed"),
      LIMIT("max_write_queue_bytes", max_write_queue_bytes, 1, kI64,
                     "Unread response bytes per connection before the server stops reading"),
      LIMIT("max_scenes", max_scenes, 1, 1 << 20, "Stored scenes (LRU eviction)"),
      LIMIT("max_scene_store_bytes", max_scene_store_bytes, 1, kI64,
                     "Bytes of stored scene JSON (LRU eviction; a larger scene is refused)"),
      LIMIT("idle_timeout_ms", idle_timeout_ms, 1, kI32,
                     "Close a connection after this long without a byte between messages"),
      LIMIT("read_timeout_ms", read_timeout_ms, 1, kI32,
                     "A message must be complete this long after its first byte: timeout"),
      LIMIT("write_timeout_ms", write_timeout_ms, 1, kI32,
                     "Close a connection that has not taken a response for this long"),
      // Issue 43: work and memory of one render.
      LIMIT("max_render_ms", max_render_ms, 1, kI32,
                     "Wall-clock time a render may take from its arrival (queueing included): "
                     "deadline_exceeded, checked inside the renderer's long loops"),
      LIMIT("max_photon_events", scene_limits.max_photon_events, 0, kI64,
                     "Most photon events (surface hits, medium scatterings; 52 bytes each) "
                     "tracing may store for one scene: limit_exceeded"),

      // Fixed: bounds compiled in (the scene format's and the renderer's).
      FIXED("max_supersample", kMaxSupersample, "Largest output.supersample"),
      FIXED("max_volumes", kMaxVolumes, "Most volumes in a scene"),
      FIXED("max_volume_dimension", kMaxVolumeDimension, "Most voxels on a volume's axis"),
      FIXED("max_transfer_points", kMaxTransferPoints, "Most points of a volume's transfer function"),
      FIXED("max_volume_level", kMaxVolumeLevel, "Largest volume.level"),
      FIXED("max_medium_regions", kMaxMediumRegions, "Most regions of medium (media) in a scene"),
      FIXED("max_medium_mesh_triangles", kMaxMediumMeshTriangles,
            "Most triangles of one mesh region of medium"),
      FIXED("max_batch_views", kMaxBatchViews, "Most views the renderer draws in one multi-view batch"),
      FIXED("min_video_bitrate_kbps", kMinVideoBitrateKbps, "Lowest video bitrate a request may ask for"),
      FIXED("max_video_bitrate_kbps", kMaxVideoBitrateKbps, "Highest video bitrate a request may ask for"),
      FIXED("max_http_header_bytes", kMaxHttpHeaderBytes, "Largest HTTP request header (413 beyond)"),
      FIXED("max_http_body_bytes", kMaxHttpBodyBytes,
            "Smallest body limit of an HTTP request (POST /v1/render: max_message_bytes)"),
      FIXED_SCENE("max_density_samples", max_density_samples, "Most samples of a table density"),
      FIXED_SCENE("min_table", min_table, "Smallest render.table_d and render.table_s"),
      FIXED_SCENE("max_table", max_table, "Largest render.table_d and render.table_s"),
      FIXED_SCENE("max_abs_coordinate", max_abs_coordinate,
                  "Largest absolute value of any position or size (world units)"),
  };
  return kTable;
}

#undef INTEGER
#undef LIMIT
#undef OPTION
#undef TEXT
#undef FLAG
#undef FIXED
#undef FIXED_SCENE

ServerConfig server_defaults() {
  ServerConfig c;
  c.http_port = 7879;
  c.request_log = true;
  return c;
}

std::string settings_markdown(const ServerConfig& defaults) {
  auto cell = [](std::string text) {
    std::string out;
    for (char ch : text) {
      if (ch == '|') out += "\\|";
      else out += ch;
    }
    return out;
  };
  std::string md =
      "| setting | option | kind | default | accepted | what it does |\n"
      "|---|---|---|---|---|---|\n";
  for (const Setting& s : settings_table()) {
    const char* kind = s.kind == SettingKind::kOption  ? "option"
                       : s.kind == SettingKind::kLimit ? "limit"
                                                       : "fixed";
    const std::string option = s.kind == SettingKind::kFixed ? "—" : "`" + s.option() + "`";
    std::string value;
    if (s.secret) {
      value = "none";
    } else {
      const json v = s.get(defaults);
      value = v.is_string() ? (v.get<std::string>().empty() ? "none" : "`" + v.get<std::string>() + "`")
                            : "`" + v.dump() + "`";
    }
    std::string accepted;
    switch (s.type) {
      case SettingType::kInteger:
        accepted = s.kind == SettingKind::kFixed ? "—" : std::to_string(s.min) + " to " + std::to_string(s.max);
        break;
      case SettingType::kNumber:
        accepted = "—";
        break;
      case SettingType::kText:
        if (s.choices.empty()) {
          accepted = "text";
        } else {
          for (std::string_view c : s.choices) accepted += (accepted.empty() ? "`" : ", `") + std::string(c) + "`";
        }
        break;
      case SettingType::kFlag:
        accepted = "flag";
        break;
    }
    std::string help(s.help);
    if (!s.env.empty()) help += " (environment: `" + std::string(s.env) + "`)";
    md += "| `" + std::string(s.name) + "` | " + option + " | " + kind + " | " + value + " | " +
          accepted + " | " + cell(help) + " |\n";
  }
  return md;
}

const Setting* find_setting(std::string_view name) {
  for (const Setting& s : settings_table()) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

namespace {

// Every row `keep` takes, but never a secret one, with its value in `c`.
json rows_json(const ServerConfig& c, bool (*keep)(const Setting&)) {
  json j = json::object();
  for (const Setting& s : settings_table()) {
    if (!s.secret && keep(s)) j[std::string(s.name)] = s.get(c);
  }
  return j;
}

}  // namespace

json limits_json(const ServerConfig& c) {
  return rows_json(c, [](const Setting& s) { return s.kind != SettingKind::kOption; });
}

json settings_json(const ServerConfig& c) {
  return rows_json(c, [](const Setting&) { return true; });
}

std::string finish_settings(ServerConfig& c, const std::set<std::string>& given) {
  const bool libpng = c.png.encoder == PngEncoder::kLibpng;
  if (!given.contains("png_level")) c.png.level = libpng ? 2 : 1;
  if (libpng && c.png.level > 9) {
    return "--png-level " + std::to_string(c.png.level) + ": libpng (zlib) levels are 0..9";
  }
  const std::string filter = png_filter_name(PngSettings{.encoder = PngEncoder::kLibpng,
                                                         .libpng_filters = c.png.libpng_filters});
  if (!libpng && (filter == "paeth" || filter == "adaptive")) {
    return "--png-filter " + filter + " needs --png-encoder libpng";
  }
  if (c.tls_cert_file.empty() != c.tls_key_file.empty()) {
    return "--tls-cert and --tls-key go together";
  }
  return "";
}

}  // namespace beamcast
