#include "bench/volume_bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <optional>

#include "protocol/scene_json.hpp"
#include "render/accuracy_controller.hpp"
#include "render/image.hpp"
#include "render/reference.hpp"
#include "render/renderer.hpp"

namespace beamcast::bench {

namespace {

struct Case {
  std::string name;
  Volume volume;
  std::string about;
};

struct Row {
  std::string knob;   // the table the row belongs to
  std::string value;  // the knob's value, as printed
  VolumeSettings settings;
  double scale = 1.0;  // S_xy: render scale
};

// A camera looking at the volume's centre from an oblique direction, the
// box's bounding sphere filling the frame's height.
Camera camera_for(const Volume& v, int size) {
  Vec3 lo, hi;
  v.world_bounds(&lo, &hi);
  const Vec3 c = 0.5 * (lo + hi);
  const double radius = 0.5 * length(hi - lo);
  const double fov = 40.0;
  const double distance = radius / std::sin(0.5 * fov * std::numbers::pi / 180.0);
  Camera cam;
  cam.position = c + distance * normalize(Vec3{0.55, 0.4, 1.0});
  cam.target = c;
  cam.fov_y_deg = fov;
  cam.near_plane = 1e-3 * distance;
  cam.far_plane = 10.0 * distance;
  cam.width = cam.height = size;
  return cam;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

// Relative L1 of two display images (sum |a - r| / sum r over channels) and
// the mean of `a` in [0, 1].
struct DisplayError {
  double rel_l1 = 0.0;
  double mean = 0.0;
};
DisplayError display_error(const Image& a, const Image& r) {
  const double top = a.bit_depth == 16 ? 65535.0 : 255.0;
  double diff = 0.0, sum = 0.0, mean = 0.0;
  for (std::size_t i = 0; i < a.rgb.size() && i < r.rgb.size(); ++i) {
    diff += std::abs(static_cast<double>(a.rgb[i]) - r.rgb[i]);
    sum += r.rgb[i];
    mean += a.rgb[i];
  }
  return {sum > 0.0 ? diff / sum : 0.0,
          mean / top / static_cast<double>(std::max<std::size_t>(1, a.rgb.size()))};
}

std::vector<Row> table_rows(bool quick) {
  std::vector<Row> rows;
  // Table 2 (S_z): samples per voxel spacing; the seed's 512 samples a ray
  // through its 256^3 bonsai are about 2 a voxel.
  for (double spv :
       quick ? std::vector<double>{0.5, 1, 2, 4} : std::vector<double>{0.25, 0.5, 1, 2, 4, 8}) {
    Row r{"S_z", "", {}, 1.0};
    r.settings.samples_per_voxel = spv;
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g/voxel", spv);
    r.value = buf;
    rows.push_back(r);
  }
  // The seed's own coarse steps: no opacity correction.
  for (double spv : {0.5, 1.0}) {
    Row r{"S_z uncorrected", "", {}, 1.0};
    r.settings.samples_per_voxel = spv;
    r.settings.opacity_correction = false;
    char buf[48];
    std::snprintf(buf, sizeof buf, "%g/voxel no correction", spv);
    r.value = buf;
    rows.push_back(r);
  }
  // Integration: pre-integrated steps (render/volume_pass.hpp) at the S_z
  // rows' steps.
  for (double spv : quick ? std::vector<double>{1, 2} : std::vector<double>{0.25, 0.5, 1, 2, 4}) {
    Row r{"integration", "", {}, 1.0};
    r.settings.samples_per_voxel = spv;
    r.settings.integration = VolumeIntegration::kPreintegrated;
    char buf[48];
    std::snprintf(buf, sizeof buf, "%g/voxel pre-integrated", spv);
    r.value = buf;
    rows.push_back(r);
  }
  // Table 3 (S_xy): rendered smaller, upscaled bilinearly.
  for (double scale : {1.0, 0.75, 0.5, 0.25}) {
    Row r{"S_xy", "", {}, scale};
    char buf[32];
    std::snprintf(buf, sizeof buf, "scale %g", scale);
    r.value = buf;
    rows.push_back(r);
  }
  // Table 4 (R_v): pyramid levels, by each of the seed's three rules.
  for (int level : {1, 2}) {
    for (auto [how, name] :
         {std::pair{VolumePyramid::kAverage, "average"}, std::pair{VolumePyramid::kMax, "max"},
          std::pair{VolumePyramid::kNonZero, "nonzero"}}) {
      Row r{"R_v", "", {}, 1.0};
      r.settings.level = level;
      r.settings.pyramid = how;
      r.value = "level " + std::to_string(level) + " " + name;
      rows.push_back(r);
    }
  }
  return rows;
}

// The preview's ladder for volume scenes (render/accuracy_controller.hpp),
// level by level: what a dragging user sees at each step.
std::vector<Row> ladder_rows(const VolumeSettings& full) {
  std::vector<Row> rows;
  for (const AccuracyLevel& level : make_volume_ladder(RenderSettings{}, full)) {
    rows.push_back({"preview ladder", level.label, level.volume.value_or(full), level.scale});
  }
  return rows;
}

std::vector<Row> ert_skip_rows() {
  std::vector<Row> rows;
  for (bool skip : {false, true}) {
    for (double ert : {1.0, 0.99, 0.95}) {
      Row r{"ERT / skipping", "", {}, 1.0};
      r.settings.skip_empty = skip;
      r.settings.ert_threshold = ert;
      char buf[64];
      std::snprintf(buf, sizeof buf, "ert %g skipping %s", ert, skip ? "on" : "off");
      r.value = buf;
      rows.push_back(r);
    }
  }
  return rows;
}

}  // namespace

void run_volume_bench(const VolumeBenchOptions& opts) {
  namespace fs = std::filesystem;
  fs::create_directories(opts.out);
  const int size = opts.size > 0 ? opts.size : (opts.quick ? 96 : 512);
  const int main_n = opts.quick ? 41 : 256;
  const int dense_n = opts.quick ? 32 : 256;

  std::vector<Case> tables;
  tables.push_back({"ml" + std::to_string(main_n),
                    procedural_volume(VolumeSourceType::kMarschnerLobb, main_n, "ml"),
                    "Marschner-Lobb sampled at " + std::to_string(main_n) + "^3, preset ml"});
  std::vector<Case> ert_cases;
  ert_cases.push_back({"heat" + std::to_string(dense_n),
                       procedural_volume(VolumeSourceType::kHeat, dense_n, "grey"),
                       "dense: the heat field at " + std::to_string(dense_n) + "^3, preset grey"});
  if (!opts.skull.empty()) {
    SceneLoadOptions load;
    load.assets_dir = opts.skull.parent_path();
    const nlohmann::json j = {
        {"volumes",
         {{{"source", {{"type", "inr"}, {"file", opts.skull.filename().string()}}},
           {"transfer", {{"preset", "bone"}}}}}},
        {"cameras", {{{"position", {0, 0, 1}}}}}};
    ert_cases.push_back({"skull", parse_scene(j, load).volumes.at(0),
                         "sparse: skull_2.9.inr (64^3 float), preset bone"});
  } else {
    Volume sparse = procedural_volume(VolumeSourceType::kMarschnerLobb, main_n, "ml");
    sparse.transfer.points = {
        {0.0, {0, 0, 0}, 0.0}, {0.55, {0.9, 0.6, 0.2}, 0.0}, {1.0, {1, 0.9, 0.6}, 0.8}};
    ert_cases.push_back({"ml_sparse", sparse, "sparse: Marschner-Lobb, nothing below 0.55"});
  }

  RendererOptions ropts;
  ropts.egl = opts.egl;
  Renderer renderer(ropts);
  std::ofstream csv(opts.out / "volumes.csv");
  csv << "volume,knob,value,samples_per_voxel,opacity_correction,ert,skip_empty,level,pyramid,"
         "integration,scale,size,gpu_ms,volume_pass_ms,wall_ms,rel_l1,mean\n";
  std::ofstream md(opts.out / "volumes.md");
  md << "# Volume ray casting: time against error (" << size << "x" << size << ", "
     << renderer.description() << ")\n\n"
     << "Error: relative L1 of the 8-bit frame against the CPU reference's (double, "
     << opts.reference_spv
     << " samples a voxel, each step's middle, full resolution). GPU ms: the whole frame, median "
        "of "
     << opts.repeats
     << "; volumes ms: the volume pass alone. Defaults: 2 samples a voxel, "
        "opacity correction, point samples, jitter, ERT 0.99, skipping on, level 0, scale 1.\n";

  auto run_case = [&](const Case& c, const std::vector<Row>& rows) {
    Scene base;
    base.background = {0.0, 0.0, 0.0};
    base.volumes = {c.volume};
    base.cameras = {camera_for(c.volume, size)};
    ReferenceOptions ro;
    ro.volume_step = std::min({c.volume.spacing[0], c.volume.spacing[1], c.volume.spacing[2]}) /
                     opts.reference_spv;
    const auto r0 = std::chrono::steady_clock::now();
    const Image ref = tone_map(render_reference(base, base.cameras[0], ro), base.output);
    const double ref_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
    std::fprintf(stderr, "%s: reference %.1f s\n", c.name.c_str(), ref_s);
    if (opts.images) write_png(opts.out / (c.name + "_reference.png"), ref);
    md << "\n## " << c.name << ": " << c.about << "\n\nReference: " << ref_s << " s.\n";
    std::string table;
    double previous_mean = 0.0;  // the row above's, in the same table
    for (const Row& row : rows) {
      if (row.knob != table) {
        table = row.knob;
        previous_mean = 0.0;
        md << "\n### " << table
           << "\n\n| setting | GPU ms | volumes ms | rel. L1 | mean | mean vs row above |\n"
           << "|---|---|---|---|---|---|\n";
      }
      Scene scene = base;
      scene.volume = row.settings;
      FrameOptions fo;
      fo.batch = false;
      fo.resolution_scale = row.scale;
      std::vector<double> gpu, pass, wall;
      std::optional<FrameResult> last;
      // One frame first: uploads and program builds are not the frame's.
      renderer.render(scene, fo);
      for (int i = 0; i < opts.repeats; ++i) {
        auto frames = renderer.render(scene, fo);
        FrameResult& fr = frames.at(0);
        gpu.push_back(fr.gpu_ms);
        for (const PassTiming& p : fr.passes) {
          if (p.name == "volumes") pass.push_back(p.gpu_ms);
        }
        wall.push_back(fr.wall_ms);
        last = std::move(fr);
      }
      const DisplayError e = display_error(last->image, ref);
      if (opts.images) {
        std::string file = c.name + "_" + row.knob + "_" + row.value + ".png";
        std::replace_if(
            file.begin(), file.end(), [](char ch) { return ch == ' ' || ch == '/' || ch == ','; },
            '_');
        write_png(opts.out / file, last->image);
      }
      const VolumeSettings& s = row.settings;
      const char* pyramid = s.pyramid == VolumePyramid::kMax       ? "max"
                            : s.pyramid == VolumePyramid::kNonZero ? "nonzero"
                                                                   : "average";
      char line[512];
      std::snprintf(
          line, sizeof line, "%s,%s,%s,%g,%d,%g,%d,%d,%s,%s,%g,%d,%.3f,%.3f,%.3f,%.6f,%.6f\n",
          c.name.c_str(), row.knob.c_str(), row.value.c_str(), s.samples_per_voxel,
          s.opacity_correction ? 1 : 0, s.ert_threshold, s.skip_empty ? 1 : 0, s.level, pyramid,
          s.integration == VolumeIntegration::kPreintegrated ? "preintegrated" : "point", row.scale,
          size, median(gpu), median(pass), median(wall), e.rel_l1, e.mean);
      csv << line << std::flush;
      char change[32] = "";
      if (previous_mean > 0.0) {
        std::snprintf(change, sizeof change, "%+.2f%%", 100.0 * (e.mean / previous_mean - 1.0));
      }
      previous_mean = e.mean;
      std::snprintf(line, sizeof line, "| %s | %.1f | %.1f | %.4f | %.4f | %s |\n",
                    row.value.c_str(), median(gpu), median(pass), e.rel_l1, e.mean, change);
      md << line << std::flush;
    }
  };
  for (const Case& c : tables) {
    std::vector<Row> rows = table_rows(opts.quick);
    const std::vector<Row> ladder = ladder_rows(VolumeSettings{});
    rows.insert(rows.end(), ladder.begin(), ladder.end());
    run_case(c, rows);
  }
  for (const Case& c : ert_cases) run_case(c, ert_skip_rows());
  std::printf("wrote %s and volumes.md\n", (opts.out / "volumes.csv").c_str());
}

}  // namespace beamcast::bench
