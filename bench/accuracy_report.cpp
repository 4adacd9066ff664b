#include "bench/accuracy_report.hpp"

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <utility>

#include "protocol/data_dir.hpp"

namespace beamcast::bench {
namespace {

// The rel_l1 an accuracy "target" means in the summary: about where an 8-bit
// frame stops showing the error (0.1% of the energy).
constexpr double kTargetRelL1 = 1e-3;

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

// PSNR is +inf for identical frames; Python's float() reads "inf".
std::string psnr_text(double db) { return std::isfinite(db) ? fmt("%.3f", db) : "inf"; }

// Whether two rows measure the same setting (only the fields the method uses).
bool same_setting(const RenderSettings& a, const RenderSettings& b) {
  if (a.method != b.method) return false;
  switch (a.method) {
    case IntegrationMethod::kTable:
      return a.layout == b.layout && a.filter == b.filter && a.table_d == b.table_d &&
             a.table_s == b.table_s;
    case IntegrationMethod::kMarch:
      return a.rule == b.rule && a.samples == b.samples;
    case IntegrationMethod::kClosedForm:
      return true;
  }
  return false;
}

const AccuracyRow* find_row(const std::vector<AccuracyRow>& rows, const std::string& scene,
                            const RenderSettings& s) {
  for (const AccuracyRow& r : rows) {
    if (r.scene == scene && same_setting(r.settings, s)) return &r;
  }
  return nullptr;
}

// Lowest error of a method on a scene; ties go to the cheaper setting.
const AccuracyRow* most_accurate(const std::vector<AccuracyRow>& rows, const std::string& scene,
                                 IntegrationMethod m) {
  const AccuracyRow* best = nullptr;
  for (const AccuracyRow& r : rows) {
    if (r.scene != scene || r.settings.method != m) continue;
    if (!best || r.rel_l1 < best->rel_l1 ||
        (r.rel_l1 == best->rel_l1 && r.gpu_ms < best->gpu_ms)) {
      best = &r;
    }
  }
  return best;
}

// Cheapest (GPU time) setting of a method reaching the target error.
const AccuracyRow* cheapest_within(const std::vector<AccuracyRow>& rows, const std::string& scene,
                                   IntegrationMethod m, double rel_l1) {
  const AccuracyRow* best = nullptr;
  for (const AccuracyRow& r : rows) {
    if (r.scene != scene || r.settings.method != m || r.rel_l1 > rel_l1) continue;
    if (!best || r.gpu_ms < best->gpu_ms) best = &r;
  }
  return best;
}

RenderSettings uniform_table(int size) {
  RenderSettings s;
  s.method = IntegrationMethod::kTable;
  s.layout = TableLayout::kUniform;
  s.filter = TableFilter::kHardware;
  s.table_d = s.table_s = size;
  return s;
}

std::string fps_cell(const AccuracyRow* r) {
  return r && r->gpu_ms > 0.0 ? fmt("%.0f", 1000.0 / r->gpu_ms) + " (" + fmt("%.3f", r->gpu_ms) +
                                    " ms)"
                              : "n/a";
}

}  // namespace

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string python_interpreter() {
  const char* env = std::getenv("BEAMCAST_PYTHON");
  return env != nullptr && *env != '\0' ? std::string(env) : std::string("/usr/bin/python3");
}

const char* csv_header() {
  return "scene,method,layout,filter,table_size,samples,rule,gpu_ms,beam_gpu_ms,wall_ms,repeats,"
         "max_abs,rms,rel_l1,psnr_db,nonfinite";
}

void write_csv(const std::filesystem::path& file, const std::vector<AccuracyRow>& rows) {
  std::ofstream out(file);
  if (!out) throw std::runtime_error("cannot write " + file.string());
  out << csv_header() << '\n';
  for (const AccuracyRow& r : rows) {
    const RenderSettings& s = r.settings;
    const bool table = s.method == IntegrationMethod::kTable;
    const bool march = s.method == IntegrationMethod::kMarch;
    // Fields a method does not use are empty, not a default that was never applied.
    out << r.scene << ',' << method_name(s.method) << ',' << (table ? layout_name(s.layout) : "")
        << ',' << (table ? filter_name(s.filter) : "") << ','
        << (table ? std::to_string(s.table_d) : "") << ','
        << (march ? std::to_string(s.samples) : "") << ',' << (march ? rule_name(s.rule) : "")
        << ',' << fmt("%.4f", r.gpu_ms) << ',' << fmt("%.4f", r.beam_gpu_ms) << ','
        << fmt("%.3f", r.wall_ms) << ',' << r.repeats << ',' << fmt("%.6e", r.max_abs) << ','
        << fmt("%.6e", r.rms) << ',' << fmt("%.6e", r.rel_l1) << ',' << psnr_text(r.psnr_db) << ','
        << r.nonfinite << '\n';
  }
  if (!out) throw std::runtime_error("error writing " + file.string());
}

void write_summary(const std::filesystem::path& file, const std::vector<AccuracyRow>& rows,
                   const std::vector<BenchScene>& scenes, const RunInfo& info) {
  std::ofstream md(file);
  if (!md) throw std::runtime_error("cannot write " + file.string());
  md << "# Accuracy against time (`beamcast bench accuracy" << (info.quick ? " --quick" : "")
     << "`)\n\n"
     << "- Renderer: " << info.renderer << "\n"
     << "- Machine: " << info.machine << "\n"
     << "- Frames: " << info.size << "x" << info.size << ", " << rows.size() << " settings, "
     << fmt("%.1f", info.total_s) << " s in all\n"
     << "- Times: medians of GL timestamp queries (GPU) and of the render call (wall) over the "
        "repeats after one warm-up frame.\n"
     << "- Errors: the warm-up frame's linear HDR buffer against the double-precision CPU "
        "reference (rel_l1 = sum |a - r| / sum |r|); PSNR on the 8-bit tone-mapped frames.\n\n";
  if (!info.skipped.empty()) {
    md << "Skipped on purpose:\n\n";
    for (const std::string& s : info.skipped) md << "- " << s << "\n";
    md << "\n";
  }

  md << "## CPU reference time\n\n| scene | beams | seconds |\n|---|---|---|\n";
  for (const RunInfo::Reference& r : info.references) {
    md << "| " << r.scene << " | " << r.beams << " | " << fmt("%.2f", r.seconds) << " |\n";
  }

  // The paper's table: 512x512, 32x32 table, on a GeForce 9800 GTX (DirectX 9).
  const RenderSettings defaults{};
  md << "\n## The paper's FPS table (" << info.size << "x" << info.size
     << "; FPS = 1000 / GPU ms per frame)\n\n"
     << "| scene | paper, 9800 GTX, 32x32 | table uniform/hardware 32 | default ("
     << setting_label(defaults) << ") |\n|---|---|---|---|\n";
  const std::pair<const char*, const char*> paper[] = {
      {"paper_1set", "3200"}, {"paper_5sets", "880"}, {"paper_10sets", "460"}};
  for (const auto& [scene, fps] : paper) {
    // A plain copy: clang 14 cannot capture a structured binding in a lambda.
    const char* name = scene;
    if (std::none_of(scenes.begin(), scenes.end(),
                     [&](const BenchScene& s) { return s.name == name; })) {
      continue;
    }
    md << "| " << scene << " | " << fps << " | "
       << fps_cell(find_row(rows, scene, uniform_table(32))) << " | "
       << fps_cell(find_row(rows, scene, defaults)) << " |\n";
  }

  md << "\n## The paper's 32x32 uniform table against the default, interleaved\n\n"
     << "Both settings rendered alternately in rounds on the same renderer, so they see the "
        "same machine load; medians over all frames of each side.\n\n"
     << "| scene | frames each | paper 32x32: GPU ms (FPS) | beams ms | rel_l1 | default: GPU ms (FPS) "
        "| beams ms | rel_l1 | default / paper time |\n|---|---|---|---|---|---|---|---|---|\n";
  for (const RunInfo::Interleaved& il : info.interleaved) {
    md << "| " << il.scene << " | " << il.frames << " | " << fmt("%.2f", il.paper_gpu_ms) << " ("
       << fmt("%.0f", 1000.0 / il.paper_gpu_ms) << ") | " << fmt("%.2f", il.paper_beam_ms) << " | "
       << fmt("%.2e", il.paper_rel_l1) << " | " << fmt("%.2f", il.default_gpu_ms) << " ("
       << fmt("%.0f", 1000.0 / il.default_gpu_ms) << ") | " << fmt("%.2f", il.default_beam_ms)
       << " | " << fmt("%.2e", il.default_rel_l1) << " | "
       << fmt("%.3f", il.default_gpu_ms / il.paper_gpu_ms) << " |\n";
  }

  md << "\n## Best setting per method\n\n"
     << "Most accurate setting of each method, and the cheapest one whose rel_l1 is at most "
     << fmt("%.0e", kTargetRelL1) << ".\n";
  for (const BenchScene& bs : scenes) {
    md << "\n### " << bs.name << " (" << bs.scene.beams.size() << " beams)\n\n"
       << "| method | most accurate | GPU ms | rel_l1 | PSNR dB | cheapest with rel_l1 <= "
       << fmt("%.0e", kTargetRelL1) << " | GPU ms | rel_l1 |\n|---|---|---|---|---|---|---|---|\n";
    for (IntegrationMethod m :
         {IntegrationMethod::kTable, IntegrationMethod::kClosedForm, IntegrationMethod::kMarch}) {
      const AccuracyRow* best = most_accurate(rows, bs.name, m);
      if (!best) continue;
      md << "| " << method_name(m) << " | " << setting_label(best->settings) << " | "
         << fmt("%.3f", best->gpu_ms) << " | " << fmt("%.2e", best->rel_l1) << " | "
         << psnr_text(best->psnr_db) << " | ";
      if (const AccuracyRow* c = cheapest_within(rows, bs.name, m, kTargetRelL1)) {
        md << setting_label(c->settings) << " | " << fmt("%.3f", c->gpu_ms) << " | "
           << fmt("%.2e", c->rel_l1) << " |\n";
      } else {
        md << "none | | |\n";
      }
    }
  }

  md << "\n## Cheapest table setting reaching rel_l1 <= " << fmt("%.0e", kTargetRelL1)
     << ", per density\n\n"
     << "| scene | setting | GPU ms | rel_l1 | uniform 32 GPU ms | uniform 32 rel_l1 | time "
        "ratio |\n|---|---|---|---|---|---|---|\n";
  for (const BenchScene& bs : scenes) {
    if (!bs.density_study) continue;
    const AccuracyRow* c = cheapest_within(rows, bs.name, IntegrationMethod::kTable, kTargetRelL1);
    const AccuracyRow* u = find_row(rows, bs.name, uniform_table(32));
    md << "| " << bs.name << " | " << (c ? setting_label(c->settings) : "none in the grid") << " | "
       << (c ? fmt("%.3f", c->gpu_ms) : "") << " | " << (c ? fmt("%.2e", c->rel_l1) : "") << " | "
       << (u ? fmt("%.3f", u->gpu_ms) : "n/a") << " | " << (u ? fmt("%.2e", u->rel_l1) : "n/a")
       << " | " << (c && u && u->gpu_ms > 0.0 ? fmt("%.2f", c->gpu_ms / u->gpu_ms) : "") << " |\n";
  }
  md << "\nPlots: accuracy.png (rel_l1 against GPU time), accuracy_tables.png (rel_l1 against "
        "table size per layout).\n";
  if (!md) throw std::runtime_error("error writing " + file.string());
}

std::string run_plot_script(const std::filesystem::path& csv,
                            const std::filesystem::path& out_dir) {
  const std::filesystem::path python = python_interpreter();
  const std::filesystem::path script =
      find_data_dir("bench") / "plot_accuracy.py";
  if (!std::filesystem::exists(python)) return "no " + python.string();
  if (!std::filesystem::exists(script)) return "no " + script.string();
  const std::string cmd = shell_quote(python) + " " + shell_quote(script) + " " +
                          shell_quote(csv.string()) + " " + shell_quote(out_dir.string());
  const int status = std::system(cmd.c_str());
  if (status == -1) return "could not start " + python.string();
  if (!WIFEXITED(status)) return "plot_accuracy.py was killed";
  const int rc = WEXITSTATUS(status);
  // The script exits 3 (after saying so) when matplotlib is not installed.
  if (rc == 3) return "matplotlib is not installed for " + python.string();
  if (rc != 0) return "plot_accuracy.py exited " + std::to_string(rc);
  return "";
}

}  // namespace beamcast::bench
