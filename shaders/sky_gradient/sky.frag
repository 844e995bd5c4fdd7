#version 430
// Sky gradient: zenith/horizon blend, a glow round the sun and its disc along each pixel's view ray
// (float64 twin: plugins/sky_gradient/__init__.py gradient_sky).
// Alpha 0: open sky (color.a is the sky occlusion, atmos/render_core.py).
// view_basis, sun_dir, sun_color: the frame block (lib/frame.glsl)
#include "lib/frame.glsl"
#include "lib/view_ray.glsl"
#include "lib/sun_disc.glsl"
in vec2 v_uv;
out vec4 frag;
uniform vec3 zenith;
uniform vec3 horizon;
uniform vec3 ground;
uniform vec4 sun_look;         // (disc chord, gain, glare, radians per pixel): SkyGradientSettings' sun disc

void main() {
    vec3 dir = view_ray_dir(v_uv, view_basis);
    vec3 s = normalize(sun_dir);
    float up = dir.y;
    vec3 sky = mix(horizon, zenith, pow(clamp(up, 0.0, 1.0), 0.6));
    sky = mix(sky, ground, smoothstep(0.0, -0.08, up));
    float day = smoothstep(-0.15, 0.1, s.y);
    sky *= mix(0.05, 1.0, day);
    vec3 disc = sun_disc(dir, s, sun_look.x, sun_look.y, sun_look.z, sun_look.w) * (1.0 - smoothstep(0.0, -0.01, up));
    sky += sun_color * day * (0.25 * pow(max(dot(dir, s), 0.0), 32.0) + disc);
    frag = vec4(sky, 0.0);
}
