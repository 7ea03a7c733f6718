#version 450 core
// Forward shading: every fragment runs shade() from shading.glsl (inserted by the renderer with the
// generated SH code before this file's body).
in vec3 v_position;
in vec3 v_normal;
out vec4 o_color;
uniform vec3 u_albedo;
uniform vec3 u_specular;
uniform float u_exponent;
uniform float u_glossy_zh[SH_BANDS];
uniform int u_glossy_layer;
float glossy_factor(int l) { return u_glossy_zh[l]; }
int glossy_layer() { return u_glossy_layer; }
void main() { o_color = vec4(shade(v_position, v_normal, u_albedo, u_specular, u_exponent), 1.0); }
