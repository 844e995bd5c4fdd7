#version 430
// Light per-frame draw for benchmarks/bench_frame_pacing.py: a slice of mix(A, B, t).
layout(binding = 0) uniform sampler3D volume_a;
layout(binding = 1) uniform sampler3D volume_b;
uniform float t;
uniform float layer;
in vec2 v_uv;
out vec4 frag;
void main() {
    vec3 uvw = vec3(v_uv.x, layer, v_uv.y);
    frag = vec4(mix(texture(volume_a, uvw), texture(volume_b, uvw), t).rgb, 1.0);
}
