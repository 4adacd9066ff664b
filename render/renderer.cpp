#include "render/renderer.hpp"

#include <GL/glcorearb.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

#include "protocol/camera.hpp"
#include "render/gl_util.hpp"
#include "render/passes.hpp"
#include "render/scene_resources.hpp"

namespace beamcast {

namespace {
double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

struct Renderer::Impl {
  std::unique_ptr<EglContext> context;
  std::vector<std::unique_ptr<Pass>> passes;
  TableCache tables;
  FrameTargets targets;
  GlVertexArray empty_vao;
  std::vector<GlQuery> queries;  // timestamps: frame start, then one after each pass
  // Target of the bilinear upscale when FrameOptions::resolution_scale < 1.
  GlTexture upscaled;
  GlFramebuffer upscaled_fbo;
  int up_width = 0, up_height = 0, up_bits = 0;

  explicit Impl(const RendererOptions& opts)
      : context(EglContext::create(opts.egl)), tables(opts.table_cache_entries) {
    passes = make_passes();
    GLuint id = 0;
    glCreateVertexArrays(1, &id);
    empty_vao = GlVertexArray(id);
    // Window depth in [0, 1] with reversed Z keeps float depth precise from
    // near to far.
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    gl_check("renderer setup");
  }

  GLuint query(std::size_t i) {
    while (queries.size() <= i) {
      GLuint id = 0;
      glGenQueries(1, &id);
      queries.emplace_back(id);
    }
    return queries[i].get();
  }

  // Bilinear upscale of the output (render size) to w x h, into `upscaled`.
  void upscale(int rw, int rh, int w, int h, int bits) {
    if (w != up_width || h != up_height || bits != up_bits) {
      up_width = w;
      up_height = h;
      up_bits = bits;
      upscaled = make_texture_2d(bits == 16 ? GL_RGBA16 : GL_RGBA8, w, h);
      GLuint id = 0;
      glCreateFramebuffers(1, &id);
      upscaled_fbo = GlFramebuffer(id);
      glNamedFramebufferTexture(id, GL_COLOR_ATTACHMENT0, upscaled.get(), 0);
      check_framebuffer(id, "upscale framebuffer");
    }
    glBlitNamedFramebuffer(targets.output_fbo.get(), upscaled_fbo.get(), 0, 0, rw, rh, 0, 0, w, h,
                           GL_COLOR_BUFFER_BIT, GL_LINEAR);
    gl_check("upscale blit");
  }

