#version 450 core
#extension GL_ARB_shader_viewport_layer_array : require
// Depth-only pass into every layer of a shadow-map array in one instanced draw: instance i draws
// the mesh into layer i with light matrix i (no framebuffer switch or clear per light).
layout(location = 0) in vec3 a_position;
layout(std430, binding = 11) readonly buffer LayerMatrices { mat4 layer_matrices[]; };
void main() {
  gl_Layer = gl_InstanceID;
  gl_Position = layer_matrices[gl_InstanceID] * vec4(a_position, 1.0);
}
