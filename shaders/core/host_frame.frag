#version 430
// A frame the game drew itself, into atmos's HDR colour and depth (atmos.host_frame; numpy reference
// atmos.host_frame.host_frame_reference): colour as linear radiance (sRGB-decoded when SRGB is 1),
// alpha 1 where the game drew (depth < 1, the sky occlusion of atmos.render_core), its depth as it is.
in vec2 v_uv;
out vec4 frag;
layout(binding = 0) uniform sampler2D host_color;
layout(binding = 1) uniform sampler2D host_depth;

void main() {
    ivec2 c = ivec2(v_uv * vec2(textureSize(host_color, 0)));
    ivec2 d = ivec2(v_uv * vec2(textureSize(host_depth, 0)));
    float depth = texelFetch(host_depth, d, 0).r;
    vec3 rgb = texelFetch(host_color, c, 0).rgb;
#if SRGB
    rgb = mix(rgb / 12.92, pow((rgb + 0.055) / 1.055, vec3(2.4)), step(0.04045, rgb));
#endif
    frag = vec4(rgb, depth < 1.0 ? 1.0 : 0.0);
    gl_FragDepth = depth;
}
