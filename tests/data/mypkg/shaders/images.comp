#version 430
// Images and a storage block bound by name at units 2, 5 and 3 (tests/test_shader_path.py).
layout(local_size_x = 1) in;
layout(binding = 2, r32f) uniform readonly image2D src;
layout(r32f, binding = 5) writeonly uniform image2D dst;
layout(std430, binding = 3) writeonly buffer Out { float values[]; };
void main() {
    float x = imageLoad(src, ivec2(0)).r;
    imageStore(dst, ivec2(0), vec4(2.0 * x));
    values[0] = x + 1.0;
}
