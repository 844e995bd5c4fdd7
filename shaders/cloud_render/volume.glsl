// The cloud volume as the renderers see it: density and transmittance toward the sun, each
// mix(A, B, t) of the two latest completed steps, and the light model sun × T + ambient.
layout(binding = 0) uniform sampler3D density_a;
layout(binding = 1) uniform sampler3D density_b;
layout(binding = 2) uniform sampler3D trans_a;       // at the shading scale; same texture coordinates
layout(binding = 3) uniform sampler3D trans_b;
uniform float t;
uniform int has_shading;       // 0: no transmittance textures, T = 1
uniform vec3 sun_color;        // already 0 with the sun below the horizon
uniform vec3 ambient;

float cloud_density(vec3 uvw) {
    return mix(textureLod(density_a, uvw, 0.0).r, textureLod(density_b, uvw, 0.0).r, t);
}

vec3 cloud_light(vec3 uvw) {
    float T = has_shading == 0 ? 1.0 : mix(textureLod(trans_a, uvw, 0.0).r, textureLod(trans_b, uvw, 0.0).r, t);
    return sun_color * T + ambient;
}
