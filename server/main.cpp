// beamcast-server: the Beamcast render service (protocol/PROTOCOL.md).
#include <cstdint>
#include <cstdio>
#include <exception>
#include <set>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "protocol/scene_json.hpp"
#include "protocol/bounded_json.hpp"
#include "protocol/data_dir.hpp"
#include "protocol/request.hpp"
#include "server/demo_scene.hpp"
#include "server/settings.hpp"
#include "server/server.hpp"

int main(int argc, char** argv) {
  using namespace beamcast;
  ServerConfig c = server_defaults();
  c.assets_dir = find_data_dir("examples");

  CLI::App app{"beamcast-server: headless energy-beam render service (protocol/PROTOCOL.md)"};
  // One option per row of the settings table (server/settings.cpp), fixed
  // rows aside; each value is held here until the command line is read.
  const std::vector<Setting>& table = settings_table();
  std::vector<std::int64_t> integers(table.size());
  std::vector<std::string> texts(table.size());
  std::vector<CLI::Option*> options(table.size(), nullptr);
  for (std::size_t i = 0; i < table.size(); ++i) {
    const Setting& s = table[i];
    const std::string help(s.help);
    switch (s.type) {
      case SettingType::kInteger:
        if (s.kind == SettingKind::kFixed) break;
        integers[i] = s.get(c).get<std::int64_t>();
        options[i] = app.add_option(s.option(), integers[i], help)
                         ->check(CLI::Range(s.min, s.max))
                         ->capture_default_str();
        break;
      case SettingType::kText: {
        texts[i] = s.get(c).get<std::string>();
        options[i] = app.add_option(s.option(), texts[i], help);
        if (!s.secret) options[i]->capture_default_str();
        if (!s.env.empty()) options[i]->envname(std::string(s.env));
        if (!s.choices.empty()) {
          options[i]->check(CLI::IsMember(std::vector<std::string>(s.choices.begin(), s.choices.end())));
        }
        break;
      }
      case SettingType::kFlag:
        options[i] = app.add_flag(s.option(), help);
        break;
      case SettingType::kNumber:
        break;  // fixed rows only
    }
  }
  bool print_settings = false;
  app.add_flag("--settings-markdown", print_settings,
               "Print the table of every setting (docs/guide/server-settings.md) and exit");
  CLI11_PARSE(app, argc, argv);
  if (print_settings) {
    std::fputs(settings_markdown(server_defaults()).c_str(), stdout);
    return 0;
  }
  std::set<std::string> given;  // rows named on the command line (or in the environment)
  for (std::size_t i = 0; i < table.size(); ++i) {
    const Setting& s = table[i];
    if (!options[i]) continue;
    if (options[i]->count() > 0) given.insert(std::string(s.name));
    switch (s.type) {
      case SettingType::kInteger:
        s.set(c, integers[i]);
        break;
      case SettingType::kText:
        s.set(c, texts[i]);
        break;
      case SettingType::kFlag:
        s.set(c, options[i]->count() > 0);
        break;
      case SettingType::kNumber:
        break;
    }
  }
  if (const std::string problem = finish_settings(c, given); !problem.empty()) {
    std::fprintf(stderr, "beamcast-server: %s\n", problem.c_str());
    return 1;
  }

  try {
    RendererOptions ropts;
    ropts.egl.device_index = c.device_index;
    ropts.egl.platform = c.egl_platform;
    // The demo scene is checked against this server's limits before it
    // listens: a limit it exceeds is a start-up error that names it.
    std::shared_ptr<StoredScene> demo;
    if (c.preload_demo) {
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
