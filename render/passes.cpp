#include "render/passes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "render/gl_validate.hpp"
#include "shaders/shader_sources.hpp"

namespace beamcast {

namespace {

GLenum internal_format(TargetFormat f, int bits) {
  switch (f) {
    case TargetFormat::kRgba32f:
      return GL_RGBA32F;
    case TargetFormat::kR32f:
      return GL_R32F;
    case TargetFormat::kDepth32f:
      return GL_DEPTH_COMPONENT32F;
    case TargetFormat::kDisplay:
      return bits == 16 ? GL_RGBA16 : GL_RGBA8;
  }
  throw GlError("unknown target format");
}

}  // namespace

void FrameTargets::ensure(const FramePlan& plan, int render_w, int render_h, int camera_w,
                          int camera_h, int bits, int layer_count) {
  const int splat_scale =
      plan.splat_scale > 0 ? plan.splat_scale
                           : std::min(auto_splat_scale(render_w, render_h), plan.auto_splat_cap);
  if (render_w != render_w_ || render_h != render_h_ || camera_w != camera_w_ ||
      camera_h != camera_h_ || bits != bits_ || layer_count != layers_ ||
      splat_scale != splat_scale_) {
    targets_ = {};
    fbos_.clear();
    render_w_ = render_w;
    render_h_ = render_h;
    camera_w_ = camera_w;
    camera_h_ = camera_h;
    bits_ = bits;
    layers_ = layer_count;
    splat_scale_ = splat_scale;
    splat_bands_ = beamcast::splat_bands(splat_size(render_w, splat_scale),
                                         splat_size(render_h, splat_scale));
  }
  for (const TargetDecl* decl : plan.targets) {
    if (find(decl->id)) continue;
    const bool camera_size = decl->size == TargetSize::kCamera;
    int w = camera_size ? camera_w : render_w;
    int h = camera_size ? camera_h : render_h;
    if (decl->size == TargetSize::kSplat) {
      w = splat_bands_.texture_w();
      h = splat_bands_.band_h;
    }
    const GLenum format = internal_format(decl->format, bits);
    Target t{decl, {}};
    if (layer_count == 0) {
      t.texture = make_texture_2d(format, w, h);
    } else {
      GLuint id = 0;
      glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &id);
      t.texture = GlTexture(id);
      glTextureStorage3D(id, 1, format, w, h, layer_count);
      glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    targets_[static_cast<std::size_t>(decl->id)] = std::move(t);
  }
  gl_check("FrameTargets::ensure");
}

const FrameTargets::Target* FrameTargets::find(TargetId id) const {
  const Target& t = targets_.at(static_cast<std::size_t>(id));
  return t.decl ? &t : nullptr;
}

GLuint FrameTargets::texture(TargetId id) const {
  const Target* t = find(id);
  if (!t) {
    throw GlError("target " + target_catalog().at(static_cast<std::size_t>(id)).name +
                  " is read but this frame's plan did not allocate it");
  }
  return t->texture.get();
}

GLuint FrameTargets::placeholder(GLenum target) {
  GlTexture& tex = placeholders_[target];
  if (!tex) {
    GLuint id = 0;
    glCreateTextures(target, 1, &id);
    tex = GlTexture(id);
    const float zero = 0.0f;
    if (target == GL_TEXTURE_2D) {
      glTextureStorage2D(id, 1, GL_R32F, 1, 1);
      glTextureSubImage2D(id, 0, 0, 0, 1, 1, GL_RED, GL_FLOAT, &zero);
    } else {  // GL_TEXTURE_2D_ARRAY, GL_TEXTURE_3D: one layer or slice
      glTextureStorage3D(id, 1, GL_R32F, 1, 1, 1);
      glTextureSubImage3D(id, 0, 0, 0, 0, 1, 1, 1, GL_RED, GL_FLOAT, &zero);
    }
    glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl_check("FrameTargets::placeholder");
  }
  return tex.get();
}

void FrameTargets::clear(const FramePlan& plan, const Color& background) {
  for (const TargetDecl* decl : plan.targets) {
    const GLuint tex = texture(decl->id);
    switch (decl->clear) {
      case TargetClear::kNone:
        break;
      case TargetClear::kBackground: {
        const float bg[4] = {static_cast<float>(background[0]), static_cast<float>(background[1]),
                             static_cast<float>(background[2]), 0.0f};
        glClearTexImage(tex, 0, GL_RGBA, GL_FLOAT, bg);
        break;
      }
      case TargetClear::kNoSurface: {
        const float v = kNoSurface;
        glClearTexImage(tex, 0, GL_RED, GL_FLOAT, &v);
        break;
      }
      case TargetClear::kZero: {
        const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
        glClearTexImage(tex, 0, GL_RGBA, GL_FLOAT, zero);
        break;
      }
      case TargetClear::kOne: {
        const float one[4] = {1.0f, 1.0f, 1.0f, 1.0f};
        glClearTexImage(tex, 0, GL_RGBA, GL_FLOAT, one);
        break;
      }
      case TargetClear::kFarDepth: {
        const float v = 0.0f;  // reversed Z
        glClearTexImage(tex, 0, GL_DEPTH_COMPONENT, GL_FLOAT, &v);
        break;
      }
    }
  }
  gl_check("FrameTargets::clear");
}

GLuint FrameTargets::fbo(const PassDecl& pass, int view) {
  PassFbos& f = fbos_[&pass];
  if (view < 0 || layers_ == 0) {
    if (!f.plain) f.plain = GlFramebuffer(make_fbo(pass, -1));
    return f.plain.get();
  }
  if (f.per_layer.empty()) f.per_layer.resize(static_cast<std::size_t>(layers_));
  GlFramebuffer& l = f.per_layer[static_cast<std::size_t>(view)];
  if (!l) l = GlFramebuffer(make_fbo(pass, view));
  return l.get();
}

// The pass's writes as attachments of one framebuffer (of one layer, or the
// plain targets with layer < 0). Rendering each view through its own
// (non-layered) framebuffer measured faster on llvmpipe than one layered
// framebuffer with gl_Layer routing (docs/performance.md).
GLuint FrameTargets::make_fbo(const PassDecl& pass, int layer) {
  GLuint id = 0;
  glCreateFramebuffers(1, &id);
  std::vector<GLenum> draw;
  for (const TargetId target : pass.writes) {
    const Target* t = find(target);
    if (!t) throw GlError("pass " + pass.name + " writes a target its plan did not allocate");
    GLenum attachment = GL_DEPTH_ATTACHMENT;
    if (t->decl->format != TargetFormat::kDepth32f) {
      attachment = GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(draw.size());
      draw.push_back(attachment);
    }
    if (layer < 0) {
      glNamedFramebufferTexture(id, attachment, t->texture.get(), 0);
    } else {
      glNamedFramebufferTextureLayer(id, attachment, t->texture.get(), 0, layer);
    }
  }
  glNamedFramebufferDrawBuffers(id, static_cast<GLsizei>(draw.size()), draw.data());
  check_framebuffer(id, ("framebuffer of pass " + pass.name).c_str());
  gl_check("FrameTargets::make_fbo");
  return id;
}

GLint set_medium_uniforms(ProgramPair& program, bool multiview, const FrameContext& ctx) {
  const Scene& scene = ctx.scene;
  const Medium* global = scene.global_medium();
  glUniform1f(program.uniform(multiview, "u_sigma_t"),
              global ? static_cast<float>(global->sigma_t()) : 0.0f);
  const int n = std::min<int>(static_cast<int>(scene.media.size()), kMaxMediumRegions);
  std::array<float, 4 * kMaxMediumRegions> a{}, b{};
  std::array<float, kMaxMediumRegions> radius{};
  std::array<GLint, 2 * kMaxMediumRegions> tris{};
  GLint first = 0;
  for (int i = 0; i < n; ++i) {
    const MediumRegion& r = scene.media[static_cast<std::size_t>(i)];
    const RegionGpu g = r.gpu();
    for (std::size_t k = 0; k < 3; ++k) {
      a[4 * i + k] = static_cast<float>(g.a[k]);
      b[4 * i + k] = static_cast<float>(g.b[k]);
    }
    a[4 * i + 3] = static_cast<float>(g.code);
    b[4 * i + 3] = static_cast<float>(r.sigma_t());
    radius[static_cast<std::size_t>(i)] = static_cast<float>(g.r);
    const auto count = static_cast<GLint>(r.gpu_triangles().size());
    tris[2 * i] = first;
    tris[2 * i + 1] = count;
    first += count;
  }
  glUniform1i(program.uniform(multiview, "u_region_count"), n);
  if (n > 0) {
    glUniform4fv(program.uniform(multiview, "u_region_a"), n, a.data());
    glUniform4fv(program.uniform(multiview, "u_region_b"), n, b.data());
    glUniform1fv(program.uniform(multiview, "u_region_r"), n, radius.data());
  }
  if (first > 0) {
    glUniform2iv(program.uniform(multiview, "u_region_tris"), n, tris.data());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 7, ctx.resources.medium_triangle_buffer());
  }
  return program.uniform(multiview, "u_region_eye");
}

