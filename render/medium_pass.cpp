#include "render/medium_pass.hpp"

#include "render/gl_util.hpp"
#include "render/passes.hpp"

namespace beamcast {

namespace {

class MediumPass final : public Pass {
 public:
  MediumPass() : program_("medium_attenuate") {}
  void execute(FrameContext& ctx, const PassDecl& self) override {
    if (!ctx.scene.medium) throw GlError("medium pass: the scene has no medium");
    const bool multi = ctx.views > 0;
    glUseProgram(program_.get(multi));
    const bool surfaces = ctx.plan.written("view_depth");
    glUniform1i(program_.uniform(multi, "u_has_surfaces"), surfaces ? 1 : 0);
    glUniform1f(program_.uniform(multi, "u_sigma_t"),
                static_cast<float>(ctx.scene.medium->sigma_t()));
    glBindTextureUnit(0, surfaces ? ctx.targets.texture("view_depth") : 0);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ZERO, GL_SRC_COLOR);  // hdr *= transmittance
    glBlendEquation(GL_FUNC_ADD);
    glDisable(GL_DEPTH_TEST);
    glBindVertexArray(ctx.empty_vao);
    for_each_view(ctx, self, program_, [] { glDrawArrays(GL_TRIANGLES, 0, 3); });
    glDisable(GL_BLEND);
    gl_check("medium pass");
  }

 private:
  ProgramPair program_;
};

}  // namespace

std::unique_ptr<Pass> make_medium_pass() { return std::make_unique<MediumPass>(); }

}  // namespace beamcast
