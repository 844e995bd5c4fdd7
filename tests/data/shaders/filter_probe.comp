#version 430
// The texture unit's bilinear weight between two texels (values 0 and 1) at 4097 points from the first
// texel's centre to the second's: weight k / 4096 if it filters in float (conftest.py filter_bits).
layout(local_size_x = 1) in;
layout(binding = 0) uniform sampler2D s;
layout(std430, binding = 0) writeonly buffer Out { float v[]; };

void main() {
    uint k = gl_GlobalInvocationID.x;
    v[k] = textureLod(s, vec2(0.25 + 0.5 * float(k) / 4096.0, 0.5), 0.0).r;
}
