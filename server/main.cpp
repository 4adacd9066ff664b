// beamcast-server: the Beamcast render service (protocol/PROTOCOL.md).
#include <cstdint>
#include <cstdio>
#include <vector>
#include <exception>

#include <CLI/CLI.hpp>

#include "protocol/scene_json.hpp"
#include "protocol/bounded_json.hpp"
#include "protocol/data_dir.hpp"
#include "protocol/request.hpp"
#include "server/demo_scene.hpp"
#include "server/limits.hpp"
#include "server/server.hpp"

int main(int argc, char** argv) {
  using namespace beamcast;
  ServerConfig c;
  c.assets_dir = find_data_dir("examples");
  c.http_port = 7879;
  std::string assets = c.assets_dir.string();
  bool no_demo = false;

  CLI::App app{"beamcast-server: headless energy-beam render service (protocol/PROTOCOL.md)"};
  app.add_option("--bind", c.bind, "Address to listen on")->capture_default_str();
  app.add_option("--token", c.token,
                 "Shared token clients must send in hello (params.token); required to bind a "
                 "non-loopback address")
      ->envname("BEAMCAST_TOKEN");
  app.add_flag("--insecure-no-token", c.insecure_no_token,
               "Allow a non-loopback bind without a token (anyone who can reach the port may "
               "render; docs/security.md)");
  app.add_option("--port", c.port, "TCP port; 0 picks a free one (printed on the first line)")
      ->capture_default_str();
  app.add_option("--http-port", c.http_port,
                 "HTTP port of the preview page and WebSocket (same address as --bind); "
                 "0 picks a free one, -1 turns HTTP off")
      ->check(CLI::Range(-1, 65535))->capture_default_str();
  auto* tls_cert = app.add_option("--tls-cert", c.tls_cert_file,
                                  "PEM certificate (chain) file: serve the HTTP listener as HTTPS "
                                  "and WSS (the BCP1 TCP port stays plain); needs --tls-key");
  auto* tls_key = app.add_option("--tls-key", c.tls_key_file,
                                 "PEM private key file of --tls-cert");
  tls_cert->needs(tls_key);
  tls_key->needs(tls_cert);
  app.add_option("--device", c.device_index, "EGL device index (-1: automatic)")->capture_default_str();
  app.add_option("--platform", c.egl_platform, "EGL platform: auto, device or surfaceless")
      ->check(CLI::IsMember({"auto", "device", "surfaceless"}));
  app.add_option("--render-workers", c.render_workers, "Render threads, each with a GL context")
      ->check(CLI::Range(1, 64))->capture_default_str();
  app.add_option("--encode-threads", c.encode_threads,
                 "Frame encoding threads; 0: the cores less the render workers and network "
                 "threads, at least 2 (hello and stats report the number)")
      ->check(CLI::Range(0, 256))->capture_default_str();
  app.add_option("--batch-window-ms", c.batch_window_ms,
                 "Batch renders of one stored scene arriving within this window into one "
                 "multi-view pass (0: off)")
      ->check(CLI::Range(0, 10000))->capture_default_str();
  app.add_option("--slice-views", c.slice_views,
                 "Cameras per slice of a render (one GPU batch; the scheduler runs other work "
                 "between slices)")
      ->check(CLI::Range(1, 64))->capture_default_str();
  app.add_option("--slice-pixels", c.slice_pixels,
                 "Pixels per slice at most (cameras x width x height; at least one camera)")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1} << 30))->capture_default_str();
  app.add_option("--preview-bitrate", c.preview_bitrate_kbps,
                 "Target bitrate in kbit/s of the preview's video stream (render param \"video\") "
                 "when a request names none")
      ->check(CLI::Range(kMinVideoBitrateKbps, kMaxVideoBitrateKbps))->capture_default_str();
  bool no_encode_hold = false;
  app.add_flag("--no-encode-hold", no_encode_hold,
               "Let batch frames' encodes run while an interactive frame renders");
  app.add_option("--network-threads", c.network_threads, "Threads running connections")
      ->check(CLI::Range(1, 64))->capture_default_str();
  std::string png_encoder = "libdeflate";
  app.add_option("--png-encoder", png_encoder,
                 "PNG encoder of still frames: libdeflate, or libpng (the setting before issue 39, "
                 "with level 2; docs/performance.md, \"Frame encoders\")")
      ->check(CLI::IsMember({"libdeflate", "libpng"}))->capture_default_str();
  int png_level = -1;
  app.add_option("--png-level", png_level,
                 "Compression level of PNG frames: libdeflate 0..12 (default 1), libpng (zlib) "
                 "0..9 (default 2)")
      ->check(CLI::Range(-1, 12));
  std::string png_filter = "sub";
  app.add_option("--png-filter", png_filter,
                 "PNG row filter: none, sub or up; libpng also paeth or adaptive")
      ->check(CLI::IsMember({"none", "sub", "up", "paeth", "adaptive"}))->capture_default_str();
  app.add_option("--assets", assets, "Directory scenes' mesh files are read from")->capture_default_str();
  app.add_flag("--no-demo", no_demo, "Do not preload the scene 'demo'");
  bool quiet_requests = false;
  app.add_flag("--quiet-requests", quiet_requests,
               "No per-request log lines on stderr (one JSON object per answered request)");
  // Every limit of PROTOCOL.md's table is an option, from the one table (server/limits.hpp).
  std::vector<std::int64_t> limit_values;
  for (const LimitEntry& e : limit_table()) limit_values.push_back(e.get(c));
  for (std::size_t i = 0; i < limit_table().size(); ++i) {
    const LimitEntry& e = limit_table()[i];
    app.add_option(e.option(), limit_values[i], std::string(e.help))
        ->check(CLI::Range(e.min, e.max))
        ->capture_default_str();
  }
  app.add_option("--drain-timeout-ms", c.drain_timeout_ms,
                 "On SIGINT/SIGTERM: how long in-flight work may finish before the server exits")
      ->check(CLI::Range(0, 3600000))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  for (std::size_t i = 0; i < limit_table().size(); ++i) limit_table()[i].set(c, limit_values[i]);
  c.assets_dir = assets;
  c.request_log = !quiet_requests;
  c.hold_batch_encodes = !no_encode_hold;
  const bool libpng = png_encoder == "libpng";
  c.png.encoder = libpng ? PngEncoder::kLibpng : PngEncoder::kLibdeflate;
  c.png.level = png_level >= 0 ? png_level : (libpng ? 2 : 1);
  if (libpng && c.png.level > 9) {
    std::fprintf(stderr, "beamcast-server: --png-level %d: libpng (zlib) levels are 0..9\n", png_level);
    return 1;
  }
  if (!libpng && (png_filter == "paeth" || png_filter == "adaptive")) {
    std::fprintf(stderr, "beamcast-server: --png-filter %s needs --png-encoder libpng\n",
                 png_filter.c_str());
    return 1;
  }
  // libpng's PNG_FILTER_* masks; libdeflate's encoder writes one filter type.
  c.png.libpng_filters = png_filter == "none"    ? 0x08
                         : png_filter == "sub"   ? 0x10
                         : png_filter == "up"    ? 0x20
                         : png_filter == "paeth" ? 0x80
                                                 : 0xF8;
  c.png.row_filter = png_filter == "none" ? PngRowFilter::kNone
                     : png_filter == "up" ? PngRowFilter::kUp
                                          : PngRowFilter::kSub;

  try {
    RendererOptions ropts;
    ropts.egl.device_index = c.device_index;
    ropts.egl.platform = c.egl_platform;
    // The demo scene is checked against this server's limits before it
    // listens: a limit it exceeds is a start-up error that names it.
    std::shared_ptr<StoredScene> demo;
    if (!no_demo) {
      try {
        const auto j = parse_json_or_throw(kDemoSceneJson, c.json_limits);
        SceneLoadOptions opts{c.assets_dir, c.scene_limits};
        demo = std::make_shared<StoredScene>();
        demo->scene = parse_scene(j, opts);
        demo->bytes = j.dump().size();
        demo->json = j;
        if (demo->bytes > c.max_scene_store_bytes) {
          throw ProtocolError({"limit_exceeded",
                               "it takes " + std::to_string(demo->bytes) +
                                   " bytes, over max_scene_store_bytes = " +
                                   std::to_string(c.max_scene_store_bytes),
                               ""});
        }
      } catch (const ProtocolError& e) {
        std::fprintf(stderr,
                     "beamcast-server: the demo scene (examples/paper_10sets.json, preloaded as "
                     "'demo') does not fit this server's limits: %s; raise the limit or pass "
                     "--no-demo\n",
                     e.what());
        return 1;
      }
    }
    Server server(c, gl_renderer_factory(ropts));
    const unsigned short port = server.start();
    // First line of output: tools and tests read the port from it.
    std::printf("beamcast-server listening on %s:%u\n", c.bind.c_str(), port);
    if (c.http_port >= 0) {
      const bool v6 = c.bind.find(':') != std::string::npos;
      std::printf("beamcast-server preview: %s://%s%s%s:%u/\n",
                  c.tls_cert_file.empty() ? "http" : "https", v6 ? "[" : "", c.bind.c_str(),
                  v6 ? "]" : "", server.http_port());
    }
    std::fflush(stdout);
    std::fprintf(stderr, "beamcast-server: renderer: %s\n",
                 server.core().renderer_description.c_str());
    if (demo) {
      server.core().scenes.put("demo", std::move(demo));
      std::fprintf(stderr, "beamcast-server: scene 'demo' preloaded (the paper's 10 beam sets)\n");
    }
    server.run(/*handle_signals=*/true);
    std::fprintf(stderr, "beamcast-server: stopped\n");
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "beamcast-server: %s\n", e.what());
    return 1;
  }
}
