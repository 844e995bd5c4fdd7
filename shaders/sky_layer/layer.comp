#version 430
// The cloud layer on the sky, one compute invocation per pixel: where nothing was drawn (depth 1), the
// view ray meets the plane y = altitude; the four scrolling octaves give fbm (one fetch each, at the mip
// level of the pixel's footprint on the plane: lod_scale × distance / the ray's slope, as the far field's),
// shaded by sky_layer/layer.glsl; the premultiplied (light, coverage) is composited over the colour and
// its alpha (lib/over.glsl): the layer adds its cover to color.a, the sky occlusion (atmos/render_core.py).
// view_basis, camera_pos: the frame block (lib/frame.glsl)
#include "lib/frame.glsl"
#include "lib/view_ray.glsl"
#include "lib/over.glsl"
#include "sky_layer/layer.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba16f) uniform image2D color_image;
layout(binding = 0) uniform sampler2D octave0;
layout(binding = 1) uniform sampler2D octave1;
layout(binding = 2) uniform sampler2D octave2;
layout(binding = 3) uniform sampler2D octave3;
layout(binding = 4) uniform sampler2D scene_depth;
uniform vec2 offsets[4];       // scroll of each octave (tiles, wrapped to [0, 1))
uniform float altitude;
uniform float tile_size;
uniform float horizon_fade;
uniform float emptiness;
uniform float sharpness;
uniform float thickness;
uniform vec3 color;
uniform vec3 lit_color;
uniform vec3 light;
uniform float lod_scale;       // octave texels per metre × a pixel's angle (rad)

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(color_image);
    if (any(greaterThanEqual(px, size)) || texelFetch(scene_depth, px, 0).r < 1.0) return;
    vec3 dir = view_ray_dir((vec2(px) + 0.5) / vec2(size), view_basis);
    float t = (altitude - camera_pos.y) / max(dir.y, 1e-6);
    if (dir.y <= 1e-6 || t <= 0.0) return;             // no cover: colour and alpha kept
    vec2 uv = (camera_pos.xz - floor(camera_pos.xz / tile_size) * tile_size + dir.xz * t) / tile_size;
    float lod = log2(max(lod_scale * t / max(dir.y, 1e-3), 1e-6));
    vec4 fbm = SKY_LAYER_WEIGHTS.x * textureLod(octave0, uv + offsets[0], lod)
             + SKY_LAYER_WEIGHTS.y * textureLod(octave1, uv + offsets[1], lod)
             + SKY_LAYER_WEIGHTS.z * textureLod(octave2, uv + offsets[2], lod)
             + SKY_LAYER_WEIGHTS.w * textureLod(octave3, uv + offsets[3], lod);
    float fade = smoothstep(0.0, horizon_fade, dir.y);
    vec4 layer = sky_layer_shade(fbm, emptiness, sharpness, thickness, color, lit_color, light, fade);
    if (layer.a > 0.0) imageStore(color_image, px, over(layer, imageLoad(color_image, px)));
}
