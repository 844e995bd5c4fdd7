#version 430
// The diffusion field (plugins/clouds/light/diffusion.py; float64 twin: diffusion_system + solve_cg + field):
// a P1 solve of the sun's scattered fluence on the field's grid (the shading grid or coarser) by Jacobi-preconditioned conjugate
// gradients in Chronopoulos and Gear's form: ONE dispatch per iteration (its two inner products in one
// reduction). One invocation per cell (x fastest); per-cell vectors in `cells` (fields at multiples of
// n_cells; r, s = A p and w = A u twice, read at `cur` and written at 1 - cur), per-workgroup partial
// sums in `parts`. Every workgroup sums the partials in the same order, so all of them see the same
// scalars (no read-back, no host sync). w = A u needs the neighbours' new u, which their own
// invocations write in the same dispatch: each invocation recomputes them from the last iteration's
// r, s and w (pointwise), so no second dispatch waits on them.
// stage 0 assemble (x kept from the last solve unless cold), 1 init (r = b - A x), 2 init (u, w = A u),
// 3 iterate, 4 write (phi, F) into the rgba16f target. The iteration stops (stage 3 does nothing) once
// |r| <= tolerance |b| (it then sets the indirect group count to 0: later iterations cost nothing more).
layout(local_size_x = 256) in;
#include "clouds/light/sample.glsl"
layout(std140, binding = 1) uniform Step {   // one record per (stage, cur, first), bound per dispatch
    int stage;
    int cur;                  // which of the two copies of r, s, w and the partials is the current one
    int first;                // the first iteration after init: beta = 0
};
uniform int cold;             // init from x = 0
uniform ivec3 size;           // the shading grid
layout(binding = 0) uniform sampler3D fine;       // the density (fine cells)
uniform ivec3 fine_size;
layout(binding = 1) uniform sampler3D trans;      // the transmittance toward the sun on the shading grid
uniform ivec3 trans_size;     // the shading grid (the field's grid `size` may be coarser: diffusion.field_shape)
uniform float sigma_t, albedo, g, tolerance;
uniform vec3 cell;            // shading cell size, metres
uniform vec3 s;               // the direction the sunlight travels (-sun_dir), unit
layout(std430, binding = 0) buffer Cells { float cells[]; };
layout(std430, binding = 1) buffer Parts { float parts[]; };
layout(std430, binding = 2) buffer Args { uint args[3]; };   // stages 2 and 3 run indirect from it: 0 groups once converged
layout(rgba16f, binding = 0) uniform writeonly image3D target;
const float FLOOR = 1e-3;
const float SIGMA_MAX = 1e3;  // diffusion.SIGMA_MAX
const float AIR_DEPTH = 1.0;  // diffusion.AIR_DEPTH
const int X = 0, P = 1, R = 2, S = 4, W = 6, DIAG = 8, RHS = 9, GX = 10, GY = 11, GZ = 12, DC = 13, QC = 14;
// (R, S and W hold two copies each: field R + cur)
shared vec3 red[256];
shared vec4 sums;

int n_cells() { return size.x * size.y * size.z; }
float at(int field, int i) { return cells[field * n_cells() + i]; }
void put(int field, int i, float v) { cells[field * n_cells() + i] = v; }
int groups_n() { return int(gl_NumWorkGroups.x); }

// The sums over all workgroups of parts[o[k] + w], k = 0..3, summed in one order by one invocation, the
// same in every workgroup (few barriers: they dominate a dispatch's cost on a CPU driver).
vec4 totals(ivec4 o) {
    if (gl_LocalInvocationID.x == 0u) {
        vec4 a = vec4(0.0);
        for (int w = 0; w < groups_n(); ++w)
            a += vec4(parts[o.x + w], parts[o.y + w], parts[o.z + w], parts[o.w + w]);
        sums = a;
    }
    barrier();
    return sums;
}

// Writes this workgroup's sums of v.x, v.y, v.z into parts[o.x|y|z + workgroup] (o < 0: not kept).
void partials(ivec3 o, vec3 v) {
    uint l = gl_LocalInvocationID.x;
    red[l] = v;
    barrier();
    if (l == 0u) {
        vec3 a = vec3(0.0);
        for (int k = 0; k < 256; ++k) a += red[k];
        int w = int(gl_WorkGroupID.x);
        for (int k = 0; k < 3; ++k)
            if (o[k] >= 0) parts[o[k] + w] = a[k];
    }
}