  FrameResult render_camera(const Scene& scene, const Camera& full_cam, SceneResources& res,
                            const std::vector<Pass*>& plan, const FrameOptions& opts) {
    const auto wall0 = std::chrono::steady_clock::now();
    FrameResult result;
    // A scaled frame renders a smaller copy of the camera (same view, fewer pixels).
    Camera small = full_cam;
    const bool scaled = opts.resolution_scale > 0.0 && opts.resolution_scale < 1.0;
    if (scaled) {
      small.width = std::max(1, static_cast<int>(std::lround(full_cam.width * opts.resolution_scale)));
      small.height =
          std::max(1, static_cast<int>(std::lround(full_cam.height * opts.resolution_scale)));
    }
    const Camera& cam = small;
    const CameraBasis basis = camera_basis(cam);
    res.bind_camera(cam, basis);
    targets.ensure(cam.width, cam.height, scene.output.bit_depth);
    glViewport(0, 0, cam.width, cam.height);
    glBindBufferBase(GL_UNIFORM_BUFFER, 0, res.camera_buffer());

    const GLuint fbo = targets.scene_fbo.get();
    const float bg[4] = {static_cast<float>(scene.background[0]),
                         static_cast<float>(scene.background[1]),
                         static_cast<float>(scene.background[2]), 0.0f};
    const float no_surface[4] = {FrameTargets::kNoSurface, 0.0f, 0.0f, 0.0f};
    const float far_depth = 0.0f;  // reversed Z
    glDepthMask(GL_TRUE);
    glQueryCounter(query(0), GL_TIMESTAMP);
    glClearNamedFramebufferfv(fbo, GL_COLOR, 0, bg);
    glClearNamedFramebufferfv(fbo, GL_COLOR, 1, no_surface);
    glClearNamedFramebufferfv(fbo, GL_DEPTH, 0, &far_depth);

    FrameContext ctx{scene, cam, basis, res, targets, empty_vao.get()};
    for (std::size_t i = 0; i < plan.size(); ++i) {
      plan[i]->execute(ctx);
      glQueryCounter(query(i + 1), GL_TIMESTAMP);
    }
    std::size_t stamp_count = plan.size() + 1;
    if (scaled) {
      upscale(cam.width, cam.height, full_cam.width, full_cam.height, scene.output.bit_depth);
      glQueryCounter(query(stamp_count++), GL_TIMESTAMP);
    }
    gl_check("frame");

    // Read-back (synchronous: it waits for the GPU to finish the frame).
    const auto rb0 = std::chrono::steady_clock::now();
    const int w = full_cam.width, h = full_cam.height;
    result.image.width = w;
    result.image.height = h;
    result.image.bit_depth = scene.output.bit_depth;
    result.image.rgb.resize(3 * static_cast<std::size_t>(w) * h);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glBindFramebuffer(GL_READ_FRAMEBUFFER,
                      scaled ? upscaled_fbo.get() : targets.output_fbo.get());
    if (scene.output.bit_depth == 16) {
      glReadnPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_SHORT,
                    static_cast<GLsizei>(result.image.rgb.size() * 2), result.image.rgb.data());
    } else {
      std::vector<std::uint8_t> bytes(result.image.rgb.size());
      glReadnPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, static_cast<GLsizei>(bytes.size()),
                    bytes.data());
      std::copy(bytes.begin(), bytes.end(), result.image.rgb.begin());
    }
    gl_check("glReadnPixels(output)");
    result.readback_ms = ms_since(rb0);
    // GL rows run bottom-up; images run top-down.
    const std::size_t row = 3 * static_cast<std::size_t>(w);
    for (int y = 0; y < h / 2; ++y) {
      std::swap_ranges(result.image.rgb.begin() + y * row, result.image.rgb.begin() + (y + 1) * row,
                       result.image.rgb.begin() + (h - 1 - y) * row);
    }
    if (opts.read_hdr) {
      const int hw = cam.width, hh = cam.height;
      const std::size_t hrow = 3 * static_cast<std::size_t>(hw);
      result.hdr.width = hw;
      result.hdr.height = hh;
      std::vector<float> buf(hrow * hh);
      glBindFramebuffer(GL_READ_FRAMEBUFFER, targets.scene_fbo.get());
      glReadBuffer(GL_COLOR_ATTACHMENT0);
      glReadnPixels(0, 0, hw, hh, GL_RGB, GL_FLOAT, static_cast<GLsizei>(buf.size() * 4),
                    buf.data());
      gl_check("glReadnPixels(hdr)");
      result.hdr.rgb.resize(buf.size());
      for (int y = 0; y < hh; ++y) {
        std::memcpy(&result.hdr.rgb[y * hrow], &buf[(hh - 1 - y) * hrow], hrow * sizeof(float));
      }
    }

    GLuint64 stamps[16] = {};
    for (std::size_t i = 0; i < stamp_count; ++i) {
      glGetQueryObjectui64v(query(i), GL_QUERY_RESULT, &stamps[i]);
    }
    for (std::size_t i = 0; i < plan.size(); ++i) {
      result.passes.push_back({plan[i]->name(), (stamps[i + 1] - stamps[i]) * 1e-6});
    }
    if (scaled) {
      result.passes.push_back({"upscale", (stamps[plan.size() + 1] - stamps[plan.size()]) * 1e-6});
    }
    result.gpu_ms = (stamps[stamp_count - 1] - stamps[0]) * 1e-6;
    result.wall_ms = ms_since(wall0);
    return result;
  }
};

Renderer::Renderer(const RendererOptions& opts) : impl_(std::make_unique<Impl>(opts)) {}
Renderer::~Renderer() = default;

const std::string& Renderer::description() const { return impl_->context->description(); }

std::vector<FrameResult> Renderer::render(const Scene& scene, const FrameOptions& opts) {
  return render(scene, scene.cameras, opts);
}

std::vector<FrameResult> Renderer::render(const Scene& scene, const std::vector<Camera>& cameras,
                                          const FrameOptions& opts) {
  std::vector<Pass*> plan;
  for (const std::string& name : plan_passes(scene)) {
    for (auto& pass : impl_->passes) {
      if (name == pass->name()) plan.push_back(pass.get());
    }
  }
  SceneResources res(scene, impl_->tables);
  std::vector<FrameResult> frames;
  frames.reserve(cameras.size());
  for (const Camera& cam : cameras) {
    frames.push_back(impl_->render_camera(scene, cam, res, plan, opts));
  }
  return frames;
}

}  // namespace beamcast
