#version 450 core
// A rendered frame to the screen: exposure scale, the tone curve of io::tonemap
// (iblkit/io/tonemap.cpp, formula for formula) and sRGB encoding. Pixel for pixel: the frame and the
// target have the same size and GL's bottom-up rows.
layout(binding = 0) uniform sampler2D u_frame;
uniform float u_scale;
uniform int u_curve;  // 0: clamp, 1: Reinhard on luminance, 2: ACES (Narkowicz 2015)
uniform vec3 u_luminance;  // the weights of ibl::luminance (core/vec.h)
out vec4 o_color;

vec3 aces(vec3 x) {
  const float a = 2.51, b = 0.03, c = 2.43, d = 0.59, e = 0.14;
  return clamp((x * (a * x + b)) / (x * (c * x + d) + e), 0.0, 1.0);
}

void main() {
  vec3 c = texelFetch(u_frame, ivec2(gl_FragCoord.xy), 0).rgb * u_scale;
  if (u_curve == 1) {
    float l = dot(c, u_luminance);
    if (l > 0.0) c /= 1.0 + l;
  } else if (u_curve == 2) {
    c = aces(c);
  }
  c = clamp(c, 0.0, 1.0);
  vec3 srgb = mix(1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, 12.92 * c, lessThanEqual(c, vec3(0.0031308)));
  o_color = vec4(srgb, 1.0);
}
