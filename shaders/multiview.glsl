// Prelude of the multi-view variant of every stage (render/passes.cpp): one
// draw renders K views into the layers of array targets; each stage picks its
// view's camera from the Cameras buffer (common.glsl).
#define BEAMCAST_MULTIVIEW 1
