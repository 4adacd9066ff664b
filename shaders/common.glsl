// Shared by every program: the per-camera block and the view ray.
// All positions are camera-relative (the CPU subtracts the eye in double), so
// far-away scenes keep float precision near the camera.

// The per-camera values, one layout (std140) for both variants.
struct CameraData {
  mat4 view_proj;    // camera-relative world -> clip, reversed Z (near -> 1, far -> 0)
  vec4 cam_right;    // xyz; w: tan(fov_y / 2) (perspective) or half height (orthographic)
  vec4 cam_up;       // xyz; w: aspect = width / height
  vec4 cam_forward;  // xyz; w: 1 for orthographic, 0 for perspective
  vec4 viewport;     // x: width, y: height, z: near, w: far (view depth)
  vec4 light_dir;    // xyz: unit vector towards the light; w: ambient
  vec4 light_color;  // rgb: light color; w: intensity
  vec4 mesh_offset;  // xyz: mesh anchor minus eye (triangles are stored anchor-relative)
};

#ifdef BEAMCAST_MULTIVIEW
// Multi-view: one camera per view (layer). Each draw renders one view,
// `u_view`, into layer u_view of the array targets (through that layer's
// framebuffer); stages copy that view's entry into `cam` first (select_view).
// A uniform view index (rather than one drawn from gl_InstanceID or gl_Layer)
// keeps every branch on camera values uniform for the compiler.
layout(std140, binding = 0) uniform CameraBlocks { CameraData cams[BEAMCAST_MAX_VIEWS]; };
uniform int u_view;
CameraData cam;
void select_view(int view) { cam = cams[view]; }
int view_index() { return u_view; }
#define VIEW_SAMPLER sampler2DArray
#define VIEW_TEXEL(s, p) texelFetch(s, ivec3(p, u_view), 0)
#else
// A struct member of a std140 block has the layout its members would have
// directly in the block, so the CPU's CameraBlock serves both variants.
layout(std140, binding = 0) uniform CameraBlock { CameraData cam; };
void select_view(int view) {}
int view_index() { return 0; }
#define VIEW_SAMPLER sampler2D
#define VIEW_TEXEL(s, p) texelFetch(s, p, 0)
#endif

struct ViewRay {
  vec3 origin;
  vec3 dir;         // unit
  float t_min;      // ray distance of the near plane
  float t_max;      // ray distance of the far plane
  float cos_axis;   // dot(dir, forward): converts view depth to ray distance
};

bool is_orthographic() { return cam.cam_forward.w > 0.5; }

// The ray through window position `frag` (gl_FragCoord.xy: pixel centres at +0.5),
// the same formula as protocol/camera.cpp's camera_ray.
ViewRay view_ray(vec2 frag) {
  vec2 ndc = 2.0 * frag / cam.viewport.xy - 1.0;
  ViewRay r;
  float aspect = cam.cam_up.w;
  if (is_orthographic()) {
    float hh = cam.cam_right.w;
    r.origin = ndc.x * hh * aspect * cam.cam_right.xyz + ndc.y * hh * cam.cam_up.xyz;
    r.dir = cam.cam_forward.xyz;
    r.cos_axis = 1.0;
  } else {
    float th = cam.cam_right.w;
    r.origin = vec3(0.0);
    r.dir = normalize(cam.cam_forward.xyz + ndc.x * th * aspect * cam.cam_right.xyz +
                      ndc.y * th * cam.cam_up.xyz);
    r.cos_axis = dot(r.dir, cam.cam_forward.xyz);
  }
  r.t_min = cam.viewport.z / r.cos_axis;
  r.t_max = cam.viewport.w / r.cos_axis;
  return r;
}

// The camera-relative point at view depth z on the ray through window
// position `frag`: view_ray's origin + (z / cos_axis) dir without its
// normalization (perspective: z times the unnormalized direction, whose
// component along forward is 1). For passes that place many G-buffer points.
vec3 view_point(vec2 frag, float z) {
  vec2 ndc = 2.0 * frag / cam.viewport.xy - 1.0;
  vec3 across = ndc.x * cam.cam_up.w * cam.cam_right.xyz + ndc.y * cam.cam_up.xyz;
  if (is_orthographic()) return cam.cam_right.w * across + z * cam.cam_forward.xyz;
  return z * (cam.cam_forward.xyz + cam.cam_right.w * across);
}

// Reversed-Z window depth of a point at view depth z (z > 0 along forward).
float window_depth(float z) {
  float n = cam.viewport.z, f = cam.viewport.w;
  if (is_orthographic()) return (f - z) / (f - n);
  return (n * f / z - n) / (f - n);
}

// Lambert shading; n is flipped to face the viewer (two-sided surfaces).
vec3 lambert(vec3 albedo, vec3 n, vec3 view_dir) {
  if (dot(n, view_dir) > 0.0) n = -n;
  float diffuse = max(0.0, dot(n, cam.light_dir.xyz));
  return albedo * cam.light_color.rgb * (cam.light_dir.w + cam.light_color.w * diffuse);
}
