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
// (one per view of a multi-view batch) attached layered.
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
  void ensure(int w, int h, int bits, int layer_count = 0);
};

struct FrameContext {
  const Scene& scene;
  const Camera& camera;
  const CameraBasis& basis;
  SceneResources& resources;
  FrameTargets& targets;
  GLuint empty_vao;
  // 0: one camera (`camera`), the per-camera programs. K >= 1: a multi-view
  // batch of K views (SceneResources::bind_views, layered targets), drawn by
  // the multi-view programs with K instances per draw; `camera` is the first.
  int views = 0;
};

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
