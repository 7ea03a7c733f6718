#version 450 core
// The object (resolved from 4× MSAA: premultiplied radiance, coverage in alpha) over the proxy's composite;
// u_flip writes GL's rows (bottom up) for a window, else the photograph's rows.
uniform sampler2D u_proxy_composite, u_object, u_photo;
uniform int u_flip, u_height;
layout(location = 0) out vec4 o_color;
layout(location = 1) out vec4 o_difference;  // rgb: composite − photograph; a: the object's coverage
void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  if (u_flip != 0) px.y = u_height - 1 - px.y;
  vec4 o = texelFetch(u_object, px, 0);
  vec3 c = texelFetch(u_proxy_composite, px, 0).rgb * (1.0 - o.a) + o.rgb, p = texelFetch(u_photo, px, 0).rgb;
  o_color = vec4(c, 1.0);
  o_difference = vec4(c - p, o.a);
}
