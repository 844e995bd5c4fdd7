// The 2D cloud layer's remap and shading (dynamic-2d-clouds-iq.txt); float64 reference in
// atmos/plugins/sky_layer/reference.py. fbm holds the four light-march samples (r = this point).
//   d      = (clamp(fbm, emptiness, sharpness) - emptiness) / (sharpness - emptiness)
//   amount = dot(max(d - (0, 0.2, 0.4, 0.6), 0), 1/4)
//   alpha  = clamp(thickness * amount, 0, 1) * fade;  rgb = mix(lit_color, color, amount) * light
// Returned premultiplied with its coverage, (rgb * alpha, alpha), composited over colour and alpha
// (lib/over.glsl): color.a then gains the layer's cover of the sky.

const vec4 SKY_LAYER_WEIGHTS = vec4(0.5, 0.25, 0.125, 0.0625);
const vec4 SKY_LAYER_RAY = vec4(0.0, 0.2, 0.4, 0.6);

vec4 sky_layer_remap(vec4 fbm, float emptiness, float sharpness) {
    return (clamp(fbm, emptiness, sharpness) - emptiness) / (sharpness - emptiness);
}

vec4 sky_layer_shade(vec4 fbm, float emptiness, float sharpness, float thickness,
                     vec3 color, vec3 lit_color, vec3 light, float fade) {
    vec4 d = sky_layer_remap(fbm, emptiness, sharpness);
    float amount = dot(max(d - SKY_LAYER_RAY, 0.0), vec4(0.25));
    float alpha = clamp(thickness * amount, 0.0, 1.0) * fade;
    vec3 rgb = mix(lit_color, color, amount) * light;
    return vec4(rgb * alpha, alpha);
}
