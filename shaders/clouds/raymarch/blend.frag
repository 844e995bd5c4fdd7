#version 430
// Full-res ray-marched clouds onto the frame, blended ONE, ONE_MINUS_SRC_ALPHA: premultiplied colour
// to attachment 0, (a·distance, a) to attachment 1 ("cloud_distance", when it is attached).
layout(binding = 0) uniform sampler2D clouds;
layout(binding = 1) uniform sampler2D cloud_distance;
out vec4 frag;
layout(location = 1) out vec4 frag_distance;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    frag = texelFetch(clouds, pixel, 0);
    vec2 d = texelFetch(cloud_distance, pixel, 0).rg;
    frag_distance = vec4(d, 0.0, d.y);
}
