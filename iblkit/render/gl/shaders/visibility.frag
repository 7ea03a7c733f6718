#version 450 core
// Deferred path, pass 1: a visibility buffer — which triangle of which object covers the pixel
// (4 bytes a pixel). Shading happens in shade.comp on every SM of compute-oriented GPUs (an H100
// runs the fragment stage on a few graphics units only).
layout(location = 0) out uint o_id;  // (object + 1) << 24 | triangle; 0 = nothing
uniform uint u_object;
void main() { o_id = ((u_object + 1u) << 24) | uint(gl_PrimitiveID); }
