#version 450 core
// Depth-only: nothing to write.
void main() {}
