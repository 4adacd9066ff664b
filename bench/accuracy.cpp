#include "bench/accuracy.hpp"

#include <sys/utsname.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <thread>

#include "bench/accuracy_report.hpp"
#include "protocol/data_dir.hpp"
#include "render/image.hpp"
#include "render/reference.hpp"
#include "render/renderer.hpp"

namespace beamcast::bench {
namespace {

constexpr TableLayout kAllLayouts[] = {TableLayout::kUniform, TableLayout::kChord,
                                       TableLayout::kWarped, TableLayout::kChordWarped};
constexpr MarchRule kRules[] = {MarchRule::kMidpoint, MarchRule::kSimpson};

// Adaptive repetition: about this much wall time per setting, within
// [kMinRepeats, kMaxRepeats] frames, so cheap settings get stable medians and
// slow ones (beams_1000 on llvmpipe) do not stretch the run past ~10 minutes.
constexpr double kTargetMs = 1000.0;
constexpr int kMinRepeats = 3;
constexpr int kMaxRepeats = 9;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double pass_ms(const FrameResult& fr, const char* name) {
  for (const PassTiming& p : fr.passes) {
    if (p.name == name) return p.gpu_ms;
  }
  return 0.0;
}

RenderSettings table_setting(TableLayout layout, TableFilter filter, int size) {
  RenderSettings s;
  s.method = IntegrationMethod::kTable;
  s.layout = layout;
  s.filter = filter;
  s.table_d = s.table_s = size;
  return s;
}

RenderSettings march_setting(MarchRule rule, int samples) {
  RenderSettings s;
  s.method = IntegrationMethod::kMarch;
  s.rule = rule;
  s.samples = samples;
  return s;
}

std::string machine_string() {
  std::string m = std::to_string(std::thread::hardware_concurrency()) + " CPU threads";
  utsname u{};
  if (uname(&u) == 0) m += std::string(", ") + u.sysname + " " + u.release + " " + u.machine;
  return m;
}

// The reference once per scene; its tone-mapped image is what PSNR compares with.
struct Reference {
  HdrImage hdr;
  Image image;
};

// One row: a warm-up frame (which also gives the error: the renderer is
// deterministic, so every repeat would give the same picture), then `repeats`
// timed frames of the same camera in one render call, sharing the uploaded
// tables as a real multi-frame client would.
AccuracyRow measure(Renderer& renderer, const BenchScene& bs, const RenderSettings& settings,
                    const Reference& ref, bool quick) {
  Scene scene = bs.scene;
  scene.render = settings;
  const Camera& cam = scene.cameras[0];
  const FrameResult first = renderer.render(scene, {cam}, FrameOptions{.read_hdr = true}).at(0);

  AccuracyRow row;
  row.scene = bs.name;
  row.settings = settings;
  const HdrError e = compare_hdr(first.hdr, ref.hdr);
  row.max_abs = e.max_abs;
  row.rms = e.rms;
  row.rel_l1 = e.rel_l1;
  row.nonfinite = e.nonfinite;
  row.psnr_db = compare_levels(first.image, ref.image).psnr_db;

  row.repeats = quick ? kMinRepeats
                      : std::clamp(static_cast<int>(kTargetMs / std::max(first.wall_ms, 1e-3)),
                                   kMinRepeats, kMaxRepeats);
  const std::vector<FrameResult> frames =
      renderer.render(scene, std::vector<Camera>(row.repeats, cam));
  std::vector<double> gpu, beam, wall;
  for (const FrameResult& fr : frames) {
    gpu.push_back(fr.gpu_ms);
    beam.push_back(pass_ms(fr, "beams"));
    wall.push_back(fr.wall_ms);
  }
  row.gpu_ms = median(gpu);
  row.beam_gpu_ms = median(beam);
  row.wall_ms = median(wall);
  return row;
}

// The paper's setting and the default on one scene, alternately, `rounds`
// times `per_round` frames each; medians of each side.
RunInfo::Interleaved interleave(Renderer& renderer, const BenchScene& bs, const Reference& ref,
                                int rounds, int per_round) {
  RunInfo::Interleaved out;
  out.scene = bs.name;
  Scene paper = bs.scene, deflt = bs.scene;
  paper.render = table_setting(TableLayout::kUniform, TableFilter::kHardware, 32);
  deflt.render = RenderSettings{};
  const Camera& cam = bs.scene.cameras[0];
  const auto error = [&](const Scene& s) {
    return compare_hdr(renderer.render(s, {cam}, FrameOptions{.read_hdr = true}).at(0).hdr,
                       ref.hdr)
        .rel_l1;
  };
  out.paper_rel_l1 = error(paper);
  out.default_rel_l1 = error(deflt);
  std::vector<double> pg, dg, pb, db;
  for (int r = 0; r < rounds; ++r) {
    for (const FrameResult& fr : renderer.render(paper, std::vector<Camera>(per_round, cam))) {
      pg.push_back(fr.gpu_ms);
      pb.push_back(pass_ms(fr, "beams"));
    }
    for (const FrameResult& fr : renderer.render(deflt, std::vector<Camera>(per_round, cam))) {
      dg.push_back(fr.gpu_ms);
      db.push_back(pass_ms(fr, "beams"));
    }
  }
  out.paper_gpu_ms = median(pg);
  out.default_gpu_ms = median(dg);
  out.paper_beam_ms = median(pb);
  out.default_beam_ms = median(db);
  out.frames = static_cast<int>(pg.size());
  return out;
}

}  // namespace

const char* method_name(IntegrationMethod m) {
  switch (m) {
    case IntegrationMethod::kTable: return "table";
    case IntegrationMethod::kClosedForm: return "closed_form";
    case IntegrationMethod::kMarch: return "march";
  }
  return "?";
}

const char* layout_name(TableLayout l) {
  switch (l) {
    case TableLayout::kUniform: return "uniform";
    case TableLayout::kChord: return "chord";
    case TableLayout::kWarped: return "warped";
    case TableLayout::kChordWarped: return "chord_warped";
  }
  return "?";
}

const char* filter_name(TableFilter f) {
  return f == TableFilter::kHardware ? "hardware" : "shader";
}

const char* rule_name(MarchRule r) { return r == MarchRule::kMidpoint ? "midpoint" : "simpson"; }

std::string setting_label(const RenderSettings& s) {
  switch (s.method) {
    case IntegrationMethod::kTable:
      return std::string("table ") + layout_name(s.layout) + "/" + filter_name(s.filter) + " " +
             std::to_string(s.table_d);
    case IntegrationMethod::kMarch:
      return std::string("march ") + rule_name(s.rule) + " " + std::to_string(s.samples);
    case IntegrationMethod::kClosedForm:
      return "closed_form";
  }
  return "?";
}

std::vector<RenderSettings> settings_grid(const BenchScene& scene, bool quick,
                                          std::vector<std::string>* skipped) {
  std::vector<RenderSettings> grid;
  if (quick) {
    for (TableLayout layout : {TableLayout::kUniform, TableLayout::kChordWarped}) {
      for (TableFilter filter : {TableFilter::kHardware, TableFilter::kShader}) {
        for (int size : {8, 32, 128}) grid.push_back(table_setting(layout, filter, size));
      }
    }
  } else {
    std::vector<int> sizes = {8, 32, 128, 1024};
    if (!scene.coarse_tables) sizes = {8, 16, 32, 64, 128, 256, 512, 1024};
    if (scene.coarse_tables && skipped) {
      skipped->push_back(scene.name + ": table sizes 8, 32, 128, 1024 only");
    }
    for (TableLayout layout : kAllLayouts) {
      for (int size : sizes) grid.push_back(table_setting(layout, TableFilter::kHardware, size));
    }
    // The shader filter only on the paper's layout and on the default one.
    for (TableLayout layout : {TableLayout::kUniform, TableLayout::kChordWarped}) {
      for (int size : sizes) grid.push_back(table_setting(layout, TableFilter::kShader, size));
    }
  }
  if (scene.closed_form) {
    RenderSettings s;
    s.method = IntegrationMethod::kClosedForm;
    grid.push_back(s);
  }
  const std::vector<int> samples =
      quick ? std::vector<int>{4, 16, 64} : std::vector<int>{4, 8, 16, 32, 64, 128, 256, 512, 1024};
  const int cap = quick ? 0 : scene.max_march_samples;
  for (MarchRule rule : kRules) {
    for (int n : samples) {
      if (cap == 0 || n <= cap) grid.push_back(march_setting(rule, n));
    }
  }
  if (cap != 0 && cap < samples.back() && skipped) {
    skipped->push_back(scene.name + ": march with N > " + std::to_string(cap) +
                       " skipped (frame time on a software rasterizer)");
  }
  return grid;
}

int run_accuracy(const AccuracyOptions& opts) {
  namespace fs = std::filesystem;
  const auto start = std::chrono::steady_clock::now();
  const int size = opts.size > 0 ? opts.size : (opts.quick ? 128 : 512);
  const fs::path examples = find_data_dir("examples");
  std::vector<BenchScene> scenes =
      opts.quick ? quick_scene_set(examples, size) : full_scene_set(examples, size);
  if (!opts.scenes.empty()) {
    for (const std::string& want : opts.scenes) {
      if (std::none_of(scenes.begin(), scenes.end(),
                       [&](const BenchScene& s) { return s.name == want; })) {
        std::fprintf(stderr, "beamcast bench accuracy: no scene '%s' in the %s set\n",
                     want.c_str(), opts.quick ? "--quick" : "full");
        return 2;
      }
    }
    std::erase_if(scenes, [&](const BenchScene& s) {
      return std::find(opts.scenes.begin(), opts.scenes.end(), s.name) == opts.scenes.end();
    });
  }
  fs::create_directories(opts.out / "reference");

  RunInfo info;
  info.size = size;
  info.quick = opts.quick;
  info.machine = machine_string();
  std::vector<std::vector<RenderSettings>> grids;
  std::size_t total = 0;
  for (const BenchScene& bs : scenes) {
    grids.push_back(settings_grid(bs, opts.quick, &info.skipped));
    total += grids.back().size();
  }

  RendererOptions ropts;
  ropts.egl = opts.egl;
  Renderer renderer(ropts);
  info.renderer = renderer.description();
  std::fprintf(stderr, "bench accuracy: %s; %zu scenes, %zu settings, %dx%d\n",
               info.renderer.c_str(), scenes.size(), total, size, size);

  // The run's very first frame is slower than any later one (the rasterizer's
  // threads and the shader cache start cold); keep that out of the first row.
  if (!scenes.empty()) renderer.render(scenes[0].scene);

  std::vector<AccuracyRow> rows;
  int failures = 0;
  std::size_t done = 0;
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const BenchScene& bs = scenes[i];
    const auto ref0 = std::chrono::steady_clock::now();
    Reference ref;
    ref.hdr = render_reference(bs.scene, bs.scene.cameras[0]);
    ref.image = tone_map(ref.hdr, bs.scene.output);
    const double ref_s = seconds_since(ref0);
    // What the rows were measured on, for people reading the numbers.
    write_png(opts.out / "reference" / (bs.name + ".png"), ref.image);
    info.references.push_back({bs.name, static_cast<int>(bs.scene.beams.size()), ref_s});
    std::fprintf(stderr, "%s: CPU reference %.2f s (%zu beams)\n", bs.name.c_str(), ref_s,
                 bs.scene.beams.size());
    for (const RenderSettings& settings : grids[i]) {
      ++done;
      const std::string label = setting_label(settings);
      try {
        const AccuracyRow row = measure(renderer, bs, settings, ref, opts.quick);
        std::fprintf(stderr,
                     "[%4zu/%zu] %-16s %-30s gpu %8.3f ms  beams %8.3f ms  wall %8.2f ms  x%d  "
                     "rel_l1 %.3e  psnr %5.1f dB\n",
                     done, total, bs.name.c_str(), label.c_str(), row.gpu_ms, row.beam_gpu_ms,
                     row.wall_ms, row.repeats, row.rel_l1, row.psnr_db);
        rows.push_back(row);
      } catch (const std::exception& e) {
        // Keep going: the other rows are still worth having; the exit code says it failed.
        ++failures;
        std::fprintf(stderr, "[%4zu/%zu] %-16s %-30s FAILED: %s\n", done, total, bs.name.c_str(),
                     label.c_str(), e.what());
      }
    }
    if (bs.name.starts_with("paper_") || bs.density_study) {
      const auto& il = info.interleaved.emplace_back(
          interleave(renderer, bs, ref, opts.quick ? 2 : 6, opts.quick ? 2 : 4));
      std::fprintf(stderr, "%s: interleaved paper 32x32 %.3f ms vs default %.3f ms (%.3fx)\n",
                   bs.name.c_str(), il.paper_gpu_ms, il.default_gpu_ms,
                   il.default_gpu_ms / il.paper_gpu_ms);
    }
  }

  const fs::path csv = opts.out / "accuracy.csv";
  write_csv(csv, rows);
  info.total_s = seconds_since(start);
  write_summary(opts.out / "accuracy.md", rows, scenes, info);
  std::fprintf(stderr, "bench accuracy: %zu rows in %.1f s -> %s\n", rows.size(), info.total_s,
               csv.c_str());
  if (opts.plots) {
    const std::string why = run_plot_script(csv, opts.out);
    if (why.empty()) {
      std::fprintf(stderr, "bench accuracy: plots in %s\n", opts.out.c_str());
    } else {
      std::fprintf(stderr, "bench accuracy: no plots: %s (the CSV is complete)\n", why.c_str());
    }
  }
  if (failures) {
    std::fprintf(stderr, "bench accuracy: %d settings failed\n", failures);
    return 1;
  }
  return 0;
}

}  // namespace beamcast::bench
