#include "server/limits.hpp"

#include <limits>

namespace beamcast {
namespace {

constexpr std::int64_t kI32 = std::numeric_limits<std::int32_t>::max();
constexpr std::int64_t kI64 = std::numeric_limits<std::int64_t>::max();

// One row: NAME is the ServerConfig member path (c.FIELD) as well as the limit's name.
#define BEAMCAST_LIMIT(name, field, lo, hi, help_text)                                      \
  LimitEntry {                                                                             \
    name, lo, hi, help_text, [](const ServerConfig& c) -> std::int64_t {                   \
      return static_cast<std::int64_t>(c.field);                                           \
    },                                                                                     \
        [](ServerConfig& c, std::int64_t v) { c.field = static_cast<decltype(c.field)>(v); } \
  }

}  // namespace

std::string LimitEntry::option() const {
  std::string o = "--" + std::string(name);
  for (char& ch : o) {
    if (ch == '_') ch = '-';
  }
  return o;
}

const std::vector<LimitEntry>& limit_table() {
  static const std::vector<LimitEntry> kTable = {
      BEAMCAST_LIMIT("max_message_bytes", max_message_bytes, 12, kI32,
                     "Largest request (JSON + binary) in bytes: message_too_large"),
      BEAMCAST_LIMIT("max_request_memory_bytes", max_request_memory_bytes, 1, kI64,
                     "Estimated memory (40 x message bytes) of the requests being read and "
                     "parsed, server-wide: busy (limit_exceeded for one request over it)"),
      BEAMCAST_LIMIT("max_json_depth", json_limits.max_depth, 1, 100000,
                     "Deepest nesting of objects and arrays in a request (the request is 1)"),
      BEAMCAST_LIMIT("max_json_values", json_limits.max_values, 1, kI64,
                     "Most JSON values (objects, arrays, scalars) in one request"),
      BEAMCAST_LIMIT("max_width", scene_limits.max_width, 1, 65536,
                     "Widest frame rendered or composed (cameras, defaults, rigs, atlases)"),
      BEAMCAST_LIMIT("max_height", scene_limits.max_height, 1, 65536,
                     "Tallest frame rendered or composed"),
      BEAMCAST_LIMIT("max_pixels", scene_limits.max_pixels, 1, kI64,
                     "Most pixels in one frame (width x height)"),
      BEAMCAST_LIMIT("max_cameras", scene_limits.max_cameras, 1, 65536,
                     "Most cameras in one render after overrides and rig expansion"),
      BEAMCAST_LIMIT("max_beams", scene_limits.max_beams, 0, kI32, "Most beams in a scene"),
      BEAMCAST_LIMIT("max_occluders", scene_limits.max_occluders, 0, kI32,
                     "Most occluders in a scene"),
      BEAMCAST_LIMIT("max_lights", scene_limits.max_lights, 0, kI32, "Most lights in a scene"),
      BEAMCAST_LIMIT("max_photons", scene_limits.max_photons, 0, kI64,
                     "Most photons a scene may ask for (gi.photons + gi.caustic_photons)"),
      BEAMCAST_LIMIT("max_shadow_texels", scene_limits.max_shadow_texels, 0, kI64,
                     "Most shadow-map texels of a lit scene's direct light (points x 6 x "
                     "gi.shadow_size^2)"),
      BEAMCAST_LIMIT("max_volume_voxels", scene_limits.max_volume_voxels, 0, kI64,
                     "Most voxels of a scene's volumes, summed (2 bytes each)"),
      BEAMCAST_LIMIT("max_mesh_triangles", scene_limits.max_mesh_triangles, 0, kI64,
                     "Most mesh triangles in a scene, all meshes together"),
      BEAMCAST_LIMIT("max_slim_spheres", scene_limits.max_slim_spheres, 0, kI64,
                     "Most SLIM support spheres in a scene, all slim occluders together"),
      BEAMCAST_LIMIT("max_request_cost", max_request_cost, 1, kI64,
                     "Largest estimated cost of one render (about ms on the reference machine; "
                     "PROTOCOL.md, \"Request cost\"): limit_exceeded with the estimate"),
      BEAMCAST_LIMIT("max_inflight_per_connection", max_inflight_per_connection, 1, 1 << 20,
                     "Unanswered requests one connection may have: busy"),
      BEAMCAST_LIMIT("max_inflight_total", max_inflight_total, 1, 1 << 20,
                     "Renders in flight on the whole server: busy"),
      BEAMCAST_LIMIT("max_connections", max_connections, 1, 1 << 20,
                     "Open connections (TCP and WebSocket); one more gets busy and is closed"),
      BEAMCAST_LIMIT("max_write_queue_bytes", max_write_queue_bytes, 1, kI64,
                     "Unread response bytes per connection before the server stops reading"),
      BEAMCAST_LIMIT("max_scenes", max_scenes, 1, 1 << 20, "Stored scenes (LRU eviction)"),
      BEAMCAST_LIMIT("max_scene_store_bytes", max_scene_store_bytes, 1, kI64,
                     "Bytes of stored scene JSON (LRU eviction; a larger scene is refused)"),
      BEAMCAST_LIMIT("idle_timeout_ms", idle_timeout_ms, 1, kI32,
                     "Close a connection after this long without a byte between messages"),
      BEAMCAST_LIMIT("read_timeout_ms", read_timeout_ms, 1, kI32,
                     "A message must be complete this long after its first byte: timeout"),
      BEAMCAST_LIMIT("write_timeout_ms", write_timeout_ms, 1, kI32,
                     "Close a connection that has not taken a response for this long"),
      // Issue 43: work and memory of one render.
      BEAMCAST_LIMIT("max_render_ms", max_render_ms, 1, kI32,
                     "Wall-clock time a render may take from its arrival (queueing included): "
                     "deadline_exceeded, checked inside the renderer's long loops"),
      BEAMCAST_LIMIT("max_photon_events", scene_limits.max_photon_events, 0, kI64,
                     "Most photon events (surface hits, medium scatterings; 52 bytes each) "
                     "tracing may store for one scene: limit_exceeded"),
  };
  return kTable;
}

#undef BEAMCAST_LIMIT

nlohmann::json limits_json(const ServerConfig& c) {
  nlohmann::json j = nlohmann::json::object();
  for (const LimitEntry& e : limit_table()) j[std::string(e.name)] = e.get(c);
  return j;
}

}  // namespace beamcast
