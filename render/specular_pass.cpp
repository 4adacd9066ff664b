#include "render/specular_pass.hpp"

#include <chrono>
#include <optional>
#include <vector>

#include "gi/parallel.hpp"
#include "gi/photon_gather.hpp"
#include "protocol/camera.hpp"
#include "render/passes.hpp"
#include "render/gl_validate.hpp"
#include "render/specular_gpu.hpp"

namespace beamcast {

namespace {

// How often the CPU path offers a turn while its rows are traced.
constexpr std::chrono::milliseconds kTurnCheck{10};

class SpecularPass final : public Pass {
 public:
  SpecularPass() : program_("specular_add") {}
  void execute(FrameContext& ctx, const PassDecl& self) override {
    if (const SpecularGpu* gpu = ctx.resources.specular_gpu()) {
      trace_on_gpu(ctx, *gpu);
    } else {
      trace_on_cpu(ctx);
    }
    glUseProgram(program_.get(ctx.views > 0));
    glBindTextureUnit(0, ctx.targets.texture(TargetId::kSpecular));
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glBlendEquation(GL_FUNC_ADD);
    glDisable(GL_DEPTH_TEST);
    glBindVertexArray(ctx.empty_vao);
    for_each_view(ctx, self, program_, [] { draw_arrays(GL_TRIANGLES, 0, 3); });
    glDisable(GL_BLEND);
    gl_check("specular pass");
  }

 private:
  // shaders/specular_trace.comp into the "specular" target, each view its
  // layer (render/specular_gpu.hpp).
  void trace_on_gpu(FrameContext& ctx, const SpecularGpu& gpu) {
    const bool multi = ctx.views > 0;
    // Groups of one invocation on a software rasterizer, where 8 x 8 lanes
    // share llvmpipe's loop count (shaders/specular_serial_on.glsl).
    if (!serial_) serial_ = software_gl();
    const GLuint group = *serial_ ? 1 : 8;
    ProgramPair& trace = lazy_.get(*serial_ ? "specular_trace_serial" : "specular_trace");
    const GLuint program = trace.get(multi);
    glUseProgram(program);
    gpu.bind(program);
    glUniform1i(trace.uniform(multi, "u_samples"), ctx.scene.gi.specular_samples);
    glBindTextureUnit(0, ctx.targets.texture(TargetId::kGbAlbedo));
    glBindImageTexture(0, ctx.targets.texture(TargetId::kSpecular), 0, multi ? GL_TRUE : GL_FALSE, 0,
                       GL_WRITE_ONLY, GL_RGBA32F);
    const GLint eye = trace.uniform(multi, "u_eye");
    const int views = multi ? ctx.views : 1;
    for (int v = 0; v < views; ++v) {
      const Camera& cam = multi ? (*ctx.view_cameras)[static_cast<std::size_t>(v)] : ctx.camera;
      const Vec3 e = view_eye(ctx, multi ? v : -1) - gpu.anchor();
      glUniform3f(eye, static_cast<float>(e[0]), static_cast<float>(e[1]), static_cast<float>(e[2]));
      if (multi) glUniform1i(trace.uniform(true, "u_view"), v);
      dispatch_compute((static_cast<GLuint>(cam.width) + group - 1) / group,
                       (static_cast<GLuint>(cam.height) + group - 1) / group, 1);
    }
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    glBindImageTexture(0, 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    gl_check("specular pass: tracing on the GPU");
  }

  void trace_on_cpu(FrameContext& ctx) {
    const GiScene* surfaces = ctx.resources.gi_scene();
    const PhotonGather* gather = ctx.resources.photon_gather();
    if (!surfaces || !gather)
      throw GlError("specular pass: the scene's ray tracing data is missing");
    const LitShading shading(ctx.scene, *surfaces, *gather);
    const bool multi = ctx.views > 0;
    const int views = multi ? ctx.views : 1;
    const GLuint albedo_tex = ctx.targets.texture(TargetId::kGbAlbedo);
    const GLuint out_tex = ctx.targets.texture(TargetId::kSpecular);
    std::vector<float> albedo, out;
    const int samples = ctx.scene.gi.specular_samples;  // K x K rays a pixel
    for (int v = 0; v < views; ++v) {
      const Camera& cam = multi ? (*ctx.view_cameras)[static_cast<std::size_t>(v)] : ctx.camera;
      const CameraBasis& basis = multi ? (*ctx.view_bases)[static_cast<std::size_t>(v)] : ctx.basis;
      const int w = cam.width, h = cam.height;
      const std::size_t n = static_cast<std::size_t>(w) * h;
      albedo.resize(4 * n);
      glGetTextureSubImage(albedo_tex, 0, 0, 0, v, w, h, 1, GL_RGBA, GL_FLOAT,
                           static_cast<GLsizei>(albedo.size() * sizeof(float)), albedo.data());
      out.assign(4 * n, 0.0f);
      // Rows bottom-up, as GL stores them and camera_ray counts them; a long
      // pass gives waiting renders turns between rows (protocol/turns.hpp).
      parallel_items_with_turns(h, 0, [&](int y) {
        for (int x = 0; x < w; ++x) {
          const std::size_t i = static_cast<std::size_t>(y) * w + x;
          const float material = albedo[4 * i + 3];
          if (!(material > 0.5f && material < 2.5f)) continue;  // mirror (1) or glass (2)
          // K x K rays at the centres of a K x K grid over the pixel.
          Color c{0.0, 0.0, 0.0};
          for (int sy = 0; sy < samples; ++sy) {
            for (int sx = 0; sx < samples; ++sx) {
              const double nx = 2.0 * (x + (sx + 0.5) / samples) / w - 1.0;
              const double ny = 2.0 * (y + (sy + 0.5) / samples) / h - 1.0;
              const Ray ray = camera_ray_ndc(cam, basis, nx, ny);
              c = c + shading.trace(ray.origin, ray.dir, ray.t_min, ray.t_max);
            }
          }
          c = (1.0 / (samples * samples)) * c;
          for (int k = 0; k < 3; ++k)
            out[4 * i + static_cast<std::size_t>(k)] = static_cast<float>(c[k]);
          out[4 * i + 3] = 1.0f;
        }
      }, [] { glFinish(); }, kTurnCheck);
      if (multi) {
        glTextureSubImage3D(out_tex, 0, 0, 0, v, w, h, 1, GL_RGBA, GL_FLOAT, out.data());
      } else {
        glTextureSubImage2D(out_tex, 0, 0, 0, w, h, GL_RGBA, GL_FLOAT, out.data());
      }
    }
  }

  ProgramPair program_;
  std::optional<bool> serial_;  // software_gl(), asked once: a pass serves one context
  LazyPrograms lazy_;  // specular_trace, built when a scene is traced on the GPU
};

}  // namespace

std::unique_ptr<Pass> make_specular_pass() { return std::make_unique<SpecularPass>(); }

}  // namespace beamcast
