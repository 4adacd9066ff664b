#include "bench/slim_bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

#include "protocol/occluders/slim.hpp"
#include "protocol/scene_json.hpp"
#include "protocol/slim_io.hpp"
#include "render/image.hpp"
#include "render/renderer.hpp"
#include "render/slim_compare.hpp"
#include "slim/mesh_io.hpp"
#include "slim/test_shapes.hpp"  // the generated shapes the tests use (header-only)

namespace beamcast::bench {

namespace {

struct Model {
  std::string name;
  std::vector<SlimSphere> spheres;
  std::filesystem::path mesh;  // optional: the mesh it was fitted to
};

struct Setting {
  std::string knob;  // what the row varies
  SlimSettings slim;
  double zoom = 1.0;
};

// A camera looking at the model's centre from a fixed direction; zoom 1
// frames the bounding sphere of the supports' centres, zoom z narrows the
// field of view z times (the camera does not move, so it stays outside).
Camera camera_for(const Aabb& box, double zoom, int size) {
  const Vec3 c = 0.5 * (box.lo + box.hi);
  const double radius = 0.5 * length(box.hi - box.lo);
  const double fov1 = 40.0;
  const double distance = radius / std::sin(0.5 * fov1 * std::numbers::pi / 180.0);
  Camera cam;
  const Vec3 dir = normalize(Vec3{0.45, 0.35, 1.0});
  cam.position = c + distance * dir;
  cam.target = c;
  cam.fov_y_deg = 2.0 * std::atan(std::tan(0.5 * fov1 * std::numbers::pi / 180.0) / zoom) * 180.0 /
                  std::numbers::pi;
  cam.near_plane = 1e-3 * distance;
  cam.far_plane = 10.0 * distance;
  cam.width = cam.height = size;
  return cam;
}

// The coverage of the points against the reference: grey where both
// cover, the GPU's shading by its normal; red: a hole; blue: spurious.
Image coverage_image(const SlimPixels& gpu, const SlimPixels& ref) {
  Image img;
  img.width = ref.width;
  img.height = ref.height;
  img.rgb.assign(3 * static_cast<std::size_t>(ref.width) * ref.height, 0);
  for (std::size_t i = 0; i < ref.covered.size(); ++i) {
    std::uint16_t* px = &img.rgb[3 * i];
    if (ref.covered[i] && !gpu.covered[i]) {
      px[0] = 255;
    } else if (gpu.covered[i] && !ref.covered[i]) {
      px[2] = 255;
    } else if (gpu.covered[i]) {
      const double shade = 60.0 + 160.0 * std::abs(gpu.normal[i][2]);
      for (int k = 0; k < 3; ++k) px[k] = static_cast<std::uint16_t>(shade);
    }
  }
  return img;
}

const char* evaluation_name(SlimEvaluation e) {
  return e == SlimEvaluation::kField ? "field" : e == SlimEvaluation::kPatch ? "patch" : "blend";
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

}  // namespace

int run_slim_bench(const SlimBenchOptions& opts) {
  const int size = opts.size > 0 ? opts.size : (opts.quick ? 128 : 512);
  std::filesystem::create_directories(opts.out);
  std::vector<Model> models = {
      // Supports 1.2 lattice spacings wide: each surface point in about 4.5
      // of them, as fitted models (the tests use 2, 12x overlap).
      {"sphere_400", test::slim_sphere({0, 0, 0}, 1.0, 400, 1.2), {}},
      {"torus_768", test::slim_torus({0, 0, 0}, 2.0, 0.6, 48, 16, 1.0), {}},
  };
  if (opts.no_generated) models.clear();
  for (const auto& path : opts.models) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    models.push_back({path.stem().string(),
                      parse_slim_file_bytes(bytes.str(), path.string(), "/", {10000000, 10000000}, 1e12), {}});
  }
  for (std::size_t i = 0; i < opts.meshes.size() && i < opts.models.size(); ++i) {
    models[models.size() - opts.models.size() + i].mesh = opts.meshes[i];
  }
  std::vector<Setting> settings;
  auto with = [](double s, double t, bool fill, SlimEvaluation e = SlimEvaluation::kField) {
    SlimSettings x;
    x.sampling = s;
    x.depth_threshold = t;
    x.fill_holes = fill;
    x.evaluation = e;
    return x;
  };
  const std::vector<double> zooms = !opts.zooms.empty() ? opts.zooms
                                    : opts.quick        ? std::vector<double>{0.25, 1.0, 4.0}
                                                        : std::vector<double>{0.25, 1.0, 4.0, 16.0};
  for (double z : zooms) {
    settings.push_back({"zoom", with(2.0, 0.25, true), z});
    settings.push_back({"zoom, patch", with(2.0, 0.25, true, SlimEvaluation::kPatch), z});
    settings.push_back({"zoom, no 2nd stage", with(2.0, 0.25, false), z});
    settings.push_back({"zoom, seed's blend", with(2.0, 0.25, true, SlimEvaluation::kBlend), z});
    settings.push_back(
        {"zoom, seed's blend, no 2nd stage", with(2.0, 0.25, false, SlimEvaluation::kBlend), z});
  }
  for (double s : opts.zoom_only ? std::vector<double>{}
                  : opts.quick   ? std::vector<double>{1.0, 4.0}
                                 : std::vector<double>{1.0, 4.0, 8.0}) {
    settings.push_back({"S", with(s, 0.25, true), 1.0});
    settings.push_back({"S, no 2nd stage", with(s, 0.25, false), 1.0});
    settings.push_back({"S, seed's blend", with(s, 0.25, true, SlimEvaluation::kBlend), 1.0});
  }
  if (!opts.zoom_only) {
    for (double t : {0.05, 1.0}) settings.push_back({"t", with(2.0, t, true), 1.0});
  }

