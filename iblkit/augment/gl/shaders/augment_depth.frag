#version 450 core
// A shadow map's texel: the linear distance from the light (local) or along its direction (distant).
in vec3 v_position;
in vec3 v_normal;
uniform vec3 u_map_eye, u_map_dir;
uniform int u_map_local;
layout(location = 0) out float o_distance;
void main() { o_distance = u_map_local != 0 ? length(v_position - u_map_eye) : dot(u_map_eye - v_position, u_map_dir); }
