#version 430
// One frame's far-field measure from the two shown sets' own (FarFieldLayer.prepare): every value measured
// of A alone and of B alone, each once per simulation step, mixed at the frame's t. The cover, the
// transitions and every per-rank mean mix linearly; the column-sum quantiles mix rank by rank (the
// displacement interpolation of the two distributions: its mean column is mix(A's, B's, t) exactly, the
// mean of the columns of mix(A, B, t)). Invocation (x, y) mixes texel (x, y) of every texture that has
// it, and the flat index y * 32 + x of the cover buffer.
layout(local_size_x = 32, local_size_y = 4) in;
#ifndef PROFILE
#define PROFILE 0       // the volume's shape by rank (while the ray march draws the far field)
#endif
#ifndef LIGHT
#define LIGHT 0         // its light by rank (while a far field is drawn)
#endif
#ifndef FIELD
#define FIELD 0         // and the diffusion field's (both sets carry one)
#endif
const int COVER_FLOATS = 35;        // cover, 33 column quantiles, transitions (cover.comp's Cover)
layout(std430, binding = 0) writeonly buffer Cover { float mixed[]; };
layout(std430, binding = 1) readonly buffer CoverA { float cover_a[]; };
layout(std430, binding = 2) readonly buffer CoverB { float cover_b[]; };
uniform float t;
#if PROFILE
layout(binding = 0) uniform sampler2D profile_a;
layout(binding = 1) uniform sampler2D profile_b;
layout(rg32f, binding = 0) writeonly uniform image2D column_profile;
#endif
#if LIGHT
layout(binding = 2) uniform sampler2D sun_a;
layout(binding = 3) uniform sampler2D sun_b;
layout(binding = 4) uniform sampler2D thickness_a;
layout(binding = 5) uniform sampler2D thickness_b;
layout(binding = 6) uniform sampler2D height_a;
layout(binding = 7) uniform sampler2D height_b;
layout(binding = 8) uniform sampler2D sun_profile_a;
layout(binding = 9) uniform sampler2D sun_profile_b;
layout(rgba32f, binding = 1) writeonly uniform image2D sun_by_rank;
layout(r32f, binding = 2) writeonly uniform image2D thickness_by_rank;
layout(r32f, binding = 3) writeonly uniform image2D height_by_rank;
layout(rgba32f, binding = 4) writeonly uniform image2D sun_profile;
#endif
#if FIELD
layout(binding = 10) uniform sampler2D field_a;
layout(binding = 11) uniform sampler2D field_b;
layout(binding = 12) uniform sampler2D field_profile_a;
layout(binding = 13) uniform sampler2D field_profile_b;
layout(rgba32f, binding = 5) writeonly uniform image2D field_column;
layout(rgba32f, binding = 6) writeonly uniform image2D field_profile;
#endif

#define MIX(image, a, b) if (all(lessThan(p, imageSize(image)))) \
    imageStore(image, p, mix(texelFetch(a, p, 0), texelFetch(b, p, 0), t))

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    int flat_index = p.y * 32 + p.x;
    if (flat_index < COVER_FLOATS)
        mixed[flat_index] = mix(cover_a[flat_index], cover_b[flat_index], t);
#if PROFILE
    MIX(column_profile, profile_a, profile_b);
#endif
#if LIGHT
    MIX(sun_by_rank, sun_a, sun_b);
    MIX(thickness_by_rank, thickness_a, thickness_b);
    MIX(height_by_rank, height_a, height_b);
    MIX(sun_profile, sun_profile_a, sun_profile_b);
#endif
#if FIELD
    MIX(field_column, field_a, field_b);
    MIX(field_profile, field_profile_a, field_profile_b);
#endif
}
