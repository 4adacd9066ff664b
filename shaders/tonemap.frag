// HDR energy -> display values: exposure, tone curve, sRGB, quantized to the
// output's bit depth here so the fixed-point store is exact. Mirrors
// render/image.cpp's tone_map (the CPU reference's tone mapping).
layout(binding = 0) uniform VIEW_SAMPLER u_hdr;
uniform float u_exposure;
uniform int u_curve;     // 0 exponential 1 - exp(-x), 1 reinhard x / (1 + x), 2 clamp
uniform float u_levels;  // 255 or 65535

layout(location = 0) out vec4 out_color;

float srgb_encode(float c) {
  return c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

float tone(float x) {
  if (u_curve == 0) return 1.0 - exp(-x);
  if (u_curve == 1) return x / (1.0 + x);
  return min(x, 1.0);
}

void main() {
  vec3 e = VIEW_TEXEL(u_hdr, ivec2(gl_FragCoord.xy)).rgb;
  vec3 c;
  for (int i = 0; i < 3; ++i) c[i] = srgb_encode(clamp(tone(u_exposure * max(e[i], 0.0)), 0.0, 1.0));
  out_color = vec4(floor(c * u_levels + 0.5) / u_levels, 1.0);
}
