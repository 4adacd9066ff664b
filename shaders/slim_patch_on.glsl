// The slim point programs' "patch" variant (slim.evaluation "patch"): one
// quad per sphere, the crossing solved per fragment (slim_crossing).
#define SLIM_PATCH 1
