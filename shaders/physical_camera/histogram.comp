#version 430
// The frame's luminance histogram (float64 twin: plugins/physical_camera/reference.py histogram):
// bin 0 below the metering range (and black), bins 1 .. BINS-1 the range's EV100 in equal steps, the
// last also above it. Each group of 16 x 16 pixels counts in shared memory, then adds its non-empty
// bins to the buffer (cleared when the graph creates it).
layout(local_size_x = 16, local_size_y = 16) in;
const int BINS = 256;             // = the group's size: one bin per invocation
const float EV_OFFSET = 3.0;      // log2(100 / 12.5): EV100 = log2(L) + 3
layout(binding = 0) uniform sampler2D hdr;
layout(std430, binding = 0) buffer Histogram { uint counts[BINS]; };
uniform vec2 ev_range;            // (lowest, highest) EV100 the bins span
shared uint local_counts[BINS];

void main() {
    uint i = gl_LocalInvocationIndex;
    local_counts[i] = 0u;
    barrier();
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (all(lessThan(pixel, textureSize(hdr, 0)))) {
        float l = dot(texelFetch(hdr, pixel, 0).rgb, vec3(0.2126, 0.7152, 0.0722));
        float ev = log2(l) + EV_OFFSET;
        int bin = 0;
        if (ev >= ev_range.x)     // false for black (-inf) and NaN
            bin = 1 + int(min(floor((ev - ev_range.x) / (ev_range.y - ev_range.x) * float(BINS - 1)), float(BINS - 2)));
        atomicAdd(local_counts[bin], 1u);
    }
    barrier();
    if (local_counts[i] > 0u) atomicAdd(counts[i], local_counts[i]);
}
