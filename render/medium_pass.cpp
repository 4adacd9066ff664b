#include "render/medium_pass.hpp"

#include <cmath>

#include "gi/photon_map.hpp"
#include "render/gl_util.hpp"
#include "render/passes.hpp"
#include "render/scene_resources.hpp"
#include "render/gl_validate.hpp"

namespace beamcast {

namespace {

class MediumPass final : public Pass {
 public:
  MediumPass() : programs_("medium_attenuate") {}
  void execute(FrameContext& ctx, const PassDecl& self) override {
    if (!ctx.scene.has_medium()) throw GlError("medium pass: the scene has no medium");
    const bool multi = ctx.views > 0;
    ProgramPair& program = programs_.get(ctx.scene);
    glUseProgram(program.get(multi));
    const bool surfaces = ctx.plan.written(TargetId::kViewDepth);
    glUniform1i(program.uniform(multi, "u_has_surfaces"), surfaces ? 1 : 0);
    const GLint region_eye = set_medium_uniforms(program, multi, ctx);
    bind_view_target_or_placeholder(ctx, 0, TargetId::kViewDepth);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ZERO, GL_SRC_COLOR);  // hdr *= transmittance
    glBlendEquation(GL_FUNC_ADD);
    glDisable(GL_DEPTH_TEST);
    glBindVertexArray(ctx.empty_vao);
    int view = 0;
    for_each_view(ctx, self, program, [&] {
      set_region_eye(ctx, region_eye, view++);
      draw_arrays(GL_TRIANGLES, 0, 3);
    });
    glDisable(GL_BLEND);
    gl_check("medium pass");
  }

 private:
  RegionProgram programs_;
};

// The volume photons' in-scattered light (shaders/volume_splat.frag): one
// camera-facing quad per photon (QuadIndices) over its kernel sphere, added to
// hdr. gi.display_fraction draws the first share of the photons at 1/share
// power, as the surface photons.
class VolumePhotonPass final : public Pass {
 public:
  VolumePhotonPass() : programs_("volume_splat") {}
  void execute(FrameContext& ctx, const PassDecl& self) override {
    if (!ctx.scene.has_medium()) throw GlError("volume photon pass: the scene has no medium");
    const Medium medium = ctx.scene.medium.value_or(Medium{});
    const double share = display_share(ctx.scene.gi.display_fraction);
    const auto count = static_cast<GLsizei>(
        std::llround(share * static_cast<double>(ctx.resources.volume_count())));
    if (count == 0) return;
    const bool multi = ctx.views > 0;
    ProgramPair& program = programs_.get(ctx.scene);
    glUseProgram(program.get(multi));
    const bool surfaces = ctx.plan.written(TargetId::kViewDepth);
    glUniform1i(program.uniform(multi, "u_has_surfaces"), surfaces ? 1 : 0);
    glUniform1f(program.uniform(multi, "u_radius"),
                static_cast<float>(ctx.resources.volume_radius()));
    glUniform1f(program.uniform(multi, "u_radius_pixels"),
                static_cast<float>(medium.radius_pixels));
    const GLint region_eye = set_medium_uniforms(program, multi, ctx);
    glUniform1i(program.uniform(multi, "u_estimator"),
                medium.estimator == VolumeEstimator::kSeed ? 1 : 0);
    glUniform1i(program.uniform(multi, "u_segments"), medium.segments);
    glUniform1f(program.uniform(multi, "u_power_scale"), static_cast<float>(1.0 / share));
    set_photon_lod(program, multi, ctx.scene.gi);
    bind_view_target_or_placeholder(ctx, 0, TargetId::kViewDepth);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, ctx.resources.volume_buffer());
    begin_additive(ctx);
    int view = 0;
    for_each_view_offset(ctx, self, program, "u_photon_offset", ctx.resources.volume_anchor(),
                         [&] {
                           set_region_eye(ctx, region_eye, view++);
                           quads_.draw(0, count);
                         });
    glDisable(GL_BLEND);
    gl_check("volume photon pass");
  }

 private:
  RegionProgram programs_;
  QuadIndices quads_;
};

}  // namespace

std::unique_ptr<Pass> make_medium_pass() { return std::make_unique<MediumPass>(); }
std::unique_ptr<Pass> make_volume_photon_pass() { return std::make_unique<VolumePhotonPass>(); }

}  // namespace beamcast
