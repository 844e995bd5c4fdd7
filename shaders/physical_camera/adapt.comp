#version 430
// The camera's exposure for this frame (float64 twin: plugins/physical_camera/reference.py): METERED 1,
// the mean EV100 of the histogram's pixels between the metering filter's shares (a bin cut by a share
// counts by the part inside; one invocation per bin, a prefix sum and a sum in shared memory), less the
// compensation, clamped to the range, then the held EV100 moves toward it (adapt: exponential near the
// target, at most speed EV/s, at once on the first frame); METERED 0, the manual EV100. Writes the
// exposure 1 / (1.2 * 2^EV100) and the bloom's weight, which the present reads.
layout(local_size_x = 256) in;
#ifndef METERED
#define METERED 1
#endif
const int BINS = 256;
#include "lib/camera.glsl"
#if METERED
layout(std430, binding = 0) readonly buffer Histogram { uint counts[BINS]; };
uniform vec2 ev_range;
uniform vec2 metering_filter;     // (low, high) shares of the sorted pixels the mean leaves out below / keeps up to
uniform float compensation;       // EV: +1 makes the image twice as bright
uniform vec3 speed;               // (EV/s toward a higher EV, toward a lower, the exponential's span in EV)
uniform float dt;                 // seconds since the last frame
shared float cum[BINS];
shared vec2 sums[BINS];
#else
uniform float manual_ev100;
#endif
uniform float bloom_weight;

void main() {
    uint i = gl_LocalInvocationIndex;
#if METERED
    float n = float(counts[i]);
    cum[i] = n;
    barrier();
    for (uint stride = 1u; stride < uint(BINS); stride <<= 1) {       // inclusive prefix sum (Hillis-Steele)
        float add = i >= stride ? cum[i - stride] : 0.0;
        barrier();
        cum[i] += add;
        barrier();
    }
    float total = cum[BINS - 1];
    vec2 cut = metering_filter * total;
    float w = clamp(cum[i], cut.x, cut.y) - clamp(cum[i] - n, cut.x, cut.y);
    float width = (ev_range.y - ev_range.x) / float(BINS - 1);
    float center = i == 0u ? ev_range.x : ev_range.x + (float(i) - 0.5) * width;
    sums[i] = vec2(w * center, w);
    barrier();
    for (uint stride = uint(BINS) / 2u; stride > 0u; stride >>= 1) {
        if (i < stride) sums[i] += sums[i + stride];
        barrier();
    }
    if (i != 0u) return;
    float mean = sums[0].y > 0.0 ? sums[0].x / sums[0].y : ev_range.x;
    float goal = clamp(mean - compensation, ev_range.x, ev_range.y);
    float ev = goal;
    if (primed > 0.5) {
        float delta = goal - ev100;
        float s = delta > 0.0 ? speed.x : speed.y;
        ev = ev100 + sign(delta) * min(s * dt, abs(delta) * (1.0 - exp(-s * dt / speed.z)));
    }
    target = goal;
#else
    if (i != 0u) return;
    float ev = manual_ev100;
    target = ev;
#endif
    ev100 = ev;
    exposure = 1.0 / (1.2 * exp2(ev));
    bloom = bloom_weight;
    primed = 1.0;
}
