#version 450 core
// Evaluates the generated GLSL SH basis at a list of directions (for the test that holds it to the
// C++ basis).
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Directions { vec4 directions[]; };
layout(std430, binding = 1) writeonly buffer Values { float values[]; };
uniform int u_count;
void main() {
  int i = int(gl_GlobalInvocationID.x);
  if (i >= u_count) return;
  float Y[SH_K];
  sh_eval(directions[i].xyz, Y);
  for (int k = 0; k < SH_K; ++k) values[i * SH_K + k] = Y[k];
}
