// Every limit and knob of the server, with defaults (documented in
// protocol/PROTOCOL.md, "Limits", and docs/guide/server-options.md); each
// is a row of the settings table (server/settings.cpp), which makes it a
// command-line option of beamcast-server and reports it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "protocol/bounded_json.hpp"
#include "protocol/scene_json.hpp"
#include "render/image.hpp"
#include "render/video.hpp"

namespace beamcast {

struct ServerConfig {
  std::string bind = "127.0.0.1";
  // Shared secret clients present in hello (params.token); empty: no auth.
  // Required for a non-loopback bind unless insecure_no_token (server/auth.hpp).
  std::string token;
  bool insecure_no_token = false;
  bool request_log = false;  // one JSON line per request on stderr (beamcast-server: on)
  bool preload_demo = true;  // beamcast-server: store the scene "demo" before listening
  unsigned short port = 7878;  // 0: any free port
  // HTTP listener (preview page, WebSocket, GET endpoints) on `bind`; -1: none,
  // 0: any free port. beamcast-server turns it on (7879) by default.
  int http_port = -1;
  // TLS for the HTTP listener (HTTPS/WSS): PEM certificate chain and private
  // key files, both or neither (docs/security.md). The BCP1 port stays plain.
  std::string tls_cert_file;
  std::string tls_key_file;
  int device_index = -1;       // EGL device; -1: automatic
  std::string egl_platform = "auto";
  int render_workers = 1;  // threads that each own a GL context
  // Frame encoding pool; 0: default_encode_threads (server/threads.hpp), the
  // cores less the render workers and network threads, at least 2.
  int encode_threads = 0;
  int network_threads = 1;
  // Cross-connection batching: renders of one stored scene arriving within this
  // many ms are rendered as one multi-view pass. 0: off (lowest latency).
  int batch_window_ms = 0;
  // Cameras per slice: a render is run in slices of at most this many cameras
  // (one GPU batch each), encoded while the next renders; the scheduler picks
  // the next slice between them (PROTOCOL.md, "Scheduling"). 4: the
  // renderer's batch size (FrameOptions::max_batch_views).
  int slice_views = 4;
  // ... and at most this many pixels (cameras x width x height; at least one
  // camera). 2^18 = one 512x512 frame: on llvmpipe a 16-camera request ran
  // 0.81-0.93x the time of 16 single requests at 256x256 with 4-camera slices,
  // but 1.11-1.20x at 512x512, where one-camera slices gave 0.96-1.03x
  // (docs/performance.md, "Slice size").
  std::int64_t slice_pixels = 1 << 18;
  // Batch frames' encodes wait while an interactive slice renders (the
  // preview's render then has the CPU to itself on a software rasterizer);
  // docs/performance.md, "Encode hold".
  bool hold_batch_encodes = true;
  // PNG encoder, level and row filter, chosen by measurement
  // (docs/performance.md, "Frame encoders"): libdeflate level 1, SUB. The
  // setting before issue 39 is --png-encoder libpng (zlib level 2, SUB).
  PngSettings png;
  // Target bitrate of the preview's video stream when a request names none
  // (render param "video"; PROTOCOL.md, "Video preview").
  int preview_bitrate_kbps = 1000;
  // AV1 preview streams' sample depth for clients that decode 10 bits
  // ("video": {"bit_depth": 10}): "auto" (video_encoder_bit_depth: 10 up to
  // 2^19 pixels on 4 cores or more), "8" or "10" (any machine, frames whose
  // shorter side is under 1080 or in bands: video_ten_bit_sound; a stream too
  // slow at 10 bits falls back to 8 within itself).
  std::string preview_bit_depth = "auto";
  std::filesystem::path assets_dir;

  SceneLimits scene_limits = kServerSceneLimits;
  std::uint64_t max_message_bytes = 16u << 20;
  // Server-wide budget of the requests being read and parsed, each counted
  // at its estimated cost (server/memory.hpp): 40 x 16 MiB, so one request of
  // max_message_bytes fits alone.
  std::uint64_t max_request_memory_bytes = 640ull << 20;
  // Enforced while a request's JSON is parsed (protocol/bounded_json.hpp):
  // max_json_depth (nesting) and max_json_values (values in one request).
  JsonLimits json_limits;
  // Largest estimated cost of one render (protocol/request_cost.hpp: about
  // milliseconds on the 2-core llvmpipe reference machine), checked before any
  // work starts: limit_exceeded with the estimate.
  std::int64_t max_request_cost = 120000;
  int max_inflight_per_connection = 16;
  int max_inflight_total = 64;
  int max_connections = 256;
  std::uint64_t max_write_queue_bytes = 64u << 20;
  int max_scenes = 256;
  std::uint64_t max_scene_store_bytes = 64u << 20;
  int idle_timeout_ms = 300000;
  int read_timeout_ms = 10000;
  int write_timeout_ms = 30000;
  int drain_timeout_ms = 10000;  // on SIGINT/SIGTERM: how long in-flight work may finish
  // Wall-clock time a render request may take from its arrival, queueing
  // included: past it, deadline_exceeded (RenderJob::deadline).
  int max_render_ms = 120000;
  // The most rows on the shorter side of one AV1 picture for clients that
  // stack bands ("video": {"bands": true}): a larger frame goes as bands of at
  // most this many rows (video_encoder_bands). libaom 3.6 runs pictures of
  // 1080 rows and more at speed 7 (kAv1FullSpeedRows); under 1079 is for tests.
  int preview_band_rows = kAv1FullSpeedRows;
};

}  // namespace beamcast