int RU(int which) { return which * groups_n(); }              // gamma = (r, u)
int WU(int which) { return (2 + which) * groups_n(); }        // delta = (w, u)
int RR(int which) { return (4 + which) * groups_n(); }        // |r|^2
int BB() { return 6 * groups_n(); }                           // |b|^2
int SCALARS(int which) { return 7 * groups_n() + 2 * which; } // (gamma, alpha) of the last iteration

float transmittance(ivec3 c) {
    vec3 h = vec3(trans_size) / vec3(size);
    return clamp(shading_trilinear(trans, trans_size, (vec3(c) + 0.5) * h - 0.5), 0.0, 1.0);
}

float extinction(ivec3 c) {
    vec3 h = vec3(fine_size) / vec3(size);
    float rho = shading_trilinear(fine, fine_size, (vec3(c) + 0.5) * h - 0.5);
    return min(sigma_t * max(rho, 0.0), SIGMA_MAX);
}
// Air is a vacuum around the cloud (diffusion.emptiness): e / h more transport extinction, 3 e / 4h escape.
float cell_mean() { return pow(cell.x * cell.y * cell.z, 1.0 / 3.0); }
float emptiness(float st) { float e = clamp(1.0 - st * cell_mean() / AIR_DEPTH, 0.0, 1.0); return e * e; }
float diffusivity(float st) {
    return 1.0 / (3.0 * max(st * (1.0 - albedo) + albedo * st * (1.0 - g) + emptiness(st) / cell_mean(), FLOOR));
}
float first_moment(ivec3 c, float st) { return g * albedo * st * transmittance(c); }

void assemble(ivec3 c, int i) {
    float st = extinction(c), D = diffusivity(st), q = first_moment(c, st);
    float V = cell.x * cell.y * cell.z;
    float diag = ((1.0 - albedo) * st + 0.75 * emptiness(st) / cell_mean()) * V;
    float rhs = albedo * st * transmittance(c) * V;
    float Gp[3];
    for (int a = 0; a < 3; ++a) {
        float A = V / cell[a], h = cell[a];
        Gp[a] = 0.0;
        for (int side = -1; side <= 1; side += 2) {
            ivec3 e = c;
            e[a] += side;
            if (e[a] < 0 || e[a] >= size[a]) {          // Marshak boundary face
                float k = 2.0 * D / h;
                diag += A * k / (2.0 * k + 1.0);
                rhs -= A * 3.0 * D * q * s[a] * float(side) / (2.0 * k + 1.0);
                continue;
            }
            float st1 = extinction(e), D1 = diffusivity(st1), q1 = first_moment(e, st1);
            float G = A / (h / (2.0 * D) + h / (2.0 * D1));
            float flux = A * 3.0 * (2.0 * D * D1 / (D + D1)) * 0.5 * (q + q1) * s[a];   // toward +a
            diag += G;
            rhs -= float(side) * flux;
            if (side == 1) Gp[a] = G;
        }
    }
    put(DIAG, i, diag); put(RHS, i, rhs);
    put(GX, i, Gp[0]); put(GY, i, Gp[1]); put(GZ, i, Gp[2]);
    put(DC, i, D); put(QC, i, q);
}

float apply(int field, ivec3 c, int i) {
    float y = at(DIAG, i) * at(field, i);
    int stride[3] = int[3](1, size.x, size.x * size.y);
    int G[3] = int[3](GX, GY, GZ);
    for (int a = 0; a < 3; ++a) {
        if (c[a] + 1 < size[a]) y -= at(G[a], i) * at(field, i + stride[a]);
        if (c[a] > 0) y -= at(G[a], i - stride[a]) * at(field, i - stride[a]);
    }
    return y;
}


// This iteration's s = w + beta s at cell j (the first iteration: w), from the last iteration's copies.
float next_s(int j, float beta) {
    return at(W + cur, j) + (first == 1 ? 0.0 : beta * at(S + cur, j));
}

// This iteration's new u = (r - alpha s) / diag at cell j: what j's own invocation computes, from the
// last iteration's copies (pointwise), so a neighbour's is known without waiting for it.
float next_u(int j, float alpha, float beta) {
    return (at(R + cur, j) - alpha * next_s(j, beta)) / at(DIAG, j);
}

// w = A u at cell c (index i, its own u given), the neighbours' u: r / diag at init (stage 2), else
// next_u (stage 3).
float a_times_u(ivec3 c, int i, float u, bool init, float alpha, float beta) {
    float w = at(DIAG, i) * u;
    int stride[3] = int[3](1, size.x, size.x * size.y);
    int G[3] = int[3](GX, GY, GZ);
    for (int a = 0; a < 3; ++a) {
        int up = i + stride[a], down = i - stride[a];
        if (c[a] + 1 < size[a]) w -= at(G[a], i) * (init ? at(R, up) / at(DIAG, up) : next_u(up, alpha, beta));
        if (c[a] > 0) w -= at(G[a], down) * (init ? at(R, down) / at(DIAG, down) : next_u(down, alpha, beta));
    }
    return w;
}