  RendererOptions ropts;
  ropts.egl = opts.egl;
  Renderer renderer(ropts);
  std::ofstream csv(opts.out / "slim.csv");
  csv << "model,spheres,knob,evaluation,sampling,depth_threshold,fill_holes,zoom,size,points,gpu_"
         "ms,slim_ms,"
         "reference_pixels,holes,interior_holes,spurious,spurious_far,other_layer,depth_mean,"
         "depth_p99,depth_max,normal_mean_deg,normal_p99_deg,normal_max_deg,interior,interior_"
         "depth_p99,"
         "interior_normal_p99_deg,crease_pixels,crease_normal_mean_deg\n";
  std::ofstream md(opts.out / "slim.md");
  md << "# SLIM point sampling against the CPU reference (" << size << "x" << size << ", "
     << renderer.description() << ")\n\n"
     << "Reference: " << opts.reference_samples << " x " << opts.reference_samples
     << " rays per pixel for depth and normal (coverage: the centre ray).\n\n"
     << "Points: sample slots the point passes process per frame (culled slots included). "
        "GPU ms: the whole frame, median of "
     << opts.repeats
     << "; slim ms: the three slim passes. Holes: pixels the reference covers and the points do "
        "not (interior: all 8 neighbours covered by the reference); spurious: the reverse (far: "
        "no covered neighbour). Depth: |GPU - reference| view depth at the model scaled to "
        "size 10 (its box diagonal). Normal: angle between the GPU's normal and F's "
        "gradient. Evaluation: field (F and its gradient at each pixel's centre ray) or blend "
        "(the seed's weighted mean of the points' depths and normals). Inner: the pixels whose 3x3 "
        "neighbourhood both cover (not the outline). Crease: inner "
        "pixels where the reference's normal turns by over 30 degrees to a neighbour.\n\n"
     << "| model | spheres | knob | evaluation | S | t | 2nd stage | zoom | points | GPU ms | slim "
        "ms | ref px | "
        "holes | interior | spurious | far | depth mean | depth p99 | normal mean ° | normal p99 ° "
        "| "
        "inner depth p99 | inner normal p99 ° | crease px | crease normal ° |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|-"
        "--|---|\n";
  for (const Model& model : models) {
    Scene base;
    base.occluders.push_back(
        Occluder{SlimOccluder::from_spheres(model.spheres), {0.8, 0.7, 0.6}, {}});
    const Aabb box = std::get<SlimOccluder>(base.occluders[0].shape).bounds();
    const double model_size = length(box.hi - box.lo);
    std::map<double, SlimPixels> references;
    for (const Setting& st : settings) {
      if (!opts.evaluations.empty() &&
          std::find(opts.evaluations.begin(), opts.evaluations.end(),
                    evaluation_name(st.slim.evaluation)) == opts.evaluations.end()) {
        continue;
      }
      Scene scene = base;
      scene.slim = st.slim;
      scene.cameras = {camera_for(box, st.zoom, size)};
      auto ref = references.find(st.zoom);
      if (ref == references.end()) {
        const auto t0 = std::chrono::steady_clock::now();
        ref = references
                  .emplace(st.zoom,
                           slim_reference(scene, scene.cameras[0], 0, opts.reference_samples))
                  .first;
        std::fprintf(stderr, "%s zoom %g: reference %.1f s\n", model.name.c_str(), st.zoom,
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
      FrameOptions fo;
      fo.batch = false;
      std::vector<double> gpu, slim_ms;
      std::map<std::string, std::vector<double>> pass_ms;
      FrameResult last;
      for (int r = 0; r < std::max(1, opts.repeats); ++r) {
        fo.read_targets.clear();
        if (r + 1 == std::max(1, opts.repeats)) fo.read_targets = {TargetId::kSlimSurface};
        auto frames = renderer.render(scene, fo);
        gpu.push_back(frames[0].gpu_ms);
        double s = 0.0;
        for (const PassTiming& p : frames[0].passes) {
          if (p.name.rfind("slim", 0) == 0) s += p.gpu_ms;
          pass_ms[p.name].push_back(p.gpu_ms);
        }
        slim_ms.push_back(s);
        last = std::move(frames[0]);
      }
      std::fprintf(stderr, "%s zoom %g %s: passes (median ms)", model.name.c_str(), st.zoom,
                   evaluation_name(st.slim.evaluation));
      for (auto& [name, ms] : pass_ms) std::fprintf(stderr, " %s %.1f", name.c_str(), median(ms));
      std::fputc('\n', stderr);
      const SlimPixels pts = slim_from_surface(last.targets[TargetId::kSlimSurface], size, size);
      const SlimErrors e = compare_slim(pts, ref->second, model_size);
      const char* eval_name = evaluation_name(st.slim.evaluation);
      if (opts.images && st.knob.rfind("zoom", 0) == 0) {
        char name[256];
        std::snprintf(name, sizeof name, "%s_zoom%g_%s_%s.png", model.name.c_str(), st.zoom,
                      st.slim.fill_holes ? "fill" : "nofill", eval_name);
        write_png(opts.out / name, coverage_image(pts, ref->second));
      }
      char line[1024];
      std::snprintf(line, sizeof line,
                    "%s,%zu,\"%s\",%s,%g,%g,%d,%g,%d,%lld,%.2f,%.2f,%lld,%lld,%lld,%lld,%lld,%lld,%"
                    ".5f,%.5f,%.4f,%.4f,"
                    "%.4f,%.4f,%lld,%.5f,%.4f,%lld,%.4f\n",
                    model.name.c_str(), model.spheres.size(), st.knob.c_str(), eval_name,
                    st.slim.sampling, st.slim.depth_threshold, st.slim.fill_holes ? 1 : 0, st.zoom,
                    size, static_cast<long long>(last.slim_points), median(gpu), median(slim_ms),
                    static_cast<long long>(e.reference_pixels), static_cast<long long>(e.holes),
                    static_cast<long long>(e.interior_holes), static_cast<long long>(e.spurious),
                    static_cast<long long>(e.spurious_far), static_cast<long long>(e.occluded),
                    e.depth_mean, e.depth_p99, e.depth_max, e.normal_mean_deg, e.normal_p99_deg,
                    e.normal_max_deg, static_cast<long long>(e.interior), e.interior_depth_p99,
                    e.interior_normal_p99_deg, static_cast<long long>(e.crease_pixels),
                    e.crease_normal_mean_deg);
      csv << line << std::flush;
      std::snprintf(line, sizeof line,
                    "| %s | %zu | %s | %s | %g | %g | %s | %g | %lld | %.1f | %.1f | %lld | %lld | "
                    "%lld | %lld | "
                    "%lld | %.4f | %.4f | %.3f | %.2f | %.4f | %.2f | %lld | %.1f |\n",
                    model.name.c_str(), model.spheres.size(), st.knob.c_str(), eval_name,
                    st.slim.sampling, st.slim.depth_threshold, st.slim.fill_holes ? "on" : "off",
                    st.zoom, static_cast<long long>(last.slim_points), median(gpu), median(slim_ms),
                    static_cast<long long>(e.reference_pixels), static_cast<long long>(e.holes),
                    static_cast<long long>(e.interior_holes), static_cast<long long>(e.spurious),
                    static_cast<long long>(e.spurious_far), e.depth_mean, e.depth_p99,
                    e.normal_mean_deg, e.normal_p99_deg, e.interior_depth_p99,
                    e.interior_normal_p99_deg, static_cast<long long>(e.crease_pixels),
                    e.crease_normal_mean_deg);
      md << line << std::flush;
      std::fputs(line, stdout);
      std::fflush(stdout);
    }
  }
  // The mesh each model was fitted to, rasterized at zoom 1 and 4 with the
  // default SLIM settings' frame beside it.
  std::ofstream mm(opts.out / "slim_mesh.md");
  mm << "# SLIM point sampling against its source mesh rasterized (" << size << "x" << size << ")\n\n"
     << "Both drawn by this renderer with the directional light (the mesh with flat triangle "
        "normals). GPU ms: median of "
     << opts.repeats << ". Image difference: 8-bit RMS and PSNR of the SLIM frame against the mesh's.\n\n"
     << "| model | spheres | triangles | zoom | SLIM GPU ms | mesh GPU ms | ratio | RMS | PSNR dB |\n"
     << "|---|---|---|---|---|---|---|---|---|\n";
  for (const Model& model : models) {
    if (model.mesh.empty()) continue;
    const slim::TriangleMesh mesh = slim::read_mesh(model.mesh);
    const std::filesystem::path obj_dir = opts.out / "meshes";
    std::filesystem::create_directories(obj_dir);
    const std::string obj = model.name + ".obj";
    {
      std::ofstream o(obj_dir / obj);
      for (const Vec3& v : mesh.vertices) o << "v " << v[0] << ' ' << v[1] << ' ' << v[2] << '\n';
      for (const auto& t : mesh.triangles) o << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
    }
    SceneLoadOptions load;
    load.assets_dir = obj_dir;
    nlohmann::json mj = {{"occluders", {{{"type", "mesh"}, {"file", obj}, {"albedo", {0.8, 0.7, 0.6}}}}},
                         {"cameras", {{{"position", {0, 0, 5}}}}}};
    Scene mesh_scene = parse_scene(mj, load);
    Scene slim_scene;
    slim_scene.occluders.push_back(
        Occluder{SlimOccluder::from_spheres(model.spheres), {0.8, 0.7, 0.6}, {}});
    const Aabb box = std::get<SlimOccluder>(slim_scene.occluders[0].shape).bounds();
    for (double zoom : {1.0, 4.0}) {
      mesh_scene.cameras = slim_scene.cameras = {camera_for(box, zoom, size)};
      FrameOptions fo;
      fo.batch = false;
      std::vector<double> ts, tm;
      FrameResult fs_last, fm_last;
      for (int r = 0; r < std::max(1, opts.repeats); ++r) {
        auto a = renderer.render(slim_scene, fo);
        auto b = renderer.render(mesh_scene, fo);
        ts.push_back(a[0].gpu_ms);
        tm.push_back(b[0].gpu_ms);
        fs_last = std::move(a[0]);
        fm_last = std::move(b[0]);
      }
      const LevelError le = compare_levels(fs_last.image, fm_last.image);
      char name[256];
      std::snprintf(name, sizeof name, "%s_zoom%g", model.name.c_str(), zoom);
      write_png(opts.out / (std::string(name) + "_slim.png"), fs_last.image);
      write_png(opts.out / (std::string(name) + "_mesh.png"), fm_last.image);
      char line[512];
      std::snprintf(line, sizeof line, "| %s | %zu | %zu | %g | %.1f | %.1f | %.1f | %.2f | %.1f |\n",
                    model.name.c_str(), model.spheres.size(), mesh.triangles.size(), zoom, median(ts),
                    median(tm), median(ts) / std::max(median(tm), 1e-9), le.rms, le.psnr_db);
      mm << line << std::flush;
      std::fputs(line, stdout);
    }
  }
  std::printf("wrote %s and slim.md\n", (opts.out / "slim.csv").c_str());
  return 0;
}

}  // namespace beamcast::bench
