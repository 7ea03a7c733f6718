#version 450 core
// Forward shading: every fragment runs shade() from shading.glsl (inserted by the renderer with the
// generated SH code before this file's body).
in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv;
out vec4 o_color;
uniform vec3 u_albedo;
uniform vec3 u_specular;
uniform float u_exponent;
uniform float u_glossy_zh[SH_BANDS];
uniform int u_glossy_layer;
uniform int u_albedo_layer;  // layer of the albedo texture in u_albedo_textures, or −1
uniform int u_lobe;          // 0: Phong, 1: Blinn-Phong
float glossy_factor(int l) { return u_glossy_zh[l]; }
int glossy_layer() { return u_glossy_layer; }
void main() {
  o_color = vec4(shade(v_position, v_normal, u_albedo * albedo_texture(v_uv, u_albedo_layer), u_specular, u_exponent, u_lobe), 1.0);
}
