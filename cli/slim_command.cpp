// `beamcast slim fit MESH --out FILE`: a SLIM surface fitted to an OFF, OBJ
// or PLY mesh (slim/fit.hpp); the report is one JSON object on stdout.
#include <chrono>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "cli/commands.hpp"
#include "protocol/slim_io.hpp"
#include "slim/fit.hpp"
#include "slim/mesh_io.hpp"

namespace beamcast::cli {

void add_slim_command(CLI::App& app) {
  CLI::App* slim_app = app.add_subcommand("slim", "SLIM implicit surfaces (support spheres)");
  slim_app->require_subcommand(1);

  struct FitArgs {
    std::string mesh, out;
    slim::FitOptions fit;
    std::int64_t samples = 200000;
  };
  auto args = std::make_shared<FitArgs>();
  CLI::App* fit = slim_app->add_subcommand(
      "fit",
      "Fit support spheres with local quadratics (min/max of two on creases) to a triangle mesh; "
      "writes the model (JSON if FILE ends in .json, else binary) and prints a JSON report: "
      "spheres, error_mean, error_rms, error_max (|F|/|grad F| at points on the mesh, model "
      "scaled to bounding box diagonal 10), uncovered, seconds");
  fit->add_option("mesh", args->mesh, "Mesh file: .off, .obj or .ply")->required();
  fit->add_option("--out,-o", args->out, "Output model file (.json or binary)")->required();
  fit->add_option("--error,-e", args->fit.error,
                  "Largest local fit error E, at the model scaled to diagonal 10 (default 0.01)")
      ->check(CLI::PositiveNumber);
  fit->add_option("--max-depth", args->fit.max_depth, "Octree levels below the root (default 10)")
      ->check(CLI::Range(0, 20));
  fit->add_option("--min-points", args->fit.min_points,
                  "Points a sphere grows to hold; no split below twice this (default 20)")
      ->check(CLI::Range(6, 100000));
  fit->add_option("--support", args->fit.support,
                  "Sphere radius over the cell's diagonal (default 0.75)")
      ->check(CLI::Range(0.5, 2.0));
  fit->add_option("--fit-points", args->fit.fit_points,
                  "Points sampled on the triangles for the fits (default max(4 x triangles, "
                  "400000))")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{20000000}));
  fit->add_option("--samples", args->samples,
                  "Points on the mesh the error is measured at (default 200000)")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{20000000}));
  fit->callback([args] {
    const auto t0 = std::chrono::steady_clock::now();
    const slim::TriangleMesh mesh = slim::read_mesh(args->mesh);
    const double read_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const slim::FitResult r = slim::fit_slim(mesh, args->fit);
    write_slim_file(args->out, r.spheres);
    const auto t1 = std::chrono::steady_clock::now();
    const slim::FitError e = slim::measure_fit_error(mesh, r.spheres, args->samples);
    const double measure_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
    const nlohmann::json report = {{"mesh", args->mesh},
                                   {"out", args->out},
                                   {"vertices", mesh.vertices.size()},
                                   {"triangles", mesh.triangles.size()},
                                   {"size", slim::model_size(mesh)},
                                   {"error_bound", args->fit.error},
                                   {"spheres", r.spheres.size()},
                                   {"creases", r.creases},
                                   {"forced", r.forced},
                                   {"depth", r.depth},
                                   {"fit_points", r.points},
                                   {"samples", e.samples},
                                   {"error_mean", e.mean},
                                   {"error_rms", e.rms},
                                   {"error_max", e.max},
                                   {"uncovered", e.uncovered},
                                   {"seconds", r.seconds},
                                   {"read_seconds", read_s},
                                   {"measure_seconds", measure_s}};
    std::printf("%s\n", report.dump().c_str());
  });
}

}  // namespace beamcast::cli
