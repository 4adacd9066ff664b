// The pass interface and the GPU-side state a frame passes between passes.
// A new effect (photon splatting, media, point surfaces, volumes) is a new Pass
// here plus its rule in pass_plan.cpp; the frame loop does not change.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "protocol/camera.hpp"
#include "protocol/scene.hpp"
#include "render/gl_util.hpp"
#include "render/scene_resources.hpp"

namespace beamcast {

// Render targets of one frame size: linear HDR colour, view depth (surfaces'
// distance along the view axis; cleared to kNoSurface), depth buffer, output.
// With layers > 0 every target is a 2D array texture of that many layers
// (one per view of a multi-view batch), with one framebuffer triple per layer
// (`layer_fbos`); the layered triple (`scene_fbo` ...) is then unused.
struct FrameTargets {
  static constexpr float kNoSurface = 1e30f;
  int width = 0;
  int height = 0;
  int bit_depth = 0;
  int layers = 0;  // 0: plain 2D textures
  GlTexture hdr;         // RGBA32F
  GlTexture view_depth;  // R32F
  GlTexture depth;       // DEPTH32F, reversed Z
  GlTexture output;      // RGBA8 or RGBA16
  GlFramebuffer scene_fbo;   // hdr + view_depth + depth
  GlFramebuffer beam_fbo;    // hdr only (beams read view_depth as a texture)
  GlFramebuffer output_fbo;  // output
  struct LayerFbos {
    GlFramebuffer scene, beam, output;
  };
  std::vector<LayerFbos> layer_fbos;
  void ensure(int w, int h, int bits, int layer_count = 0);
  // The framebuffer of a view (view < 0 or no layers: the plain one).
  GLuint scene_for(int view) const {
    return view < 0 || layers == 0 ? scene_fbo.get() : layer_fbos[view].scene.get();
  }
  GLuint beam_for(int view) const {
    return view < 0 || layers == 0 ? beam_fbo.get() : layer_fbos[view].beam.get();
  }
  GLuint output_for(int view) const {
    return view < 0 || layers == 0 ? output_fbo.get() : layer_fbos[view].output.get();
  }
};

struct FrameContext {
  const Scene& scene;
  const Camera& camera;
  const CameraBasis& basis;
  SceneResources& resources;
  FrameTargets& targets;
  GLuint empty_vao;
  // 0: one camera (`camera`), the per-camera programs. K >= 1: a multi-view
  // batch of K <= kMaxBatchViews views (SceneResources::bind_views, array
  // targets), drawn by the multi-view programs, each draw once per view into
  // that view's layer with the uniform u_view; `camera` is the first.
  int views = 0;
};

// Views in one multi-view batch: the size of the shaders' camera array
// (BEAMCAST_MAX_VIEWS in shaders/multiview*.glsl; 64 blocks of 176 bytes fit
// the 16 KiB every GL 4.5 driver must allow a uniform block).
inline constexpr int kMaxBatchViews = 64;

class Pass {
 public:
  virtual ~Pass() = default;
  virtual const char* name() const = 0;
  virtual void execute(FrameContext& ctx) = 0;
};

// Every pass, in execution order (the order of pass_catalog()); programs are
// compiled here, so a GL context must be current. Multi-view programs are
// compiled on first use, so a context without layered rendering never needs them.
std::vector<std::unique_ptr<Pass>> make_passes();

}  // namespace beamcast
