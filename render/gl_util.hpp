// Small RAII wrappers and checks for GL objects. Every failure names the GL call
// (or the shader stage, program and log) and throws GlError: a broken GL state
// is an internal failure of this process, never a client's fault.
#pragma once

#include <GL/glcorearb.h>

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace beamcast {

class GlError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Throws GlError naming `call` if glGetError reports anything.
void gl_check(const char* call);

// Whether the current context's GL is a software rasterizer (Mesa's llvmpipe
// or softpipe): gi.specular_tracer "auto" keeps the CPU tracer there, and the
// GPU tracer runs in groups of one invocation (shaders/specular_serial_on.glsl).
bool software_gl();

// Owns one GL object name; `Deleter` frees it.
template <void (*Deleter)(GLuint)>
class GlHandle {
 public:
  GlHandle() = default;
  explicit GlHandle(GLuint id) : id_(id) {}
  ~GlHandle() { reset(); }
  GlHandle(GlHandle&& o) noexcept : id_(std::exchange(o.id_, 0)) {}
  GlHandle& operator=(GlHandle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, 0);
    }
    return *this;
  }
  GlHandle(const GlHandle&) = delete;
  GlHandle& operator=(const GlHandle&) = delete;
  GLuint get() const { return id_; }
  explicit operator bool() const { return id_ != 0; }
  void reset() {
    if (id_) Deleter(id_);
    id_ = 0;
  }

 private:
  GLuint id_ = 0;
};

void delete_texture(GLuint id);
void delete_buffer(GLuint id);
void delete_framebuffer(GLuint id);
void delete_vertex_array(GLuint id);
void delete_program(GLuint id);
void delete_query(GLuint id);

using GlTexture = GlHandle<delete_texture>;
using GlBuffer = GlHandle<delete_buffer>;
using GlFramebuffer = GlHandle<delete_framebuffer>;
using GlVertexArray = GlHandle<delete_vertex_array>;
using GlProgram = GlHandle<delete_program>;
using GlQuery = GlHandle<delete_query>;

// Compiles and links a program from assembled stage sources. On failure throws
// GlError with the program name, the stage, the info log and numbered source.
GlProgram build_program(std::string_view name, const std::string& vertex_src,
                        const std::string& fragment_src);
// The same for a compute program.
GlProgram build_compute_program(std::string_view name, const std::string& compute_src);

// Creates an immutable 2D texture with the given internal format.
GlTexture make_texture_2d(GLenum internal_format, int width, int height);

// A depth cube-map array of `cubes` cubes (6 layers each), size x size a
// face, for shadow lookups (samplerCubeArrayShadow): linear filtering with
// depth comparison, clamped at the edges, and seamless cube-map filtering
// enabled on the current context, so a lookup near a face's edge blends
// with the neighbouring face rather than the far edge of its own (the
// default GL_REPEAT, which NVIDIA honours and llvmpipe clamps).
GlTexture make_shadow_cube_array(GLsizei size, GLsizei cubes);

// An immutable buffer of `bytes` (glNamedBufferStorage), from `data`
// (nullptr: uninitialized) with storage `flags`.
GlBuffer make_buffer(std::size_t bytes, const void* data, GLbitfield flags = 0);
template <class T>
GlBuffer make_buffer(const std::vector<T>& data, GLbitfield flags = 0) {
  return make_buffer(data.size() * sizeof(T), data.data(), flags);
}

// Draws of many quads without instancing: quad i is vertices 4i .. 4i+3 in
// a triangle strip's order, i.e. corner (gl_VertexID & 1, (gl_VertexID >> 1)
// & 1) of item gl_VertexID >> 2, as two indexed triangles. llvmpipe runs
// its vertex pipeline (fetch, shader, clip, emit) once per instance of an
// instanced draw, for 4 vertices; indexed, it shades the vertices of
// thousands of quads a batch (docs/gi.md, "Quads without instancing",
// and docs/slim.md measure it). The index buffer holds kChunk quads;
// larger draws go in chunks, each shifted by its base vertex (which
// gl_VertexID includes).
class QuadIndices {
 public:
  static constexpr GLsizei kChunk = 16384;
  // Draws quads first .. first + count - 1 (gl_VertexID >> 2 runs over
  // them) with the vertex array bound here (no attributes).
  void draw(GLsizei first, GLsizei count);

 private:
  GlBuffer indices_;
  GlVertexArray vao_;
};

// Checks the bound draw framebuffer; throws GlError naming its status.
void check_framebuffer(GLuint fbo, const char* what);

}  // namespace beamcast
