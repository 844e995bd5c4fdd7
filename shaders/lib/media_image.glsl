// A local medium's (light, transmittance) composited by a compute pass, one invocation per pixel:
// colour.rgb = light + T · colour.rgb, its alpha (the sky occlusion, atmos/render_core.py) kept — what
// the raster passes' blend (ONE, SRC_ALPHA; alpha ZERO, ONE) does. LOCAL_MEDIA 1: the same onto
// "media_light" and "media_transmittance" (atmos/composition.py; lib/media_out.glsl is the raster twin);
// 2: the medium is the first and only one, which makes those targets: (L, T) stored, what blending onto
// their clear (0, 1) gives.
#ifndef LOCAL_MEDIA
#define LOCAL_MEDIA 0
#endif
layout(binding = 0, rgba16f) uniform image2D color_image;
#if LOCAL_MEDIA == 2
layout(binding = 1, rgba32f) writeonly uniform image2D media_light_image;
layout(binding = 2, r32f) writeonly uniform image2D media_transmittance_image;
#elif LOCAL_MEDIA
layout(binding = 1, rgba32f) uniform image2D media_light_image;
layout(binding = 2, r32f) uniform image2D media_transmittance_image;
#endif

// c: the colour at the pixel, loaded by a caller that needed it already.
void blend_medium(ivec2 pixel, vec4 medium, vec4 c) {
    imageStore(color_image, pixel, vec4(medium.rgb + medium.a * c.rgb, c.a));
#if LOCAL_MEDIA == 2
    imageStore(media_light_image, pixel, medium);
    imageStore(media_transmittance_image, pixel, vec4(medium.a));
#elif LOCAL_MEDIA
    vec4 l = imageLoad(media_light_image, pixel);
    imageStore(media_light_image, pixel, medium + medium.a * l);
    float t = imageLoad(media_transmittance_image, pixel).r;
    imageStore(media_transmittance_image, pixel, vec4(medium.a * t));
#endif
}

void blend_medium(ivec2 pixel, vec4 medium) {
    blend_medium(pixel, medium, imageLoad(color_image, pixel));
}
