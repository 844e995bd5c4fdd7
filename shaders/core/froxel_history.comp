#version 430
// A froxel volume's temporal accumulation (atmos/froxels.py FroxelHistory), one invocation per froxel
// boundary (x, y, k): its point P = camera + dir(x, y) d_k is projected into the previous frame's view
// (prev_basis, prev_origin) and the accumulated volume read there trilinearly (lib/froxel_slices.glsl
// froxel_read); the fresh value of this frame's jittered slices is blended in with weight
//   w = max(blend, min(moved / (d_k - d_k-1), 1))   (moved: how far the camera went, m),
// so a still camera averages its jitters and a moving one trusts each slice's fresh value the more the
// farther it moved through it; where P was outside the previous view (or has_history is 0), w = 1.
// float64 twin: atmos/froxels.py history_reference.
#include "lib/frame.glsl"
#include "lib/froxel_slices.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(binding = 0) uniform sampler3D fresh;          // this frame's volume (texelFetch)
layout(binding = 1) uniform sampler3D history;        // the previous frame's output (linear, clamped)
layout(binding = 0, rgba16f) writeonly uniform image3D resolved;
layout(std140, binding = 1) uniform History {   // written once per frame (atmos/froxels.py HISTORY_BINDING)
    mat3 prev_basis;           // the previous frame's view_basis (lib/frame.glsl)
    vec3 prev_origin;          // the previous frame's camera position
    float moved;               // m the camera moved since the previous frame
    float froxel_range;        // m: the volume's last boundary
    float froxel_knee;
    float blend;               // the fresh value's least weight
    int has_history;
};

void main() {
    ivec3 size = imageSize(resolved);
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, size))) return;
    vec4 now = texelFetch(fresh, c, 0);
    float w = 1.0;
    if (has_history != 0 && c.z > 0) {
        float slices = float(size.z - 1);
        float d1 = froxel_distance(float(c.z) / slices, froxel_range, froxel_knee);
        float d0 = froxel_distance(float(c.z - 1) / slices, froxel_range, froxel_knee);
        vec3 dir = normalize(view_basis * vec3((vec2(c.xy) + 0.5) / vec2(size.xy) * 2.0 - 1.0, 1.0));
        vec3 q = inverse(prev_basis) * (camera_pos + dir * d1 - prev_origin);
        if (q.z > 0.0) {
            vec2 uv = (q.xy / q.z + 1.0) * 0.5;
            float d = length(camera_pos + dir * d1 - prev_origin);
            if (all(greaterThanEqual(uv, vec2(0.0))) && all(lessThanEqual(uv, vec2(1.0)))) {
                w = max(blend, min(moved / max(d1 - d0, 1e-6), 1.0));
                vec4 past = froxel_read(history, uv, d, froxel_range, froxel_knee);
                now = mix(past, now, w);
            }
        }
    }
    imageStore(resolved, c, now);
}
