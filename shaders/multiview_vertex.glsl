// Prelude of the multi-view vertex stages: they route each primitive to its
// view's layer by writing gl_Layer (ARB_shader_viewport_layer_array, which
// llvmpipe and current GPU drivers have; the renderer checks before use).
#extension GL_ARB_shader_viewport_layer_array : require
#define BEAMCAST_MULTIVIEW 1
