// Proxy geometry of one beam per instance: the back faces of the box around it.
// Drawn with front faces culled and depth clamping on, every pixel whose ray
// meets the box gets exactly one fragment, also when the camera is inside the
// box and when the box reaches past the near or far plane.

struct BeamData {
  vec4 p0_radius;    // xyz: centre (sphere) or p0 (capsule), camera-relative; w: radius
  vec4 axis_length;  // xyz: unit axis p0 -> p1; w: length (0 for a sphere)
  vec4 color_layer;  // rgb: color * intensity; w: table layer of the density
  vec4 caps_kind;    // x: cap at p0, y: cap at p1 (1 or 0); z: 0 sphere, 1 capsule
  vec4 density;      // x: DensityKind, y: gaussian sigma, z: 1 full-screen (the
                     // eye inside or near the box: beam_proxy_full_screen)
};
layout(std430, binding = 1) readonly buffer Beams { BeamData beams[]; };

flat out int v_beam;
#ifdef BEAMCAST_MULTIVIEW
uniform int u_view_beams;  // beams per view; view v's copies start at v * u_view_beams
#endif

// Cube corners (bit 0: x, bit 1: y, bit 2: z) of 12 triangles, counter-clockwise
// seen from outside.
const int kCubeIndex[36] = int[36](4, 6, 2, 4, 2, 0, 1, 3, 7, 1, 7, 5, 0, 1, 5, 0, 5, 4,
                                   6, 7, 3, 6, 3, 2, 2, 3, 1, 2, 1, 0, 4, 5, 7, 4, 7, 6);

void main() {
  int index = gl_InstanceID;
#ifdef BEAMCAST_MULTIVIEW
  select_view(u_view);
  index += u_view * u_view_beams;
#endif
  BeamData b = beams[index];
  v_beam = index;
  if (b.density.z > 0.5) {
    // One clockwise triangle over the whole viewport (front faces are
    // culled), the other 11 collapsed to a point.
    vec2 corner = gl_VertexID == 1 ? vec2(-1.0, 3.0) : gl_VertexID == 2 ? vec2(3.0, -1.0)
                                                                        : vec2(-1.0);
    gl_Position = vec4(corner, 0.5, 1.0);
    return;
  }
  int ci = kCubeIndex[gl_VertexID];
  vec3 c = vec3((ci & 1) != 0 ? 1.0 : -1.0, (ci & 2) != 0 ? 1.0 : -1.0, (ci & 4) != 0 ? 1.0 : -1.0);
  float r = b.p0_radius.w;
  vec3 pos;
  if (b.caps_kind.z < 0.5) {
    pos = b.p0_radius.xyz + r * c;
  } else {
    // Right-handed frame (u1, u2, w) keeps the cube's winding.
    vec3 w = b.axis_length.xyz;
    vec3 helper = abs(w.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
    vec3 u1 = normalize(cross(helper, w));
    vec3 u2 = cross(w, u1);
    float lo = b.caps_kind.x > 0.5 ? -r : 0.0;
    float hi = b.axis_length.w + (b.caps_kind.y > 0.5 ? r : 0.0);
    float along = mix(lo, hi, 0.5 * (c.z + 1.0));
    pos = b.p0_radius.xyz + along * w + r * (c.x * u1 + c.y * u2);
  }
  gl_Position = cam.view_proj * vec4(pos, 1.0);
}
