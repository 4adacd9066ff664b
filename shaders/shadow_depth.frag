// The stored depth is the distance to the direct point over u_far (not the
// projected depth), so the lookup compares distances along any direction.
in vec3 v_rel;
uniform float u_far;

void main() { gl_FragDepth = length(v_rel) / u_far; }
