#version 430
// Test shader: the error is inside the included file, at its line 4.
layout(local_size_x = 1) in;
#include "test/broken_lib.glsl"
void main() { helper(); }