const Vec3& view_eye(const FrameContext& ctx, int view) {
  return ctx.views > 0 && view >= 0 ? ctx.view_eyes[static_cast<std::size_t>(view)]
                                    : ctx.basis.eye;
}

void set_view_offset(const FrameContext& ctx, GLint location, int view, const Vec3& anchor) {
  const Vec3 off = anchor - view_eye(ctx, view);
  glUniform3f(location, static_cast<float>(off[0]), static_cast<float>(off[1]),
              static_cast<float>(off[2]));
}

void set_region_eye(const FrameContext& ctx, GLint location, int view) {
  const Vec3& eye = view_eye(ctx, view);
  glUniform3f(location, static_cast<float>(eye[0]), static_cast<float>(eye[1]),
              static_cast<float>(eye[2]));
}

void begin_additive(const FrameContext& ctx) {
  glEnable(GL_BLEND);
  glBlendFunc(GL_ONE, GL_ONE);
  glBlendEquation(GL_FUNC_ADD);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glBindVertexArray(ctx.empty_vao);
}

void bind_gbuffer(const FrameContext& ctx) {
  glBindTextureUnit(0, ctx.targets.texture(TargetId::kViewDepth));
  glBindTextureUnit(1, ctx.targets.texture(TargetId::kGbNormal));
  glBindTextureUnit(2, ctx.targets.texture(TargetId::kGbAlbedo));
}

