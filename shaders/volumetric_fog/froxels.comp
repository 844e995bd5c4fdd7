#version 430
// The volumetric fog's froxel volume (VolumetricFogSettings.froxels = (W, H, D)): one invocation per
// froxel column marches the view ray through its centre, uv = ((x, y) + 0.5) / (W, H), slice by slice
// (lib/froxel_slices.glsl, out to max_distance), one sample per slice in the part of the slice inside the
// medium's bounding ellipsoid, at the share froxel_jitter of it (0.5: the middle; it moves every frame and
// core/froxel_history.comp averages the frames) — the per-pixel march (volumetric_fog/medium.glsl fog_march) with the slices as its steps. Layer k holds (in-scattered light, transmittance) from the
// camera to slice boundary k (layer 0: the camera, (0, 0, 0, 1)); froxel_apply.comp reads it
// trilinearly. The camera is the frame block's (lib/frame.glsl). float64 twin: plugins/volumetric_fog/reference.py
// froxel_volume.
#include "lib/hash.glsl"
#include "lib/value_noise.glsl"
#include "lib/view_ray.glsl"
#include "lib/froxel_slices.glsl"
#include "volumetric_fog/medium.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba16f) writeonly uniform image3D fog_volume;
uniform float froxel_knee;     // m: slices are nearly even inside it, logarithmic beyond
uniform int froxel_jittered;   // whether the slices' samples move with the frame block's frame_index
                               // (lib/froxel_slices.glsl froxel_jitter; 0: the middles)

void main() {
    ivec3 size = imageSize(fog_volume);
    ivec2 c = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(c, size.xy))) return;
    vec3 dir = view_ray_dir((vec2(c) + 0.5) / vec2(size.xy), view_basis);
    vec2 range = fog_range(camera_pos, dir, max_distance);
    int slices = size.z - 1;
    vec3 light = vec3(0.0);
    float trans = 1.0;
    imageStore(fog_volume, ivec3(c, 0), vec4(light, trans));
    float d0 = 0.0, jitter = froxel_jitter(frame_index, froxel_jittered != 0);
    for (int z = 1; z <= slices; ++z) {
        float d1 = froxel_distance(float(z) / float(slices), max_distance, froxel_knee);
        float a = max(d0, range.x), b = min(d1, range.y);
        if (b > a && trans > 0.01) {
            vec3 p = camera_pos + dir * mix(a, b, jitter);
            float d = fog_density(p);
            if (d > 0.0) {
                float step_t = exp(-absorption * d * (b - a));
                light += trans * (1.0 - step_t) * (ambient_light + sun_light * fog_sun_transmittance(p));
                trans *= step_t;
            }
        }
        imageStore(fog_volume, ivec3(c, z), vec4(light, trans));
        d0 = d1;
    }
}
