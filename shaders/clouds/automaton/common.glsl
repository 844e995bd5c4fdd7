// Shared declarations of the cloud automaton shaders (see plugins/automaton/automaton.py).
// Dispatch: 1D invocation index spread over a 2D grid of 64-wide groups.

#define PRECISION_BITS 16
#define PLANES 17            // threshold bit planes 0..16 (plane 16 set <=> T == 65536, p == 1)

uniform ivec3 u_size;        // nx, ny, nz (cells)
uniform int u_nwx;           // words per x row = ceil(nx / 32)
uniform uint u_count;        // invocations that do work (words or cells)

// Stochastic rules 0 extinction, 1 humidity, 2 activation.
// u_mode: 0 = rule off (p == 0 everywhere), 1 = scalar threshold u_threshold, 2 = per-cell array.
uniform uvec3 u_mode;
uniform uvec3 u_threshold;   // T = floor(p * 65536 + 0.5) in [0, 65536] for mode 1
// The random streams (seed, step, rule, plane) of the step (lib/hash.glsl atmos_step_key, hashed on the GPU).
uniform uint u_seed;
uniform uint u_step;
// Advection's shift (sx, sz) per layer y, a uniform (captured when the step is dispatched: a buffer
// updated per step raced the queued steps reading it on NVIDIA); automaton.py MAX_LAYERS.
#define MAX_LAYERS 128
uniform ivec2 u_shifts[MAX_LAYERS];

uint invocation_index() {
    return gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * (gl_NumWorkGroups.x * gl_WorkGroupSize.x);
}

// uint threshold of a float32 probability in [0, 1]: exact in float32 (p * 65536 < 2^23).
uint quantize(float p) {
    return uint(floor(p * 65536.0 + 0.5));
}
