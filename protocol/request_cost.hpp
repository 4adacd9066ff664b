// The estimated work of one render (PROTOCOL.md, "Request cost"): a pure
// function of the parsed scene and the cameras the request renders, in one
// unit, "cost", meant as milliseconds of render time on the reference machine
// (2 cores, llvmpipe; weights measured by bench/request_cost.py, numbers in
// docs/performance.md, "Request cost"). The server refuses a render whose
// estimate passes max_request_cost before any work starts. Each term is an
// upper bound of one kind of work (a photon takes max_depth bounces, every
// pixel may be a mirror, every ray crosses a volume's whole diagonal): the
// estimate may overstate a render, never a kind of work it leaves out.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "protocol/scene.hpp"

namespace beamcast {

// One row of PROTOCOL.md's cost table: `units` of some work times `weight`
// (cost per unit) is `cost`. `path` is the scene-relative JSON pointer of the
// field that sets the term (e.g. "/gi/photons"; "/cameras" for per-pixel terms).
struct CostTerm {
  std::string_view name;
  double units = 0.0;
  double weight = 0.0;
  double cost = 0.0;
  std::string path;
};

struct RequestCost {
  double total = 0.0;
  std::vector<CostTerm> terms;  // the non-zero ones, in the table's order
  // The term with the largest cost (nullptr if there is none).
  const CostTerm* dominant() const;
  // "photon_paths 1.2e+06 + pixels 300 + ..." for messages, largest first.
  std::string breakdown() const;
};

// Cost per unit of each term (PROTOCOL.md's table lists the same numbers; a
// unit test compares them).
struct CostWeights {
  double fixed = 10.0;                 // per render: setup, read-back, encode
  double pixel = 1.0e-4;               // per rendered pixel (beams, surfaces, tonemap, PNG)
  double beam_pixel = 1.0e-6;          // per beam per rendered pixel (every beam covering the frame)
  double lit_pixel = 3.0e-4;           // per rendered pixel of a lit scene (G-buffer, splats, resolve)
  double direct_point_pixel = 1.0e-5;  // per rendered pixel per direct point (direct pass)
  double photon_bounce = 4.0e-5;       // per photon x gi.max_depth (CPU tracing among surfaces)
  double medium_photon_event = 2.8e-3; // per photon x gi.max_depth with a scattering medium
  double volume_photon_view = 3.0e-3;  // per possible volume photon per 512^2 view per medium part
  double specular_ray = 1.8e-3;        // per pixel x specular_samples^2 x the gather factor
  double volume_sample = 1.0e-5;       // per pixel per step through a volume's diagonal
  double slim_sphere_view = 3.0e-3;    // per SLIM sphere per camera ("patch" evaluation)
  double slim_sampled_sphere_view = 5.0e-2;  // ... per sphere per camera ("field", "blend")
  double triangle_view = 2.5e-4;       // per mesh triangle per camera
  double medium_pixel = 1.0e-4;        // per pixel per medium part (scene-wide, regions, triangles)
};
inline constexpr CostWeights kCostWeights{};

// `cameras`: those the request renders (the scene's, or the request's
// override); the scene's output.supersample applies to each.
RequestCost estimate_request_cost(const Scene& scene, const std::vector<Camera>& cameras,
                                  const CostWeights& w = kCostWeights);

}  // namespace beamcast
