#include "render/gl_validate.hpp"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "render/egl_context.hpp"
#include "render/gl_util.hpp"

namespace beamcast {
namespace {

// -1: not set (the environment decides), 0 off, 1 on.
std::atomic<int> g_validation{-1};
thread_local const std::string* t_pass = nullptr;

struct SamplerKind {
  GLenum type;
  GLenum target;
  GLenum binding;
  bool shadow;
  const char* glsl;
};

// Every sampler type of GL 4.5 core, with the target its texture must have.
constexpr SamplerKind kSamplers[] = {
    {GL_SAMPLER_1D, GL_TEXTURE_1D, GL_TEXTURE_BINDING_1D, false, "sampler1D"},
    {GL_INT_SAMPLER_1D, GL_TEXTURE_1D, GL_TEXTURE_BINDING_1D, false, "isampler1D"},
    {GL_UNSIGNED_INT_SAMPLER_1D, GL_TEXTURE_1D, GL_TEXTURE_BINDING_1D, false, "usampler1D"},
    {GL_SAMPLER_1D_SHADOW, GL_TEXTURE_1D, GL_TEXTURE_BINDING_1D, true, "sampler1DShadow"},
    {GL_SAMPLER_2D, GL_TEXTURE_2D, GL_TEXTURE_BINDING_2D, false, "sampler2D"},
    {GL_INT_SAMPLER_2D, GL_TEXTURE_2D, GL_TEXTURE_BINDING_2D, false, "isampler2D"},
    {GL_UNSIGNED_INT_SAMPLER_2D, GL_TEXTURE_2D, GL_TEXTURE_BINDING_2D, false, "usampler2D"},
    {GL_SAMPLER_2D_SHADOW, GL_TEXTURE_2D, GL_TEXTURE_BINDING_2D, true, "sampler2DShadow"},
    {GL_SAMPLER_3D, GL_TEXTURE_3D, GL_TEXTURE_BINDING_3D, false, "sampler3D"},
    {GL_INT_SAMPLER_3D, GL_TEXTURE_3D, GL_TEXTURE_BINDING_3D, false, "isampler3D"},
    {GL_UNSIGNED_INT_SAMPLER_3D, GL_TEXTURE_3D, GL_TEXTURE_BINDING_3D, false, "usampler3D"},
    {GL_SAMPLER_CUBE, GL_TEXTURE_CUBE_MAP, GL_TEXTURE_BINDING_CUBE_MAP, false, "samplerCube"},
    {GL_INT_SAMPLER_CUBE, GL_TEXTURE_CUBE_MAP, GL_TEXTURE_BINDING_CUBE_MAP, false, "isamplerCube"},
    {GL_UNSIGNED_INT_SAMPLER_CUBE, GL_TEXTURE_CUBE_MAP, GL_TEXTURE_BINDING_CUBE_MAP, false,
     "usamplerCube"},
    {GL_SAMPLER_CUBE_SHADOW, GL_TEXTURE_CUBE_MAP, GL_TEXTURE_BINDING_CUBE_MAP, true,
     "samplerCubeShadow"},
    {GL_SAMPLER_1D_ARRAY, GL_TEXTURE_1D_ARRAY, GL_TEXTURE_BINDING_1D_ARRAY, false,
     "sampler1DArray"},
    {GL_SAMPLER_1D_ARRAY_SHADOW, GL_TEXTURE_1D_ARRAY, GL_TEXTURE_BINDING_1D_ARRAY, true,
     "sampler1DArrayShadow"},
    {GL_SAMPLER_2D_ARRAY, GL_TEXTURE_2D_ARRAY, GL_TEXTURE_BINDING_2D_ARRAY, false,
     "sampler2DArray"},
    {GL_INT_SAMPLER_2D_ARRAY, GL_TEXTURE_2D_ARRAY, GL_TEXTURE_BINDING_2D_ARRAY, false,
     "isampler2DArray"},
    {GL_UNSIGNED_INT_SAMPLER_2D_ARRAY, GL_TEXTURE_2D_ARRAY, GL_TEXTURE_BINDING_2D_ARRAY, false,
     "usampler2DArray"},
    {GL_SAMPLER_2D_ARRAY_SHADOW, GL_TEXTURE_2D_ARRAY, GL_TEXTURE_BINDING_2D_ARRAY, true,
     "sampler2DArrayShadow"},
    {GL_SAMPLER_CUBE_MAP_ARRAY, GL_TEXTURE_CUBE_MAP_ARRAY, GL_TEXTURE_BINDING_CUBE_MAP_ARRAY, false,
     "samplerCubeArray"},
    {GL_SAMPLER_CUBE_MAP_ARRAY_SHADOW, GL_TEXTURE_CUBE_MAP_ARRAY,
     GL_TEXTURE_BINDING_CUBE_MAP_ARRAY, true, "samplerCubeArrayShadow"},
    {GL_INT_SAMPLER_CUBE_MAP_ARRAY, GL_TEXTURE_CUBE_MAP_ARRAY, GL_TEXTURE_BINDING_CUBE_MAP_ARRAY,
     false, "isamplerCubeArray"},
    {GL_UNSIGNED_INT_SAMPLER_CUBE_MAP_ARRAY, GL_TEXTURE_CUBE_MAP_ARRAY,
     GL_TEXTURE_BINDING_CUBE_MAP_ARRAY, false, "usamplerCubeArray"},
    {GL_SAMPLER_2D_RECT, GL_TEXTURE_RECTANGLE, GL_TEXTURE_BINDING_RECTANGLE, false,
     "sampler2DRect"},
    {GL_SAMPLER_2D_RECT_SHADOW, GL_TEXTURE_RECTANGLE, GL_TEXTURE_BINDING_RECTANGLE, true,
     "sampler2DRectShadow"},
    {GL_SAMPLER_BUFFER, GL_TEXTURE_BUFFER, GL_TEXTURE_BINDING_BUFFER, false, "samplerBuffer"},
    {GL_INT_SAMPLER_BUFFER, GL_TEXTURE_BUFFER, GL_TEXTURE_BINDING_BUFFER, false, "isamplerBuffer"},
    {GL_UNSIGNED_INT_SAMPLER_BUFFER, GL_TEXTURE_BUFFER, GL_TEXTURE_BINDING_BUFFER, false,
     "usamplerBuffer"},
    {GL_SAMPLER_2D_MULTISAMPLE, GL_TEXTURE_2D_MULTISAMPLE, GL_TEXTURE_BINDING_2D_MULTISAMPLE,
     false, "sampler2DMS"},
    {GL_SAMPLER_2D_MULTISAMPLE_ARRAY, GL_TEXTURE_2D_MULTISAMPLE_ARRAY,
     GL_TEXTURE_BINDING_2D_MULTISAMPLE_ARRAY, false, "sampler2DMSArray"},
};

const SamplerKind* sampler_kind(GLenum type) {
  for (const SamplerKind& k : kSamplers) {
    if (k.type == type) return &k;
  }
  return nullptr;  // not a sampler (images and plain uniforms)
}

std::string program_label(GLuint program) {
  char buf[128];
  GLsizei len = 0;
  glGetObjectLabel(GL_PROGRAM, program, sizeof buf, &len, buf);
  return len > 0 ? std::string(buf, static_cast<std::size_t>(len)) : "#" + std::to_string(program);
}

bool mipmap_filter(GLint f) { return f != GL_NEAREST && f != GL_LINEAR; }

// Why texture `tex` cannot serve sampler `k` (empty if it can): the
// completeness rules of GL 4.5 core 8.17 that this renderer can break
// (no storage, a mipmap filter without the levels) and the depth-comparison
// rule of 8.22 (a shadow sampler needs comparison on, others off).
std::string texture_fault(GLuint tex, const SamplerKind& k, GLuint sampler) {
  if (k.target == GL_TEXTURE_BUFFER) {
    GLint store = 0;
    glGetTextureLevelParameteriv(tex, 0, GL_TEXTURE_BUFFER_DATA_STORE_BINDING, &store);
    return store == 0 ? "texture " + std::to_string(tex) + " has no buffer" : "";
  }
  GLint w = 0;
  glGetTextureLevelParameteriv(tex, 0, GL_TEXTURE_WIDTH, &w);
  if (w <= 0) return "texture " + std::to_string(tex) + " has no storage";
  if (k.target == GL_TEXTURE_2D_MULTISAMPLE || k.target == GL_TEXTURE_2D_MULTISAMPLE_ARRAY) {
    return "";
  }
  GLint min_filter = 0, compare = 0;
  if (sampler != 0) {
    glGetSamplerParameteriv(sampler, GL_TEXTURE_MIN_FILTER, &min_filter);
    glGetSamplerParameteriv(sampler, GL_TEXTURE_COMPARE_MODE, &compare);
  } else {
    glGetTextureParameteriv(tex, GL_TEXTURE_MIN_FILTER, &min_filter);
    glGetTextureParameteriv(tex, GL_TEXTURE_COMPARE_MODE, &compare);
  }
  if (mipmap_filter(min_filter)) {
    GLint immutable = 0, levels = 0, h = 0, d = 0;
    glGetTextureParameteriv(tex, GL_TEXTURE_IMMUTABLE_FORMAT, &immutable);
    glGetTextureParameteriv(tex, GL_TEXTURE_IMMUTABLE_LEVELS, &levels);
    glGetTextureLevelParameteriv(tex, 0, GL_TEXTURE_HEIGHT, &h);
    glGetTextureLevelParameteriv(tex, 0, GL_TEXTURE_DEPTH, &d);
    const int dim = std::max({w, k.target == GL_TEXTURE_3D ? d : 1, h});
    int needed = 1;
    while ((dim >> needed) > 0) ++needed;
    if (!immutable || levels < needed) {
      return "texture " + std::to_string(tex) + " has a mipmap filter but not every level";
    }
  }
  const bool comparing = compare == GL_COMPARE_REF_TO_TEXTURE;
  if (k.shadow && !comparing) {
    return "texture " + std::to_string(tex) + " has no depth comparison for a shadow sampler";
  }
  if (!k.shadow && comparing) {
    return "texture " + std::to_string(tex) + " compares depth for a sampler that does not";
  }
  return "";
}

// A program's active samplers (one entry per array element), listed once
// per program and context: enumerating every uniform at each draw doubled
// the stability sweep's time on llvmpipe. delete_program forgets an entry,
// so a name the driver hands out again is listed again.
struct SamplerSlot {
  const SamplerKind* kind;
  GLint location;
  std::string name;
};
std::mutex g_programs_mutex;
std::map<std::pair<const void*, GLuint>, std::vector<SamplerSlot>> g_programs;

std::vector<SamplerSlot> list_samplers(GLuint prog) {
  std::vector<SamplerSlot> slots;
  GLint count = 0;
  glGetProgramiv(prog, GL_ACTIVE_UNIFORMS, &count);
  for (GLint i = 0; i < count; ++i) {
    char name[256];
    GLsizei len = 0;
    GLint size = 0;
    GLenum type = 0;
    glGetActiveUniform(prog, static_cast<GLuint>(i), sizeof name, &len, &size, &type, name);
    const SamplerKind* k = sampler_kind(type);
    if (!k) continue;
    std::string base(name, static_cast<std::size_t>(len));
    if (base.size() > 3 && base.compare(base.size() - 3, 3, "[0]") == 0) base.resize(base.size() - 3);
    for (GLint e = 0; e < size; ++e) {
      std::string element = size > 1 ? base + "[" + std::to_string(e) + "]" : base;
      const GLint location = glGetUniformLocation(prog, element.c_str());
      slots.push_back({k, location, std::move(element)});
    }
  }
  return slots;
}

const std::vector<SamplerSlot>& samplers_of(GLuint prog) {
  const std::pair<const void*, GLuint> key{EglContext::guarded(), prog};
  std::lock_guard lock(g_programs_mutex);
  auto it = g_programs.find(key);
  if (it == g_programs.end()) it = g_programs.emplace(key, list_samplers(prog)).first;
  return it->second;  // std::map: stays valid while other entries come and go
}

[[noreturn]] void fail(GLuint program, const std::string& what) {
  const std::string pass = t_pass ? *t_pass + " pass" : "(no pass)";
  throw GlError(pass + ", program '" + program_label(program) + "': " + what);
}

}  // namespace

bool gl_validation_enabled() {
  int v = g_validation.load(std::memory_order_relaxed);
  if (v < 0) {
    const char* e = std::getenv("BEAMCAST_GL_VALIDATE");
    v = e && std::string(e) == "1" ? 1 : 0;
    g_validation.store(v, std::memory_order_relaxed);
  }
  return v == 1;
}

void set_gl_validation(bool on) { g_validation.store(on ? 1 : 0); }

void forget_program(GLuint program) {
  std::lock_guard lock(g_programs_mutex);
  g_programs.erase({EglContext::guarded(), program});
}

GlPassLabel::GlPassLabel(const std::string& pass) : outer_(t_pass) { t_pass = &pass; }
GlPassLabel::~GlPassLabel() { t_pass = outer_; }

void validate_draw_state(bool compute) {
  GLint program = 0;
  glGetIntegerv(GL_CURRENT_PROGRAM, &program);
  const auto prog = static_cast<GLuint>(program);
  if (prog == 0) fail(0, "no program bound");
  if (!compute) {
    GLint fb = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &fb);
    const GLenum status =
        fb == 0 ? GLenum{GL_FRAMEBUFFER_UNDEFINED}
                : glCheckNamedFramebufferStatus(static_cast<GLuint>(fb), GL_DRAW_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
      fail(prog, "draw framebuffer " + std::to_string(fb) + " is not complete (status 0x" +
                     [status] {
                       char b[16];
                       std::snprintf(b, sizeof b, "%x", status);
                       return std::string(b);
                     }() +
                     ")");
    }
  }
  GLint active_texture = GL_TEXTURE0;
  glGetIntegerv(GL_ACTIVE_TEXTURE, &active_texture);
  std::string fault;
  for (const SamplerSlot& slot : samplers_of(prog)) {
    GLint unit = 0;
    glGetUniformiv(prog, slot.location, &unit);
    glActiveTexture(GL_TEXTURE0 + static_cast<GLenum>(unit));
    GLint tex = 0, sampler = 0;
    glGetIntegerv(slot.kind->binding, &tex);
    glGetIntegerv(GL_SAMPLER_BINDING, &sampler);
    const std::string where =
        "unit " + std::to_string(unit) + " (" + slot.kind->glsl + " " + slot.name + ")";
    if (tex == 0) {
      fault = where + ": no texture of the sampler's target bound";
    } else if (std::string why = texture_fault(static_cast<GLuint>(tex), *slot.kind,
                                               static_cast<GLuint>(sampler));
               !why.empty()) {
      fault = where + ": " + why;
    }
    if (!fault.empty()) break;
  }
  glActiveTexture(static_cast<GLenum>(active_texture));
  if (!fault.empty()) fail(prog, fault);
}

void draw_arrays(GLenum mode, GLint first, GLsizei count) {
  if (gl_validation_enabled()) validate_draw_state(false);
  glDrawArrays(mode, first, count);
}

void draw_arrays_instanced(GLenum mode, GLint first, GLsizei count, GLsizei instances) {
  if (gl_validation_enabled()) validate_draw_state(false);
  glDrawArraysInstanced(mode, first, count, instances);
}

void draw_elements_base_vertex(GLenum mode, GLsizei count, GLenum type, const void* indices,
                               GLint base_vertex) {
  if (gl_validation_enabled()) validate_draw_state(false);
  glDrawElementsBaseVertex(mode, count, type, indices, base_vertex);
}

void multi_draw_arrays_indirect(GLenum mode, const void* indirect, GLsizei count, GLsizei stride) {
  if (gl_validation_enabled()) validate_draw_state(false);
  glMultiDrawArraysIndirect(mode, indirect, count, stride);
}

void dispatch_compute(GLuint x, GLuint y, GLuint z) {
  if (gl_validation_enabled()) validate_draw_state(true);
  glDispatchCompute(x, y, z);
}

}  // namespace beamcast
