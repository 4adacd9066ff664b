// The edge correction's share (pass "photons", drawn before the splats,
// with gi.edge_correction): for each splat pixel, the kernel-weighted share
// of its disk (radius r, in its tangent plane, about the G-buffer point it
// stands for) that lies on its own surface, added into the splat target's
// alpha (the splats add only to rgb). Where the disk hangs over a surface's
// edge or into a corner, the photons of the missing part are missing from
// the sum; gi_resolve divides each splat pixel's sum by its share, which
// removes that bias for locally even light. Made per splat pixel, at the
// point the splats were summed for, so the upsampling brings corrected sums
// (made per render pixel, the correction over-corrected values the
// upsampling had pulled from further inside: 1.08 at splat_scale 2 on the
// GL test's edge band). The share is found in the G-buffer at 48 points of
// the disk (4 rings of 12), each projected into the image:
//   - the pixel shows a quad light: not covered (the light stops the photons
//     of what lies behind it);
//   - the pixel shows the same surface (the splats' normal and plane tests):
//     covered;
//   - no surface, or the visible surface lies behind the point by more than
//     the plane tolerance (the point floats past an edge): not covered;
//   - the visible surface is in front of the point: not covered if its
//     plane separates the point from x (a concave corner: the wall's disk
//     reaches under the floor), else unknown, counted as covered (something
//     in front hides the rest of x's surface);
//   - off the image: unknown, covered.
// A band's texel plus u_band_shift is its splat-grid texel (render/pass_plan.hpp,
// SplatBands; the pass draws once per band).
uniform ivec2 u_band_shift;
uniform int u_splat_scale;  // this target has 1/u_splat_scale of the G-buffer's pixels per side

layout(location = 0) out vec4 out_color;

void main() {
  select_view(view_index());
  // The G-buffer pixel this splat pixel stands for (as photon_splat.frag).
  ivec2 px = min((ivec2(gl_FragCoord.xy) + u_band_shift) * u_splat_scale + u_splat_scale / 2,
                 ivec2(cam.viewport.xy) - 1);
  float z = VIEW_TEXEL(u_view_depth, px).r;
  if (z >= 1e29 || VIEW_TEXEL(u_gb_albedo, px).w > 0.5) discard;  // no photons there
  vec3 n = VIEW_TEXEL(u_gb_normal, px).xyz;
  out_color = vec4(0.0, 0.0, 0.0, disk_share(surface_point(px, z), n));
}
