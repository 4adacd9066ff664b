// Prelude of the multi-view variant of every stage (render/passes.cpp): a
// pass renders K views into the layers of array targets, one draw per view;
// each stage picks its view's camera from the CameraBlocks array (common.glsl).
#define BEAMCAST_MULTIVIEW 1
#define BEAMCAST_MAX_VIEWS 64  // = kMaxBatchViews in render/passes.hpp
