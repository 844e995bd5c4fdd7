#version 430
// One seamlessly tiling octave of 2D value noise (atmos/tile_octaves.py; dynamic-2d-clouds-iq.txt): 4D noise on two
// circles, u -> (cos, sin)(2πu) and v -> (cos, sin)(2πv) of radius frequency/2π, so the texture repeats
// with period 1 and has `frequency` noise cells across. Channel c holds the noise channel_steps[c]
// light steps toward the sun (uv + channel_steps[c] * light_shift): one fetch gives all four samples
// (the sky layer's light march: 0, 1, 2, 3; the far field's relief: OctaveTextures.bake's steps).
#include "lib/hash.glsl"
#include "lib/value_noise.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba32f) uniform writeonly image2D octave;
uniform float frequency;
uniform uint key;
uniform vec2 light_shift;
uniform vec4 channel_steps;

const float TAU = 6.283185307179586;

float tile_noise(vec2 uv, float radius) {
    vec2 a = TAU * uv;
    return value_noise4(radius * vec4(cos(a.x), sin(a.x), cos(a.y), sin(a.y)), key);
}

void main() {
    ivec2 size = imageSize(octave);
    ivec2 cell = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(cell, size))) return;
    vec2 uv = vec2(cell) / vec2(size);
    float radius = frequency / TAU;
    vec4 v;
    for (int c = 0; c < 4; ++c) v[c] = tile_noise(uv + channel_steps[c] * light_shift, radius);
    imageStore(octave, cell, v);
}
