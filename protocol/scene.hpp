// Scene model: what a client describes. Pure data, no GL, no sockets.
// Every later scene element (lights, media, SLIM surfaces, volumes) is a new
// member here and a new pass in render/, never a change to the existing ones;
// a new occluder or beam kind is a module in protocol/occluders/ or
// protocol/beams/ (docs/architecture.md, "Adding a scene element").
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "protocol/beams/beams.hpp"
#include "protocol/density.hpp"
#include "protocol/lights/lights.hpp"
#include "protocol/medium.hpp"
#include "protocol/occluders/occluders.hpp"
#include "protocol/vec.hpp"
#include "protocol/volume.hpp"

namespace beamcast {

// A glowing body whose density depends on the normalized distance x = dist/radius
// to its center (sphere) or to its axis segment (capsule). One module per kind
// in protocol/beams/ (parsing, bounds, GPU form, CPU reference geometry).
struct Beam {
  BeamShape shape;
  double radius = 1.0;
  Color color{1.0, 1.0, 1.0};
  double intensity = 1.0;
  Density density;
  // Whether the beam also lights the scene (issue 14): the parser then adds
  // its light (a BeamEmitter, flux 4 pi x color x intensity x the volume
  // integral of f) to Scene::lights.
  bool emit = false;
};

// One module per kind in protocol/occluders/ (parsing, bounds, GPU form, CPU
// reference intersection); the kinds are listed once, in OccluderShape.
// How a surface scatters light (photon tracing and the path-traced
// reference; the raster path shades every kind with `albedo`).
enum class MaterialType {
  kDiffuse,  // Lambertian, reflectance Occluder::albedo
  kMirror,   // perfect specular reflection, scaled by `reflectance`
  kGlass,    // smooth dielectric: Fresnel reflection and refraction, `ior`, `tint`
};
struct Material {
  MaterialType type = MaterialType::kDiffuse;
  Color reflectance{1.0, 1.0, 1.0};  // mirror
  double ior = 1.5;                  // glass (the outside is vacuum, ior 1)
  Color tint{1.0, 1.0, 1.0};         // glass: transmittance per crossing
};

struct Occluder {
  OccluderShape shape;
  Color albedo{0.8, 0.8, 0.8};
  Material material;
};

// A light of the global-illumination path (photon mapping; "lights" in
// JSON). One module per kind in protocol/lights/; `flux` is the emitted
// power per channel, color x power (a quad may give its radiance instead).
struct Light {
  LightShape shape;
  Color flux{1.0, 1.0, 1.0};
};

// Photon mapping settings ("gi" in JSON), the accuracy knobs of issue 14.
enum class SplatKernel { kBox, kCone, kEpanechnikov };
// Who carries direct light (light -> diffuse surface): the raster pass
// "direct" (shadow-mapped point emitters, no splat noise) or the photons.
enum class DirectLightMethod { kShadowMaps, kPhotons };
enum class SpecularTracer { kAuto, kGpu, kCpu };
struct GiSettings {
  std::int64_t photons = 100000;          // emitted for the global map
  std::int64_t caustic_photons = 100000;  // emitted for the caustic map (with specular surfaces)
  double radius = 0.0;                    // splat / gather radius; 0: from the scene size
  // The caustic map's splat radius; 0: default_caustic_radius (gi/photon_map.hpp).
  double caustic_radius = 0.0;
  SplatKernel kernel = SplatKernel::kEpanechnikov;
  std::uint64_t seed = 1;
  int max_depth = 16;  // bounces a photon may take
  DirectLightMethod direct = DirectLightMethod::kShadowMaps;
  int direct_samples = 16;  // points per area light in the direct pass
  // 4: the points of each light with a multiple of 4 of them are shared out
  // over a 2 x 2 pixel pattern (each pixel a quarter of them, at 4 times
  // the weight) and a 3 x 3 surface-aware filter gives every pixel all four
  // quarters (pass direct, filtered in gi_resolve; interleaved sampling): the
  // direct pass's point loop costs a quarter. 1: every pixel every point.
  int direct_interleave = 4;
  int shadow_size = 256;    // texels per cube-map face of a direct point's shadow map
  // Divide each pixel's photon estimate by the share of its disk on its own
  // surface (the splats' edge bias at corners and edges; pass gi_resolve).
  bool edge_correction = true;
  // Give the pixels on a quad light's outline the share of the pixel that
  // sees it (pass gi_resolve; the first 8 quad lights): without it the
  // light's aliased edge is most of the Cornell box's error (docs/gi.md).
  bool light_antialias = true;
  // Mirror and glass pixels (pass "specular"): K x K rays spread over each
  // pixel, their radiance averaged (the reflections' and refractions' edges
  // and the light seen in them, as the reference's pixel average does).
  int specular_samples = 2;
  // Who follows those rays (gi.specular_tracer): the GPU (a compute pass
  // over the occluders, a BVH of their triangles and the photons in hashed
  // grids; render/specular_gpu.hpp) or the CPU (Embree and kd-trees,
  // gi/photon_gather.hpp, the reference the GPU's is tested against).
  // Scenes the GPU tracer does not cover (SLIM occluders, a medium and,
  // for now, direct light from shadow maps: gpu_traces_specular) are
  // traced on the CPU whatever this says. kAuto: the GPU on a hardware GL,
  // the CPU on a software rasterizer (llvmpipe, softpipe), where Embree was
  // measured about twice as fast as the compute pass.
  SpecularTracer specular_tracer = SpecularTracer::kAuto;
  // Photons are splatted at 1/splat_scale of the render size per side, then
  // brought back by a surface-aware upsampling (pass gi_resolve) of values
  // each corrected at its own splat pixel (the edge correction); on the
  // Cornell box 2 costs no error over 1 at 0.5x the frame time, and
  // with the default radius (four times the area of its disks before
  // 2026-11-26) 4 costs 0.05% of the image's error at 0.4x the time of 2
  // (docs/gi.md). 0 (the default): 8 from 512 render pixels a side up, else
  // 4 (render/passes.hpp, auto_splat_scale; at 512^2 8 costs 0.02% of the
  // image's error at 0.85x the GPU time of 4).
  int splat_scale = 0;
  // Photons merged before splatting (gi/photon_clusters.hpp): per cell of
  // side cluster x the radius, normal bin and plane, one disk at their
  // centroid carrying their power; 0: one disk per photon. The splats' fill
  // falls with the disks' count: on the Cornell box at 1e5 photons 0.35
  // draws 3 744 disks for 65 141 photons, the image's error within 0.01% of
  // unmerged photons' at 512^2 and 128^2 (docs/gi.md, "Photon clusters").
  double cluster = 0.35;
  // Level of detail (seed 001, section 6; gi.lod): photons in `lod_groups`
  // groups by storage order (index mod groups); at distance D from the
  // viewpoint the share Q = smoothstep(lod_near, lod_far, D) of the groups
  // is dropped (1 - smoothstep(lod_far, lod_near, D) when near > far, the
  // seed's convention: near photons dropped), one group fading at a time,
  // and the kept photons' power is scaled by 1 / (1 - Q), so the expected
  // flux is unchanged. 0 groups: off. Surface and volume photons alike.
  int lod_groups = 0;
  double lod_near = 0.0;
  double lod_far = 0.0;
  // Not in JSON: the share of each cached map the photon pass draws (the
  // first photons in storage order, i.e. whole paths of the first chunks,
  // their power scaled by 1 / share, the default radii taken at the drawn
  // count). Set by the preview's accuracy controller for moving frames
  // (render/accuracy_controller.hpp): the maps stay cached, nothing is
  // traced again.
  double display_fraction = 1.0;
  // Not in JSON: the most photon events (surface hits and medium
  // scatterings, 52 bytes each) tracing may store for this scene, all maps
  // together; past it tracing stops with PhotonEventLimit. Set from
  // SceneLimits::max_photon_events when the scene is parsed.
  std::int64_t max_photon_events = std::int64_t{1} << 26;
};

// SLIM point sampling ("slim" in JSON; issue 16): the accuracy knobs of the
// GPU pass (docs/slim.md measures each against time).
// How a pixel's surface is computed from the SLIM points that reach it.
enum class SlimEvaluation : std::uint8_t {
  // F and its gradient evaluated at the pixel's centre ray, over the
  // spheres whose points reach the pixel: view depth by a Newton step of F
  // along the ray, normal from F's gradient (the reference's surface).
  kField,
  // The seed's: the points' weighted mean depth and normal (each point's own
  // height-field normal).
  kBlend,
  // F evaluated as kField, without sampling: each sphere is drawn as one
  // quad over its projection and each of its fragments solves where the
  // centre ray meets the sphere's height field (a quadratic in closed
  // form). S and the second stage do not apply.
  kPatch,
};

struct SlimSettings {
  // S: the (u, v) grid step is n = S r / N, N the sphere's projected width
  // (diameter) in pixels, so S = 2 puts samples about one pixel apart.
  double sampling = 2.0;
  // t: a point joins a pixel's blend if it lies within t x (its sphere's
  // radius) behind the nearest point there (the seed's t = r is 1).
  double depth_threshold = 0.25;
  // The seed's second stage: more samples where neighbours project more
  // than a pixel apart.
  bool fill_holes = true;
  // Skip spheres whose every normal faces away from the camera (their
  // points lie behind the front of a closed surface); false for open
  // sheets meant to be seen from both sides.
  bool cull_backfaces = true;
  // "patch" by default: the field's surface (the same errors, measured in
  // docs/slim.md) at a tenth of the points' time on llvmpipe.
  SlimEvaluation evaluation = SlimEvaluation::kPatch;
};

// One directional light for Lambert shading of occluders.
struct DirectionalLight {
  Vec3 direction{-0.4, -1.0, -0.3};  // direction the light travels (need not be unit)
  Color color{1.0, 1.0, 1.0};
  double intensity = 1.0;
  double ambient = 0.15;
};

enum class Projection { kPerspective, kOrthographic };

struct Camera {
  std::string name;  // optional; frames are named after it
  Vec3 position{0.0, 0.0, 5.0};
  // Orientation: camera looks down its local -Z with local +Y up (OpenGL).
  // Either a look-at target with an up vector, or a quaternion (w, x, y, z).
  std::optional<Vec3> target;
  std::optional<std::array<double, 4>> rotation;
  Vec3 up{0.0, 1.0, 0.0};
  Projection projection = Projection::kPerspective;
  double fov_y_deg = 45.0;     // perspective: vertical field of view
  double ortho_height = 2.0;   // orthographic: world height of the view
  double near_plane = 0.01;
  double far_plane = 1000.0;
  int width = 512;
  int height = 512;
};

enum class ToneCurve { kExponential, kReinhard, kClamp };

struct OutputSettings {
  double exposure = 1.0;
  ToneCurve tone = ToneCurve::kExponential;
  int bit_depth = 8;  // 8 or 16 bits per channel PNG
  // Antialiasing: each camera rendered at supersample x its width and
  // height, its linear HDR averaged over each supersample^2 block (a box
  // filter, the reference's pixel average) before tone mapping. 1: none.
  int supersample = 1;
};

// How the beam line integrals are evaluated; every accuracy knob lives here
// (docs/accuracy.md measures each against time).
enum class IntegrationMethod {
  kTable,       // g(d, s) from a precomputed table (the default)
  kClosedForm,  // exact antiderivative in the shader (abe, linear, quadratic, gaussian)
  kMarch,       // `samples` evaluations of f along the ray per beam piece
};
enum class TableLayout {
  kUniform,      // the paper's grid: d and s uniform on [0, 1] x [0, 2]
  kChord,        // s normalized to the chord: s' = (s - 1) / sqrt(1 - d^2) on [-1, 1]
  kWarped,       // d rows placed per density where g varies most, s uniform
  kChordWarped,  // both
};
enum class TableFilter {
  kHardware,  // the texture unit's bilinear filter
  kShader,    // four texel fetches, weights in full float precision
};
enum class MarchRule { kMidpoint, kSimpson };
// Capsule cylinders where the ray's s-interval is short (rays nearly parallel
// to the axis; docs/stability.md).
enum class NearParallel {
  kQuadrature,  // composite Gauss rule on f there, blended with the table (the default)
  kNone,        // the paper's form everywhere: [g(s1) - g(s0)] / sin(theta); streaks as
                // theta -> 0 (its fig 3.4); for comparison only
};

struct RenderSettings {
  IntegrationMethod method = IntegrationMethod::kTable;
  // Default: chord_warped 128x128, chosen by `beamcast bench accuracy`
  // (docs/accuracy.md): every built-in density under 3e-4 relative L1 image
  // error at the frame time of the paper's uniform 32x32 table.
  int table_d = 128;  // rows of g(d, s) (d axis)
  int table_s = 128;  // columns of g(d, s) (s axis)
  TableLayout layout = TableLayout::kChordWarped;
  TableFilter filter = TableFilter::kHardware;
  int f_table = 1024;  // samples of the 1D table of f (near-parallel path, user tables)
  int samples = 64;    // kMarch: sub-intervals per beam piece (even for Simpson)
  MarchRule rule = MarchRule::kMidpoint;
  NearParallel near_parallel = NearParallel::kQuadrature;  // kTable and kClosedForm
};

struct Scene {
  Color background{0.0, 0.0, 0.0};
  DirectionalLight light;
  std::vector<Beam> beams;
  std::vector<Occluder> occluders;
  std::vector<Light> lights;
  std::vector<Camera> cameras;
  OutputSettings output;
  RenderSettings render;
  GiSettings gi;
  SlimSettings slim;
  // A participating medium filling the scene ("medium"; issue 15), and
  // regions of heterogeneous medium ("media") added to it.
  std::optional<Medium> medium;
  std::vector<MediumRegion> media;
  // Scalar volumes ray cast with transfer functions ("volumes"; issue 17)
  // and the ray caster's accuracy knobs ("volume").
  std::vector<Volume> volumes;
  VolumeSettings volume;

  // Global illumination runs when a light of "lights" lights the scene;
  // otherwise the directional light shades it.
  bool has_gi() const { return !lights.empty(); }
  // The medium passes run when the medium attenuates (sigma_t > 0) or a
  // region of medium exists.
  bool has_medium() const { return (medium && medium->sigma_t() > 0.0) || !media.empty(); }
  // Whether the medium scatters anywhere (the volume photon pass runs).
  bool medium_scatters() const {
    bool any = medium && medium->sigma_s > 0.0;
    for (const MediumRegion& r : media) any = any || r.sigma_s > 0.0;
    return any;
  }
  // The scene-wide medium when it attenuates, else null; and the field of
  // it and the regions.
  const Medium* global_medium() const {
    return medium && medium->sigma_t() > 0.0 ? &*medium : nullptr;
  }
  MediumField medium_field() const { return MediumField(global_medium(), media); }
};

}  // namespace beamcast
