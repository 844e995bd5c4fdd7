#version 430
// One text label (atmos.plugins.text): drawn with the viewport set to the label's pixel rectangle, so
// texel (x, y) of the glyph coverage (rows top-down, as rasterised) lands on pixel (x, y) of it.
// Straight alpha over the screen, which keeps its alpha; numpy reference: atmos.plugins.text.reference.
in vec2 v_uv;
out vec4 frag;
layout(binding = 0) uniform sampler2D coverage;
uniform vec4 color;     // display (sRGB) colour and opacity

void main() {
    ivec2 size = textureSize(coverage, 0);
    ivec2 p = min(ivec2(v_uv * vec2(size)), size - 1);
    float a = texelFetch(coverage, ivec2(p.x, size.y - 1 - p.y), 0).r * color.a;
    frag = vec4(color.rgb, a);
}
