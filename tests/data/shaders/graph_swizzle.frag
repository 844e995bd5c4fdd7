#version 430
// Render-graph test: copies `src` texel by texel as (b, r, 2g, 1).
layout(binding = 0) uniform sampler2D src;
out vec4 frag;
void main() {
    vec4 c = texelFetch(src, ivec2(gl_FragCoord.xy), 0);
    frag = vec4(c.b, c.r, 2.0 * c.g, 1.0);
}