void bind_view_placeholder(FrameContext& ctx, GLuint unit) {
  glBindTextureUnit(unit, ctx.targets.placeholder(ctx.views > 0 ? GL_TEXTURE_2D_ARRAY
                                                                : GL_TEXTURE_2D));
}

bool bind_view_target_or_placeholder(FrameContext& ctx, GLuint unit, TargetId target) {
  const bool written = ctx.plan.written(target);
  if (written) {
    glBindTextureUnit(unit, ctx.targets.texture(target));
  } else {
    bind_view_placeholder(ctx, unit);
  }
  return written;
}

void set_photon_lod(ProgramPair& program, bool multiview, const GiSettings& gi) {
  glUniform1i(program.uniform(multiview, "u_lod_groups"), gi.lod_groups);
  glUniform1f(program.uniform(multiview, "u_lod_near"), static_cast<float>(gi.lod_near));
  glUniform1f(program.uniform(multiview, "u_lod_far"), static_cast<float>(gi.lod_far));
}

std::array<int, 4> pixel_rect(std::span<const Vec3> points, const Camera& cam, const CameraBasis& b,
                              int margin) {
  std::array<double, 2> lo{std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::infinity()};
  std::array<double, 2> hi{-lo[0], -lo[1]};
  for (const Vec3& p : points) {
    const auto w = window_position(cam, b, p);
    if (!w) return kEveryPixel;
    for (int a = 0; a < 2; ++a) {
      lo[a] = std::min(lo[a], (*w)[a]);
      hi[a] = std::max(hi[a], (*w)[a]);
    }
  }
  auto pixel = [](double x, int m) {
    return static_cast<int>(std::clamp(std::floor(x) + m, -1e9, 1e9));
  };
  return {pixel(lo[0], -margin), pixel(lo[1], -margin), pixel(hi[0], margin), pixel(hi[1], margin)};
}

}  // namespace beamcast
