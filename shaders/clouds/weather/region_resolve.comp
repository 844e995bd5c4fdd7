#version 430
// Region volume, pass 2 of 2: writes every cell of the float 3D texture from the max buffer.
layout(local_size_x = 8, local_size_y = 8, local_size_z = 4) in;
layout(std430, binding = 3) readonly buffer Region { uint cells[]; };
layout(binding = 0, FORMAT) uniform writeonly image3D region;
uniform ivec3 size;

void main() {
    ivec3 q = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(q, size))) return;
    float v = uintBitsToFloat(cells[q.x + size.x * (q.y + size.y * q.z)]);
    imageStore(region, q, vec4(v, 0.0, 0.0, 0.0));
}
