#version 430
// Test shader for tests/test_frames.py: writes z-layers [z0, z0 + layers) of a 3D rgba32f image.
// x = step + 0.01 * x (linear in step: continuity test), y = a hash-like function of (x, y, z, step),
// z = feedback * previous.z + y (reads the previous result: naive vs sliced must agree), w = z index.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 1) in;
layout(rgba32f, binding = 0) uniform writeonly image3D dst;
layout(rgba32f, binding = 1) uniform readonly image3D src;
uniform int z0;
uniform float step_value;
uniform float feedback;
void main() {
    ivec3 p = ivec3(gl_GlobalInvocationID.xy, z0 + int(gl_GlobalInvocationID.z));
    ivec3 size = imageSize(dst);
    if (any(greaterThanEqual(p, size))) return;
    vec4 prev = imageLoad(src, p);
    float f = fract(sin(float(p.x) * 12.9898 + float(p.y) * 78.233 + float(p.z) * 37.719 + step_value * 4.581) * 43758.5453);
    imageStore(dst, p, vec4(step_value + 0.01 * float(p.x), f, feedback * prev.z + f, float(p.z)));
}
