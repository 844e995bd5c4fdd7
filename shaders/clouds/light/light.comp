#version 430
// Cloud light volume for the renderer (plugins/shading/scattering.py): rgb = sun_color * T + ambient, a = T.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(binding = 0) uniform sampler3D transmittance;
layout(RESULT_FORMAT, binding = 0) uniform writeonly image3D light;
uniform vec3 sun_color;
uniform vec3 ambient;

void main() {
    ivec3 n = imageSize(light);
    ivec3 i = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(i, n))) return;
    float t = texelFetch(transmittance, i, 0).r;
    imageStore(light, i, vec4(sun_color * t + ambient, t));
}
