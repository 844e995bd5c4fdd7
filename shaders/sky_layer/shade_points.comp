#version 430
// Test helper: sky_layer_shade for `count` (fbm samples, fade) inputs into premultiplied (rgb·α, α) outputs.
#include "sky_layer/layer.glsl"
layout(local_size_x = 64) in;
struct Input { vec4 fbm; vec4 fade; };
layout(std430, binding = 0) readonly buffer Inputs { Input inputs[]; };
layout(std430, binding = 1) writeonly buffer Outputs { vec4 outputs[]; };
uniform uint count;
uniform float emptiness;
uniform float sharpness;
uniform float thickness;
uniform vec3 color;
uniform vec3 lit_color;
uniform vec3 light;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    outputs[i] = sky_layer_shade(inputs[i].fbm, emptiness, sharpness, thickness, color, lit_color, light,
                                 inputs[i].fade.x);
}
