#include "protocol/render_response.hpp"

#include <algorithm>
#include <limits>
#include <tuple>

#include "protocol/json_reader.hpp"

namespace beamcast {

using json = nlohmann::json;
using namespace json_read;

bool RenderAtlas::operator==(const RenderAtlas& o) const {
  return std::tie(columns, rows, cell_width, cell_height) ==
             std::tie(o.columns, o.rows, o.cell_width, o.cell_height) &&
         tiles.size() == o.tiles.size() && std::equal(tiles.begin(), tiles.end(), o.tiles.begin());
}

bool RenderFrame::operator==(const RenderFrame& o) const {
  return std::tie(camera, index, width, height, gpu_ms, pass_ms, readback_ms, gpu_batch, photons,
                  x, y, format, bit_depth, encode_ms, attachment, data_base64) ==
             std::tie(o.camera, o.index, o.width, o.height, o.gpu_ms, o.pass_ms, o.readback_ms,
                      o.gpu_batch, o.photons, o.x, o.y, o.format, o.bit_depth, o.encode_ms,
                      o.attachment, o.data_base64) &&
         atlas.has_value() == o.atlas.has_value() && (!atlas || *atlas == *o.atlas);
}

// --- writing ---

json to_json(const RenderFrame& f) {
  json j = {{"camera", f.camera}, {"index", f.index}, {"width", f.width}, {"height", f.height}};
  if (f.gpu_ms) j["gpu_ms"] = *f.gpu_ms;
  if (f.pass_ms) {
    json p = json::object();
    for (const PassTime& t : *f.pass_ms) p[t.name] = t.gpu_ms;
    j["pass_ms"] = std::move(p);
  }
  if (f.readback_ms) j["readback_ms"] = *f.readback_ms;
  if (f.gpu_batch) {
    const GpuBatch& b = *f.gpu_batch;
    j["gpu_batch"] = {{"index", b.index},
                      {"views", b.views},
                      {"gpu_ms", b.gpu_ms},
                      {"readback_ms", b.readback_ms}};
  }
  if (f.photons) {
    j["photons"] = {{"count", f.photons->count},
                    {"disks", f.photons->disks},
                    {"trace_ms", f.photons->trace_ms},
                    {"upload_ms", f.photons->upload_ms}};
  }
  if (f.x) j["x"] = *f.x;
  if (f.y) j["y"] = *f.y;
  if (f.format) j["format"] = *f.format;
  if (f.bit_depth) j["bit_depth"] = *f.bit_depth;
  if (f.encode_ms) j["encode_ms"] = *f.encode_ms;
  if (f.attachment)
    j["attachment"] = {{"offset", f.attachment->offset}, {"length", f.attachment->length}};
  if (f.data_base64) j["data_base64"] = *f.data_base64;
  if (f.atlas) {
    const RenderAtlas& a = *f.atlas;
    json tiles = json::array();
    for (const RenderFrame& t : a.tiles) tiles.push_back(to_json(t));
    j["atlas"] = {{"columns", a.columns},
                  {"rows", a.rows},
                  {"cell_width", a.cell_width},
                  {"cell_height", a.cell_height},
                  {"tiles", std::move(tiles)}};
  }
  return j;
}

namespace {

json to_json(const QualityReport& q) {
  json j = {{"mode", q.mode},           {"level", q.level},
            {"levels", q.levels},       {"label", q.label},
            {"reason", q.reason},       {"still", q.still},
            {"moving", q.moving},       {"scale", q.scale},
            {"method", q.method},       {"table", q.table},
            {"samples", q.samples},     {"format", q.format},
            {"budget_ms", q.budget_ms}, {"estimate_ms", q.estimate_ms},
            {"frame_ms", q.frame_ms}};
  if (q.jpeg_quality) j["jpeg_quality"] = *q.jpeg_quality;
  if (q.bitrate_kbps) j["bitrate_kbps"] = *q.bitrate_kbps;
  if (q.keyframe) j["keyframe"] = *q.keyframe;
  if (q.encoder_speed) j["encoder_speed"] = *q.encoder_speed;
  if (q.encoder_bit_depth) j["encoder_bit_depth"] = *q.encoder_bit_depth;
  if (q.encoder_bands) j["encoder_bands"] = *q.encoder_bands;
  return j;
}

}  // namespace

json to_json(const RenderResponse& r) {
  json frames = json::array();
  for (const RenderFrame& f : r.frames) frames.push_back(to_json(f));
  json j = {{"passes", r.passes},
            {"batched", r.batched},
            {"batch", {{"requests", r.batch_requests}, {"views", r.batch_views}}},
            {"frames", std::move(frames)},
            {"timings",
             {{"queue_ms", r.timings.queue_ms},
              {"render_ms", r.timings.render_ms},
              {"readback_ms", r.timings.readback_ms},
              {"encode_ms", r.timings.encode_ms},
              {"server_ms", r.timings.server_ms}}}};
  if (r.quality) j["quality"] = to_json(*r.quality);
  if (r.stream) {
    j["stream"] = {{"part", r.stream->part}, {"last", r.stream->last}, {"frames", r.stream->frames}};
  }
  return j;
}

// --- reading (ObjectReader: typed, with the pointer of a bad field) ---

namespace {

template <class T>
T read_ranged(const Node& n, std::int64_t lo, std::int64_t hi) {
  const std::int64_t v = read_integer(n);
  if (v < lo || v > hi) {
    fail("out_of_range", n.path,
         n.name() + " must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
             std::to_string(v));
  }
  return static_cast<T>(v);
}
int read_int(const Node& n) {
  return read_ranged<int>(n, std::numeric_limits<int>::min(), std::numeric_limits<int>::max());
}
std::uint64_t read_size(const Node& n) {
  return read_ranged<std::uint64_t>(n, 0, std::numeric_limits<std::int64_t>::max());
}

template <class T, class F>
std::optional<T> read_optional(const ObjectReader& r, std::string_view key, F read) {
  if (auto n = r.optional(key)) return read(*n);
  return std::nullopt;
}

RenderFrame read_frame(const Node& n) {
  const ObjectReader r(n, "a frame");
  RenderFrame f;
  f.camera = read_string(r.required("camera"));
  f.index = read_size(r.required("index"));
  f.width = read_int(r.required("width"));
  f.height = read_int(r.required("height"));
  f.gpu_ms = read_optional<double>(r, "gpu_ms", read_number);
  if (auto p = r.optional("pass_ms")) {
    const ObjectReader passes(*p, "pass_ms");
    f.pass_ms.emplace();
    for (const auto& [name, value] : p->json().items()) {
      f.pass_ms->push_back({name, read_number(passes.required(name))});
    }
  }
  f.readback_ms = read_optional<double>(r, "readback_ms", read_number);
  if (auto b = r.optional("gpu_batch")) {
    const ObjectReader br(*b, "gpu_batch");
    f.gpu_batch =
        GpuBatch{read_int(br.required("index")), read_int(br.required("views")),
                 read_number(br.required("gpu_ms")), read_number(br.required("readback_ms"))};
  }
  if (auto p = r.optional("photons")) {
    const ObjectReader pr(*p, "photons");
    f.photons = PhotonReport{read_integer(pr.required("count")), read_number(pr.required("trace_ms")),
                             read_number(pr.required("upload_ms"))};
    // Servers before gi.cluster sent no disks: one per photon.
    const auto disks = pr.optional("disks");
    f.photons->disks = disks ? read_integer(*disks) : f.photons->count;
  }
  f.x = read_optional<int>(r, "x", read_int);
  f.y = read_optional<int>(r, "y", read_int);
  f.format = read_optional<std::string>(r, "format", read_string);
  f.bit_depth = read_optional<int>(r, "bit_depth", read_int);
  f.encode_ms = read_optional<double>(r, "encode_ms", read_number);
  if (auto a = r.optional("attachment")) {
    const ObjectReader ar(*a, "attachment");
    f.attachment = Attachment{read_size(ar.required("offset")), read_size(ar.required("length"))};
  }
  f.data_base64 = read_optional<std::string>(r, "data_base64", read_string);
  if (auto a = r.optional("atlas")) {
    const ObjectReader ar(*a, "atlas");
    RenderAtlas atlas;
    atlas.columns = read_int(ar.required("columns"));
    atlas.rows = read_int(ar.required("rows"));
    atlas.cell_width = read_int(ar.required("cell_width"));
    atlas.cell_height = read_int(ar.required("cell_height"));
    for (const Node& t : read_array(ar.required("tiles"))) atlas.tiles.push_back(read_frame(t));
    f.atlas = std::move(atlas);
  }
  return f;
}

QualityReport read_quality(const Node& n) {
  const ObjectReader r(n, "quality");
  QualityReport q;
  q.mode = read_string(r.required("mode"));
  q.level = read_size(r.required("level"));
  q.levels = read_size(r.required("levels"));
  q.label = read_string(r.required("label"));
  q.reason = read_string(r.required("reason"));
  q.still = read_bool(r.required("still"));
  q.moving = read_bool(r.required("moving"));
  q.scale = read_number(r.required("scale"));
  q.method = read_string(r.required("method"));
  const Node table = r.required("table");
  const std::vector<Node> t = read_array(table, 2, "table");
  if (t.size() != 2) fail("wrong_type", table.path, "table must be an array of 2 integers");
  q.table = {read_int(t[0]), read_int(t[1])};
  q.samples = read_int(r.required("samples"));
  q.format = read_string(r.required("format"));
  q.jpeg_quality = read_optional<int>(r, "jpeg_quality", read_int);
  q.bitrate_kbps = read_optional<int>(r, "bitrate_kbps", read_int);
  q.keyframe = read_optional<bool>(r, "keyframe", read_bool);
  q.encoder_speed = read_optional<int>(r, "encoder_speed", read_int);
  q.encoder_bit_depth = read_optional<int>(r, "encoder_bit_depth", read_int);
  q.encoder_bands = read_optional<int>(r, "encoder_bands", read_int);
  q.budget_ms = read_number(r.required("budget_ms"));
  q.estimate_ms = read_number(r.required("estimate_ms"));
  q.frame_ms = read_number(r.required("frame_ms"));
  return q;
}

}  // namespace

RenderResponse render_response_from_json(const json& result, const std::string& path) {
  const ObjectReader r(Node{&result, path}, "a render result");
  RenderResponse out;
  for (const Node& p : read_array(r.required("passes"))) out.passes.push_back(read_string(p));
  for (const Node& f : read_array(r.required("frames"))) out.frames.push_back(read_frame(f));
  out.batched = read_bool(r.required("batched"));
  const ObjectReader batch(r.required("batch"), "batch");
  out.batch_requests = read_int(batch.required("requests"));
  out.batch_views = read_int(batch.required("views"));
  const ObjectReader t(r.required("timings"), "timings");
  out.timings =
      RenderTimings{read_number(t.required("queue_ms")), read_number(t.required("render_ms")),
                    read_number(t.required("readback_ms")), read_number(t.required("encode_ms")),
                    read_number(t.required("server_ms"))};
  if (auto q = r.optional("quality")) out.quality = read_quality(*q);
  if (auto st = r.optional("stream")) {
    const ObjectReader sr(*st, "stream");
    out.stream = StreamPart{read_int(sr.required("part")), read_bool(sr.required("last")),
                            read_size(sr.required("frames"))};
  }
  return out;
}

}  // namespace beamcast
