// Fitting a SLIM surface (protocol/slim_model.hpp) to a triangle mesh
// (issue 16, item 2), in the spirit of multi-level partition of unity: an
// octree over the mesh's bounding cube; each cell owns a support sphere
// (its centre, radius `support` x the cell's diagonal) holding a weighted
// least-squares quadratic height field over the mesh points inside it, in a
// frame whose w axis is the points' mean normal, or on a crease (normals in
// two groups) the min or max of two. A cell is split while its fit misses
// some point inside its sphere by more than E. docs/slim.md, "Fitting meshes".
//
// Sizes: E and every reported error are in units of the model scaled so that
// its bounding box diagonal is 10; the spheres are in the mesh's coordinates.
#pragma once

#include <cstdint>
#include <vector>

#include "protocol/slim_model.hpp"
#include "slim/mesh_io.hpp"

namespace beamcast::slim {

// The model size that errors are measured against: 10 units = this length.
double model_size(const TriangleMesh& mesh);  // the bounding box diagonal

struct FitOptions {
  double error = 0.01;           // E, at the model scaled to size 10
  int max_depth = 10;            // octree levels below the root cell
  int min_points = 20;           // a sphere grows (within its parent's) to hold this many points;
                                 // a cell whose sphere holds under twice this is not split
  double support = 0.75;         // sphere radius / cell diagonal, in [0.5, 2]
  double max_normal_deg = 60.0;  // a wider spread of normals: no single fit
  double crease_deg = 30.0;      // two normal groups this far apart: try a crease
  std::int64_t fit_points = 0;   // triangle samples (0: max(4 x triangles, 400 000))
};

struct FitResult {
  std::vector<SlimSphere> spheres;  // in the mesh's coordinates
  std::int64_t creases = 0;         // spheres with crease != kNone
  std::int64_t forced = 0;          // fits kept past max_depth / min_points with error > E
  std::int64_t points = 0;          // fitted points (vertices + triangle samples)
  int depth = 0;                    // deepest level used
  double seconds = 0.0;
};

// Throws std::invalid_argument on options out of range or a mesh without area.
FitResult fit_slim(const TriangleMesh& mesh, const FitOptions& options);

// The fit's error at `samples` points drawn uniformly by area on the mesh
// (fixed seed): the distance estimate |F| / |grad F| with F from SlimField,
// in units of the model scaled to size 10. Points no support reaches count
// as uncovered and are left out of mean, rms and max.
struct FitError {
  std::int64_t samples = 0;
  std::int64_t uncovered = 0;
  double mean = 0.0, rms = 0.0, max = 0.0;
};
FitError measure_fit_error(const TriangleMesh& mesh, const std::vector<SlimSphere>& spheres,
                           std::int64_t samples = 200000, std::uint32_t seed = 1);
// The same at given points (mesh coordinates), e.g. near a crease.
FitError measure_fit_error_at(const std::vector<Vec3>& points, double model_size,
                              const std::vector<SlimSphere>& spheres);

}  // namespace beamcast::slim
