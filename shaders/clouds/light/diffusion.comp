#version 430
// The diffusion field (plugins/clouds/light/diffusion.py; float64 twin: diffusion_system + solve_cg + field):
// a P1 solve of the sun's scattered fluence on the field's grid (the shading grid or coarser) by Jacobi-preconditioned conjugate
// gradients, two dispatches per iteration. One invocation per cell (x fastest); per-cell vectors in
// `cells` (fields at multiples of n_cells), per-workgroup partial sums in `parts`. Every workgroup sums
// the partials in the same order, so all of them see the same scalars (no read-back, no host sync).
// stage 0 assemble (x kept from the last solve unless cold), 1 init (r = b - A x), 2 p/Ap, 3 x/r/z,
// 4 write (phi, F) into the rgba16f target. The iteration stops (stages 2 and 3 do nothing) once
// |r| <= tolerance |b| (stage 3 then sets the indirect group count to 0: they cost nothing more).
layout(local_size_x = 256) in;
#include "clouds/light/sample.glsl"
layout(std140, binding = 1) uniform Step {   // one record per (stage, cur, first), bound per dispatch
    int stage;
    int cur;                  // which of the two rz / rr partial arrays is the current one
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
const int X = 0, R = 1, Z = 2, P = 3, AP = 4, DIAG = 5, RHS = 6, GX = 7, GY = 8, GZ = 9, DC = 10, QC = 11;
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

int RZ(int which) { return which * groups_n(); }
int RR(int which) { return (2 + which) * groups_n(); }
int PAP() { return 4 * groups_n(); }
int BB() { return 5 * groups_n(); }

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
        float rz = 0.0, rr = 0.0, bb = 0.0;
        if (inside) {
            float r = at(RHS, i) - apply(X, c, i), z = r / at(DIAG, i);
            put(R, i, r); put(Z, i, z);
            rz = r * z; rr = r * r; bb = at(RHS, i) * at(RHS, i);
        }
        partials(ivec3(RZ(cur), RR(cur), BB()), vec3(rz, rr, bb));
    } else if (stage == 2) {
        vec4 v = totals(ivec4(RR(cur), BB(), RZ(cur), RZ(1 - cur)));   // (rr, bb, rz, rz_old)
        if (v.x <= tolerance * tolerance * v.y) return;   // converged: uniform over all invocations
        float beta = first == 1 ? 0.0 : v.z / max(v.w, 1e-37);
        float pap = 0.0;
        if (inside) {
            float p = at(Z, i) + beta * (first == 1 ? 0.0 : at(P, i));
            float ap = apply(Z, c, i) + (first == 1 ? 0.0 : beta * at(AP, i));
            put(P, i, p); put(AP, i, ap);
            pap = p * ap;
        }
        partials(ivec3(PAP(), -1, -1), vec3(pap, 0.0, 0.0));
    } else if (stage == 3) {
        vec4 v = totals(ivec4(RR(cur), BB(), RZ(cur), PAP()));        // (rr, bb, rz, pAp)
        float rz = 0.0, rr = 0.0;
        if (v.x <= tolerance * tolerance * v.y) {                                      // carry this workgroup's partials to the next array
            if (gl_LocalInvocationID.x == 0u) {
                if (gl_WorkGroupID.x == 0u) args[0] = 0u;       // later iterations dispatch nothing
                int w = int(gl_WorkGroupID.x);
                parts[RZ(1 - cur) + w] = parts[RZ(cur) + w];
                parts[RR(1 - cur) + w] = parts[RR(cur) + w];
            }
            return;
        }
        float alpha = v.w > 0.0 ? v.z / v.w : 0.0;
        if (inside) {
            float x = at(X, i) + alpha * at(P, i), r = at(R, i) - alpha * at(AP, i), z = r / at(DIAG, i);
            put(X, i, x); put(R, i, r); put(Z, i, z);
            rz = r * z; rr = r * r;
        }
        partials(ivec3(RZ(1 - cur), RR(1 - cur), -1), vec3(rz, rr, 0.0));
    } else if (inside) {
        float phi = at(X, i), D = at(DC, i);
        vec3 F = -D * vec3(gradient(c, i, 0), gradient(c, i, 1), gradient(c, i, 2)) + 3.0 * D * at(QC, i) * s;
        float n = length(F);
        F *= min(1.0, max(phi, 0.0) / max(n, 1e-30));
        imageStore(target, c, vec4(phi, F));
    }
}
