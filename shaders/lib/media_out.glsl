// A local medium's (light, transmittance) also onto "media_light" and "media_transmittance" (atmos/
// composition.py) when LOCAL_MEDIA is 1: blended like the colour (ONE, SRC_ALPHA) onto targets cleared to
// 0 and 1, so they hold the local media composited, which the aerial perspective mixes the air with.
#ifndef LOCAL_MEDIA
#define LOCAL_MEDIA 0
#endif
#if LOCAL_MEDIA
layout(location = 1) out vec4 media_light;
layout(location = 2) out vec4 media_transmittance;
#endif

void write_media(vec4 medium) {
#if LOCAL_MEDIA
    media_light = medium;
    media_transmittance = vec4(0.0, 0.0, 0.0, medium.a);     // blended: T_target = 0 + T · T_target
#endif
}
