#version 430
// Depth of the low-resolution cloud target: the farthest scene depth in each factor × factor block,
// so a sprite seen through any pixel of the block is drawn there (the composite sorts out edges).
layout(binding = 0) uniform sampler2D scene_depth;
uniform int factor;

void main() {
    ivec2 last = textureSize(scene_depth, 0) - 1;
    ivec2 base = ivec2(gl_FragCoord.xy) * factor;
    float d = 0.0;
    for (int j = 0; j < factor; ++j)
        for (int i = 0; i < factor; ++i)
            d = max(d, texelFetch(scene_depth, min(base + ivec2(i, j), last), 0).r);
    gl_FragDepth = d;
}