float gradient(ivec3 c, int i, int a) {
    int stride = a == 0 ? 1 : (a == 1 ? size.x : size.x * size.y);
    if (size[a] == 1) return 0.0;
    if (c[a] == 0) return (at(X, i + stride) - at(X, i)) / cell[a];
    if (c[a] == size[a] - 1) return (at(X, i) - at(X, i - stride)) / cell[a];
    return (at(X, i + stride) - at(X, i - stride)) / (2.0 * cell[a]);
}

void main() {
    int i = int(gl_GlobalInvocationID.x);
    bool inside = i < n_cells();
    ivec3 c = ivec3(i % size.x, (i / size.x) % size.y, i / (size.x * size.y));
    if (stage == 0) {
        if (inside) {
            assemble(c, i);
            if (cold == 1 || !(abs(at(X, i)) < 1e30)) put(X, i, 0.0);     // a NaN never carries over
        }
    } else if (stage == 1) {
        float bb = 0.0;
        if (inside) {
            put(R, i, at(RHS, i) - apply(X, c, i));
            bb = at(RHS, i) * at(RHS, i);
        }
        partials(ivec3(BB(), -1, -1), vec3(bb, 0.0, 0.0));
    } else if (stage == 2) {
        float ru = 0.0, wu = 0.0, rr = 0.0;
        if (inside) {
            float r = at(R, i), u = r / at(DIAG, i);
            float w = a_times_u(c, i, u, true, 0.0, 0.0);
            put(W, i, w);
            ru = r * u; wu = w * u; rr = r * r;
        }
        partials(ivec3(RU(0), WU(0), RR(0)), vec3(ru, wu, rr));
    } else if (stage == 3) {
        vec4 v = totals(ivec4(RR(cur), BB(), RU(cur), WU(cur)));       // (rr, bb, gamma, delta)
        int nxt = 1 - cur;
        if (v.x <= tolerance * tolerance * v.y) {       // converged (uniform): carry the partials to the next copy
            if (gl_LocalInvocationID.x == 0u) {
                int w = int(gl_WorkGroupID.x);
                if (w == 0) {
                    args[0] = 0u;                       // later iterations dispatch nothing
                    parts[SCALARS(nxt)] = parts[SCALARS(cur)];
                    parts[SCALARS(nxt) + 1] = parts[SCALARS(cur) + 1];
                }
                parts[RU(nxt) + w] = parts[RU(cur) + w];
                parts[WU(nxt) + w] = parts[WU(cur) + w];
                parts[RR(nxt) + w] = parts[RR(cur) + w];
            }
            return;
        }
        float gamma = v.z, delta = v.w, beta = 0.0, denom = delta;
        if (first == 0) {
            float gamma_old = parts[SCALARS(cur)], alpha_old = parts[SCALARS(cur) + 1];
            beta = gamma_old > 0.0 ? gamma / gamma_old : 0.0;
            if (alpha_old > 0.0) denom = delta - beta * gamma / alpha_old;
        }
        float alpha = denom > 0.0 ? gamma / denom : 0.0;
        if (gl_GlobalInvocationID.x == 0u) {
            parts[SCALARS(nxt)] = gamma;
            parts[SCALARS(nxt) + 1] = alpha;
        }
        float ru = 0.0, wu = 0.0, rr = 0.0;
        if (inside) {
            float s_i = next_s(i, beta);
            float p = at(R + cur, i) / at(DIAG, i) + (first == 1 ? 0.0 : beta * at(P, i));
            put(P, i, p);
            put(X, i, at(X, i) + alpha * p);
            put(S + nxt, i, s_i);
            float r = at(R + cur, i) - alpha * s_i, u = r / at(DIAG, i);
            float w = a_times_u(c, i, u, false, alpha, beta);
            put(R + nxt, i, r);
            put(W + nxt, i, w);
            ru = r * u; wu = w * u; rr = r * r;
        }
        partials(ivec3(RU(nxt), WU(nxt), RR(nxt)), vec3(ru, wu, rr));
    } else if (inside) {
        float phi = at(X, i), D = at(DC, i);
        vec3 F = -D * vec3(gradient(c, i, 0), gradient(c, i, 1), gradient(c, i, 2)) + 3.0 * D * at(QC, i) * s;
        float n = length(F);
        F *= min(1.0, max(phi, 0.0) / max(n, 1e-30));
        imageStore(target, c, vec4(phi, F));
    }
}
