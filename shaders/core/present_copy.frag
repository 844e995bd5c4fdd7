#version 430
// The present pass's screen image drawn 1:1 onto a multisampled screen (a window's, which a framebuffer
// blit writes only from its own format): its bytes, exact levels, unchanged.
out vec4 frag;
layout(binding = 0) uniform sampler2D screen_image;

void main() {
    frag = texelFetch(screen_image, ivec2(gl_FragCoord.xy), 0);
}
