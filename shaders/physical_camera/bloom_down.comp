#version 430
// One bloom downsample (float64 twin: plugins/physical_camera/reference.py down): texel i of the half-size
// level takes the finer level's texels 2i-2 .. 2i+3 per axis (clamped), weighted (1, 5, 10, 10, 5, 1)/32:
// a smooth low-pass, 36 exact fetches (no filter hardware).
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D source;
layout(binding = 0, rgba16f) uniform writeonly image2D level;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(level)))) return;
    ivec2 last = textureSize(source, 0) - 1;
    const float w[6] = float[6](1.0, 5.0, 10.0, 10.0, 5.0, 1.0);
    vec3 sum = vec3(0.0);
    for (int j = 0; j < 6; ++j) {
        int y = clamp(2 * p.y + j - 2, 0, last.y);
        vec3 row = vec3(0.0);
        for (int i = 0; i < 6; ++i) row += w[i] * texelFetch(source, ivec2(clamp(2 * p.x + i - 2, 0, last.x), y), 0).rgb;
        sum += w[j] * row;
    }
    imageStore(level, p, vec4(sum / 1024.0, 1.0));     // a convex mix: never above the source's largest value
}
