#include "render/gl_util.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <vector>

#include "render/egl_context.hpp"
#include "render/gl_debug.hpp"
#include "render/gl_validate.hpp"
#include "shaders/shader_sources.hpp"

namespace beamcast {

namespace {
const char* gl_error_name(GLenum e) {
  switch (e) {
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    default: return "unknown GL error";
  }
}

GLuint compile_stage(std::string_view program, GLenum stage, const char* stage_name,
                     const std::string& src) {
  GLuint s = glCreateShader(stage);
  const char* text = src.c_str();
  glShaderSource(s, 1, &text, nullptr);
  glCompileShader(s);
  GLint ok = GL_FALSE;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint len = 0;
    glGetShaderiv(s, GL_INFO_LOG_LENGTH, &len);
    std::string log(static_cast<std::size_t>(len > 0 ? len : 1), '\0');
    glGetShaderInfoLog(s, len, nullptr, log.data());
    log.resize(std::strlen(log.c_str()));  // the terminating NUL would end what()
    glDeleteShader(s);
    // The log and the listing name each assembled file and its own line numbers.
    throw GlError("compiling " + std::string(stage_name) + " shader of program '" +
                  std::string(program) + "' failed:\n" + annotate_shader_log(log, src) + "\n" +
                  numbered_shader_source(src));
  }
  return s;
}
}  // namespace

bool software_gl() {
  const auto* name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const std::string s = name != nullptr ? name : "";
  return s.find("llvmpipe") != std::string::npos || s.find("softpipe") != std::string::npos;
}

void gl_check(const char* call) {
  // A call issued in another context's namespace finds stale or foreign names
  // (on NVIDIA: errors, wrong images, crashes); say so rather than what it broke.
  if (const EglContext* owner = EglContext::guarded(); owner && !owner->is_current()) {
    throw GlError(std::string(call) + ": issued while another context than its owner's is current");
  }
  if (!EglContext::any_current()) throw GlError(std::string(call) + ": issued with no context current");
  GLenum e = glGetError();
  // In a debug context, high-severity KHR_debug messages say what went wrong.
  const std::string debug = take_gl_debug_errors();
  if (e == GL_NO_ERROR && debug.empty()) return;
  std::string msg = std::string(call) + ": " + (e == GL_NO_ERROR ? "" : gl_error_name(e));
  while ((e = glGetError()) != GL_NO_ERROR) msg += std::string(", ") + gl_error_name(e);
  if (!debug.empty()) msg += " (" + debug + ")";
  throw GlError(msg);
}

void delete_texture(GLuint id) { glDeleteTextures(1, &id); }
void delete_buffer(GLuint id) { glDeleteBuffers(1, &id); }
void delete_framebuffer(GLuint id) { glDeleteFramebuffers(1, &id); }
void delete_vertex_array(GLuint id) { glDeleteVertexArrays(1, &id); }
void delete_program(GLuint id) {
  forget_program(id);
  glDeleteProgram(id);
}
void delete_query(GLuint id) { glDeleteQueries(1, &id); }

namespace {
// Links compiled stages into a program (the stages deleted either way).
GlProgram link_program(std::string_view name, std::initializer_list<GLuint> stages) {
  GlProgram prog(glCreateProgram());
  for (const GLuint s : stages) glAttachShader(prog.get(), s);
  glLinkProgram(prog.get());
  for (const GLuint s : stages) glDeleteShader(s);
  GLint ok = GL_FALSE;
  glGetProgramiv(prog.get(), GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint len = 0;
    glGetProgramiv(prog.get(), GL_INFO_LOG_LENGTH, &len);
    std::string log(static_cast<std::size_t>(len > 0 ? len : 1), '\0');
    glGetProgramInfoLog(prog.get(), len, nullptr, log.data());
    log.resize(std::strlen(log.c_str()));
    throw GlError("linking program '" + std::string(name) + "' failed:\n" + log);
  }
  // The name that validation (render/gl_validate.hpp) and debuggers show.
  const std::string label(name);
  glObjectLabel(GL_PROGRAM, prog.get(), static_cast<GLsizei>(label.size()), label.c_str());
  gl_check("build_program");
  return prog;
}
}  // namespace

GlProgram build_program(std::string_view name, const std::string& vertex_src,
                        const std::string& fragment_src) {
  GLuint vs = compile_stage(name, GL_VERTEX_SHADER, "vertex", vertex_src);
  GLuint fs = 0;
  try {
    fs = compile_stage(name, GL_FRAGMENT_SHADER, "fragment", fragment_src);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  return link_program(name, {vs, fs});
}

GlProgram build_compute_program(std::string_view name, const std::string& compute_src) {
  return link_program(name, {compile_stage(name, GL_COMPUTE_SHADER, "compute", compute_src)});
}

GlBuffer make_buffer(std::size_t bytes, const void* data, GLbitfield flags) {
  GLuint id = 0;
  glCreateBuffers(1, &id);
  GlBuffer buffer(id);
  glNamedBufferStorage(id, static_cast<GLsizeiptr>(bytes), data, flags);
  return buffer;
}

void QuadIndices::draw(GLsizei first, GLsizei count) {
  if (!vao_) {
    std::vector<GLuint> index;
    index.reserve(6 * static_cast<std::size_t>(kChunk));
    for (GLuint q = 0; q < static_cast<GLuint>(kChunk); ++q) {
      for (const GLuint k : {0u, 1u, 2u, 2u, 1u, 3u}) index.push_back(4 * q + k);
    }
    indices_ = make_buffer(index);
    GLuint id = 0;
    glCreateVertexArrays(1, &id);
    vao_ = GlVertexArray(id);
    glVertexArrayElementBuffer(id, indices_.get());
  }
  glBindVertexArray(vao_.get());
  for (GLsizei done = 0; done < count; done += kChunk) {
    const GLsizei n = std::min(kChunk, count - done);
    draw_elements_base_vertex(GL_TRIANGLES, 6 * n, GL_UNSIGNED_INT, nullptr, 4 * (first + done));
  }
}

GlTexture make_shadow_cube_array(GLsizei size, GLsizei cubes) {
  GLuint id = 0;
  glCreateTextures(GL_TEXTURE_CUBE_MAP_ARRAY, 1, &id);
  GlTexture tex(id);
  glTextureStorage3D(id, 1, GL_DEPTH_COMPONENT32F, size, size, 6 * cubes);
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  for (const GLenum wrap : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R}) {
    glTextureParameteri(id, wrap, GL_CLAMP_TO_EDGE);
  }
  glTextureParameteri(id, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTextureParameteri(id, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  // Context state (GL 4.5 core, 8.13.1): cube-map lookups filter across faces.
  glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
  return tex;
}

GlTexture make_texture_2d(GLenum internal_format, int width, int height) {
  GLuint id = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &id);
  GlTexture tex(id);
  glTextureStorage2D(id, 1, internal_format, width, height);
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  gl_check("glTextureStorage2D");
  return tex;
}

void check_framebuffer(GLuint fbo, const char* what) {
  const GLenum status = glCheckNamedFramebufferStatus(fbo, GL_DRAW_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "0x%x", status);
    throw GlError(std::string(what) + ": framebuffer incomplete, status " + buf);
  }
}

}  // namespace beamcast
