// Prelude of "specular_trace_serial" (shaders/programs.txt): the specular
// tracer in work groups of one invocation, the program the pass uses on a
// software rasterizer. Mesa's llvmpipe runs the invocations of a group as
// lanes of one SIMD function and ends every loop of a run once all its loops
// together have turned 65 535 times (gallivm's LP_MAX_TGSI_LOOP_ITERATIONS,
// one count shared by every loop of the shader, there against endless
// loops). The 8 x 8 group's lanes run each loop as long as their slowest
// lane, so a group whose pixels follow many branches through glass and
// gather many photons ran past that count and lost its last rays
// (docs/gi.md). Alone, an invocation's count is its own.
#define SPECULAR_SERIAL 1
