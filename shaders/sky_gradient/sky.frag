#version 430
// Sky gradient: zenith/horizon blend, sun disc and glow along each pixel's view ray.
// Alpha 0: open sky (color.a is the sky occlusion, atmos/render_core.py).
// view_basis, sun_dir, sun_color: the frame block (lib/frame.glsl)
#include "lib/frame.glsl"
#include "lib/view_ray.glsl"
in vec2 v_uv;
out vec4 frag;
uniform vec3 zenith;
uniform vec3 horizon;
uniform vec3 ground;

void main() {
    vec3 dir = view_ray_dir(v_uv, view_basis);
    vec3 s = normalize(sun_dir);
    float up = dir.y;
    vec3 sky = mix(horizon, zenith, pow(clamp(up, 0.0, 1.0), 0.6));
    sky = mix(sky, ground, smoothstep(0.0, -0.08, up));
    float cosang = dot(dir, s);
    float day = smoothstep(-0.15, 0.1, s.y);
    sky *= mix(0.05, 1.0, day);
    sky += sun_color * day * (0.25 * pow(max(cosang, 0.0), 32.0) + 20.0 * smoothstep(0.9995, 0.9998, cosang));
    frag = vec4(sky, 0.0);
}
