#version 430
// The aerial perspective's froxel volume (SkySettings.aerial_froxels; Hillaire 2020's camera volume):
// one invocation per froxel column marches the view ray through its centre, uv = ((x, y) + 0.5) / (W, H),
// slice by slice out to the distances of the slices' centres (sky/aerial_slices.glsl), one segment per
// slice sampled at its middle (sky/atmosphere.glsl atm_segment), stopping where the ray leaves the air.
// Texel z holds what varies slowly along the ray: (L / (1 - T), -ln(T) / path), the light per unit of
// opacity (the air's colour; L the in-scattered light, T the mean RGB transmittance) and the mean
// extinction over the path taken (the slice's distance, or the ray's end if nearer). sky/aerial.comp
// reads it trilinearly at (uv, aerial_slice_w(distance)) and rebuilds T = exp(-a distance),
// L = rgb (1 - T): the march's own values at the slices, and a ray nearer than the first slice keeps
// its colour and extinction (L and 1 - T fall to 0 with the distance). float64 reference:
// plugins/sky/atmosphere.py aerial_perspective (tests and benchmarks/bench_sky.py compare with its
// 96-step march).
// view_basis, sun_dir: the frame block (lib/frame.glsl)
#include "lib/frame.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(rgba32f, binding = 0) writeonly uniform image3D aerial_volume;
uniform float view_r;          // the camera's radius from the planet's centre
uniform float aerial_range;    // m: the last slice's reach (plugins/sky/aerial.py volume_range)
#include "lib/view_ray.glsl"
#include "sky/atmosphere.glsl"
#include "sky/aerial_slices.glsl"

void main() {
    ivec3 size = imageSize(aerial_volume);
    ivec2 c = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(c, size.xy))) return;
    vec3 dir = view_ray_dir((vec2(c) + 0.5) / vec2(size.xy), view_basis);
    float r = atm_clamp_radius(view_r), end = atm_ray_end(r, dir.y), nu = dot(dir, sun_dir);
    vec3 radiance = vec3(0.0), transfer = vec3(0.0), throughput = vec3(1.0);
    vec2 phases = atm_phases(nu, false);
    float t = 0.0;
    for (int z = 0; z < size.z; ++z) {
        float d = min(aerial_slice_distance((float(z) + 0.5) / float(size.z), aerial_range), end);
        if (d > t) atm_segment(r, dir.y, sun_dir.y, nu, t, d, phases, false, radiance, transfer, throughput);
        t = max(t, d);
        float T = dot(throughput, vec3(1.0 / 3.0)), opacity = 1.0 - T;
        vec3 light = radiance * atm_sun;
        imageStore(aerial_volume, ivec3(c, z), vec4(opacity > 1e-7 ? light / opacity : vec3(0.0),
                                                    -log(max(T, 1e-30)) / max(t, 1e-3)));
    }
}
