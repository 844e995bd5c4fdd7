// A coarse image (half the size, rounded up) read at a fine pixel: per axis a 3-tap tent of bilinear
// samples, i.e. coarse texels m-1, m, m+1 weighted (5, 10, 1)/16 for fine 2m and (1, 10, 5)/16 for
// 2m+1, clamped to the edge; 9 exact fetches, no filter hardware (float64 twin:
// plugins/physical_camera/reference.py up). The bloom's upsampling chain and the present use it.
#ifndef UPSAMPLE2X_INCLUDED
#define UPSAMPLE2X_INCLUDED
vec3 upsample2x_weights(int i) {
    return (i & 1) == 0 ? vec3(5.0, 10.0, 1.0) / 16.0 : vec3(1.0, 10.0, 5.0) / 16.0;
}

vec3 upsample2x(sampler2D coarse, ivec2 fine) {
    ivec2 last = textureSize(coarse, 0) - 1;
    ivec2 m = fine >> 1;
    vec3 wx = upsample2x_weights(fine.x), wy = upsample2x_weights(fine.y);
    vec3 sum = vec3(0.0);
    for (int j = 0; j < 3; ++j) {
        int y = clamp(m.y + j - 1, 0, last.y);
        vec3 row = vec3(0.0);
        for (int i = 0; i < 3; ++i) row += wx[i] * texelFetch(coarse, ivec2(clamp(m.x + i - 1, 0, last.x), y), 0).rgb;
        sum += wy[j] * row;
    }
    return sum;
}
#endif
