// Draw-time validation (test builds, or BEAMCAST_GL_VALIDATE=1): before each
// draw or dispatch, every active sampler of the bound program must have a
// complete texture of its target on its unit, and the draw framebuffer must be
// complete. llvmpipe renders through both mistakes; the GL spec leaves them
// undefined and NVIDIA's results differ. A failure throws GlError naming the
// pass, the program and the unit.
#pragma once

#include <GL/glcorearb.h>

#include <string>

namespace beamcast {

// Whether draws are validated: set_gl_validation's value if it was called,
// else the environment variable BEAMCAST_GL_VALIDATE ("1" on, else off).
bool gl_validation_enabled();
void set_gl_validation(bool on);

// Drops what validation remembers of `program` in the current context (its
// samplers): called when the program is deleted (delete_program).
void forget_program(GLuint program);

// The pass whose draws follow on this thread (for the messages); nests.
class GlPassLabel {
 public:
  explicit GlPassLabel(const std::string& pass);
  ~GlPassLabel();
  GlPassLabel(const GlPassLabel&) = delete;
  GlPassLabel& operator=(const GlPassLabel&) = delete;

 private:
  const std::string* outer_;
};

// Checks the state a draw (`compute` false) or dispatch (`compute` true)
// reads; throws GlError on the first fault. Call through the wrappers below.
void validate_draw_state(bool compute);

// glDraw* / glDispatchCompute with validate_draw_state first when enabled.
void draw_arrays(GLenum mode, GLint first, GLsizei count);
void draw_arrays_instanced(GLenum mode, GLint first, GLsizei count, GLsizei instances);
void draw_elements_base_vertex(GLenum mode, GLsizei count, GLenum type, const void* indices,
                               GLint base_vertex);
void multi_draw_arrays_indirect(GLenum mode, const void* indirect, GLsizei count, GLsizei stride);
void dispatch_compute(GLuint x, GLuint y, GLuint z);

}  // namespace beamcast
