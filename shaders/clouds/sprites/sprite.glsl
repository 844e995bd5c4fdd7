// The sprite stage shared by the point draw (sprite.vert, sprite.frag) and the compute splat
// (splat_setup.comp, splat_blend.comp): one cloud particle per cell of a sprite group (thesis 6.2), or
// per block of s³ cells at level of detail L (s = 2^L). A segment (group x, slice or block y, group z,
// code) packs L | (span x − 1) << 2 | (span z − 1) << 3 in its code, a unit of 1 or 2 groups per side
// (columns merged across a boundary the camera stands on, see segments.py). ``vertex`` is a block's place
// in the unit's drawing order: rows along the axis the camera is farther off, each axis walked toward the
// camera, so of two neighbouring sprites the farther is always drawn first. The sprite sits at the
// block's centre of mass; its density is the block's mean of mix(A, B, t) (cells past the volume's edge
// count as empty; the grid is B's placement, A's cell is c + a_shift); empty blocks and blocks past the
// edge are culled. The light samples filter in float32 (volume.glsl texel_trilinear), not with a texture
// unit's 8-bit sub-texel weights: once per sprite, and T falls by orders of magnitude between cells.
// Include after lib/frame.glsl and clouds/volume/volume.glsl (with CLOUD_EXACT_FILTER defined).
uniform ivec3 volume_shape;
uniform ivec2 group_size;
uniform vec3 layer_min;        // world corner of cell (0, 0, 0)
uniform vec3 cell_size;
uniform vec3 camera_cell;      // the camera in cells from the volume's corner
// camera_pos (the view ray to the sprite's centre), view_proj, near (sprites fade out before their centre
// crosses it) and far: the frame block (lib/frame.glsl)
uniform float base_diameter;   // world sprite diameter of one cell at density 1: size factor × max(cx, cz)
uniform float pixel_scale;     // pixel diameter = world diameter × pixel_scale / clip.w
uniform float max_point_size;
uniform vec3 camera_right;     // the sprite's screen axes (the fragment shader's too)
uniform vec3 camera_up;
uniform float tau_scale;       // sigma_t × cell volume: the optical depth a unit of summed density spreads over the screen (m²)

// What one sprite hands its pixels (sprite.vert's flat outputs; a record of the splat's list).
struct Sprite {
    vec4 position;        // clip position, depth-tested at its front (CULLED: not drawn)
    float point_size;     // pixels
    vec4 octaves;         // b^i P_i(T): the sun's light per octave (volume.glsl octave_weights)
    vec3 slope;           // log T's slope h across the sprite (per unit pc) and h^T cov h / 2
    vec3 ambient;         // sky and ground light at the sprite, dimmed by the columns above and below
    vec4 field;           // the diffusion field (phi, F) at the sprite's centre (0 when its weight is 0)
    vec3 sun;             // the sun's source at the sprite's height (volume.glsl sun_source_at)
    vec3 center;          // world centre and radius: the pixel's view ray for the phase function
    float radius;
    float tau;
    vec3 conic;           // the footprint's inverse covariance (xx, xy, yy) on the screen axes, in radii
    float falloff;        // k of the profile (exp(-Q/2) - exp(-k)) / (1 - exp(-k)), Q = p^T conic p
    float coverage;       // < 1 for sprites smaller than a pixel (their area in pixels) or near the near plane
    float stretch;        // the point's half side over the radius, in the screen-parallel plane (>= 1 off-axis)
};

const vec4 CULLED = vec4(0.0, 0.0, 2.0, 1.0);   // z > w: outside the clip volume
// per axis (cells²): the trilinear hat's 1/6 around a cell centre, widened to the quadratic B-spline's 1/4
// (the hat convolved with one cell) so a Gaussian this wide leaves < 1 % ripple on the grid (particle.py)
const float CELL_VARIANCE = 0.25;
const float MIN_FALLOFF = 1e-2;         // q this small is a 1 - r² disc: the profile's limit
const float MAX_OFF_AXIS = 4.0;         // |x/z|, |y/z| of the Jacobian's m (76°): beyond, centres are far off screen
// A cell's mass is its density times the trilinear hat around its centre; the sprite's light is the
// mean of J over that mass, not J at the centre (T is convex: a centre sample is too dark on the lit
// side, by up to ~20 % at an optical depth of 1 per cell). Per axis, the mean of the trilinear T under
// the hat is exactly the average of two samples at ±1/3 cell, so 8 samples at the block's centre of
// mass ± sqrt(variance of its cells + 1/9) cells (exact for one cell, the mass's spread for a block).
const float HAT_SPREAD = 1.0 / 9.0;
const float MIN_T = 1e-30;              // log T's floor
const float MAX_SLOPE = 8.0;            // |log T change| per half side at most: e^8 across a sprite

// The block drawn k-th of n (size s) along an axis with the camera c cells from the group's start:
// each side of the camera walked toward it, the side whose innermost block is farther first.
int toward(int k, int n, float c, int s) {
    float x = c / float(s);
    int before = int(clamp(ceil(x - 0.5), 0.0, float(n)));     // blocks whose centre is before c
    int after = n - before;
    if (x >= float(before))                                     // c in block `before`: its left neighbour is farther
        return k < before ? k : n - 1 - (k - before);
    return k < after ? n - 1 - k : k - after;
}

bool sprite_setup(ivec4 segment, int vertex, out Sprite o) {
    int s = 1 << (segment.w & 3);
    ivec2 extent = group_size * (1 + ((ivec2(segment.w) >> ivec2(2, 3)) & 1));
    ivec2 n = extent / s;
    ivec2 origin = segment.xz * group_size;
    vec2 cam = camera_cell.xz - vec2(origin);
    vec2 off = abs(cam - 0.5 * vec2(extent));
    ivec2 block = off.x >= off.y
        ? ivec2(toward(vertex / n.y, n.x, cam.x, s), toward(vertex % n.y, n.y, cam.y, s))
        : ivec2(toward(vertex % n.x, n.x, cam.x, s), toward(vertex / n.x, n.y, cam.y, s));
    ivec3 cell = ivec3(origin.x + block.x * s, segment.y * s, origin.y + block.y * s);
    o = Sprite(CULLED, 1.0, vec4(0.0), vec3(0.0), vec3(0.0), vec4(0.0), vec3(0.0), vec3(0.0), 0.0, 0.0,
               vec3(1.0, 0.0, 1.0), 1.0, 0.0, 1.0);
    if (any(greaterThanEqual(cell, volume_shape))) return false;
    float sum = 0.0;
    vec3 first = vec3(0.0), second = vec3(0.0);   // density-weighted cell centres from the block's corner, and squares
    for (int z = 0; z < s; ++z)
        for (int y = 0; y < s; ++y)
            for (int x = 0; x < s; ++x) {
                ivec3 c = cell + ivec3(x, y, z);
                ivec3 ca = c + a_shift;              // A's cell at the same world point; past its edge: empty
                float da = all(greaterThanEqual(ca, ivec3(0))) && all(lessThan(ca, volume_shape))
                    ? texelFetch(density_a, ca, 0).r : 0.0;
                if (all(lessThan(c, volume_shape))) {
                    float dc = mix(da, texelFetch(density_b, c, 0).r, t);
                    vec3 o = vec3(x, y, z) + 0.5;
                    sum += dc;
                    first += dc * o;
                    second += dc * o * o;
                }
            }
    if (!(sum > 0.0)) return false;
    // the sprite at the block's centre of mass, lit by the mean J of its mass (HAT_SPREAD)
    vec3 mean = first / sum;
    vec3 cells_var = max(second / sum - mean * mean, 0.0);      // of the block's cell centres, cells²
    vec3 spread = sqrt(cells_var + HAT_SPREAD);
    vec3 center = vec3(cell) + mean;
    sum *= cloud_edge_weight((vec2(cell.xz) + 0.5 * float(s)) / vec2(volume_shape.xz), edge_fade);
    if (!(sum > 0.0)) return false;
    vec3 world = layer_min + center * cell_size;
    vec4 clip = view_proj * vec4(world, 1.0);
    float diameter = float(s) * base_diameter;
    // the perspective's Jacobian at the sprite (EWA splatting): off-axis a blob's depth projects
    // sideways, so its footprint and the spacing of its neighbours stretch by up to sqrt(1 + |m|²)
    // radially; without it the footprint is too narrow there and the grid shows (particle.py)
    vec3 rel = world - camera_pos, forward = cross(camera_up, camera_right);
    vec2 m = clamp(vec2(dot(rel, camera_right), dot(rel, camera_up)) / max(dot(rel, forward), near),
                   -MAX_OFF_AXIS, MAX_OFF_AXIS);       // behind the camera: culled anyway, no degenerate axes
    float stretch = sqrt(1.0 + dot(m, m));
    vec3 axis_x = (camera_right - m.x * forward) / stretch, axis_y = (camera_up - m.y * forward) / stretch;
    float px = stretch * diameter * pixel_scale / max(clip.w, 1e-6);
    float c = clamp(px, 0.0, 1.0);
    o.coverage = c * c * clamp((clip.w - near) / diameter, 0.0, 1.0);   // no pop when the near plane clips it
    o.point_size = clamp(px, 1.0, max_point_size);
    // the footprint: the block's mass (its cells' spread + each cell's, world m², diagonal) through
    // the Jacobian (axis_x, axis_y), in the point's half sides (stretch radii); the profile is that
    // Gaussian cut to 0 at the iso-line whose long axis is the half side (particle.py)
    float radius = 0.5 * diameter;
    vec3 mass_var = (cells_var + CELL_VARIANCE) * cell_size * cell_size / (radius * radius);
    vec3 cov = vec3(dot(axis_x * axis_x, mass_var), dot(axis_x * axis_y, mass_var), dot(axis_y * axis_y, mass_var));
    float det = cov.x * cov.z - cov.y * cov.y;
    float longest = 0.5 * (cov.x + cov.z) + sqrt(0.25 * (cov.x - cov.z) * (cov.x - cov.z) + cov.y * cov.y);
    float k = max(0.5 / longest, MIN_FALLOFF), e = exp(-k);
    o.conic = vec3(cov.z, -cov.y, cov.x) / det;
    o.falloff = k;
    o.tau = tau_scale * sum * (1.0 - e) / (2.0 * PI * sqrt(det) * radius * radius * stretch * (1.0 - e - k * e));
    o.stretch = stretch;
    vec3 ray = normalize(world - camera_pos);
    vec3 uvw = center / vec3(volume_shape);
    vec2 col = cloud_columns(uvw);
    float up = col.x, down = col.y;
    vec4 octaves = vec4(0.0);
    vec3 slope = vec3(0.0);                        // sum of side × log T over the taps
    for (int i = 0; i < 8; ++i) {
        vec3 side = vec3((i & 1) == 0 ? -1.0 : 1.0, (i & 2) == 0 ? -1.0 : 1.0, (i & 4) == 0 ? -1.0 : 1.0);
        float T = cloud_transmittance(uvw + side * spread / vec3(volume_shape));
        octaves += octave_weights(T);
        slope += side * log(max(T, MIN_T));
    }
    // log T's gradient (1/m) fitted to the taps, on the sprite's screen axes per unit of point coordinate
    // (sprite.frag's pc: a half side stretch × radius long): the sun's light varies across the sprite as
    // T does, exp(e_i (h.pc - e_i h^T cov h / 2)) per octave (e = octave_exponents()), a mean of 1 over the footprint's Gaussian
    vec3 g = slope / (8.0 * spread * cell_size);
    vec2 h = clamp(stretch * 0.5 * diameter * vec2(dot(g, camera_right), dot(g, camera_up)), -MAX_SLOPE, MAX_SLOPE);
    o.slope = vec3(h, 0.5 * dot(h, vec2(cov.x * h.x + cov.y * h.y, cov.y * h.x + cov.z * h.y)));
    o.octaves = octaves / 8.0;
    o.ambient = ambient_source(up, down, ray.y);
    o.field = ms_diffusion > 0.0 ? cloud_diffusion(uvw) : vec4(0.0);
    o.sun = sun_source_at(uvw.y);
    o.center = world;
    o.radius = 0.5 * diameter;
    // depth-tested at its front (the centre pulled a radius toward the camera, x and y unmoved): a
    // sprite whose centre is just behind a surface still shows the part of its mass in front (sprite.frag)
    float front = max(clip.w - o.radius, near);
    float ndc = (far + near) / (far - near) - 2.0 * far * near / ((far - near) * front);
    o.position = vec4(clip.xy, min(ndc, 1.0) * clip.w, clip.w);
    return true;
}

// The premultiplied (J a, a) of sprite ``o`` at point coordinate ``pc`` ((-1, -1)..(1, 1) across the
// point, y up) whose scene lies ``scene`` metres deep and the sprite's centre ``depth`` (its clip w).
// Soft particle: × clamp(1/2 + (scene − depth) / (2 radius), 0, 1), the share of its depth span in front
// of the surface (float64: reference.soft_fade). The light J (volume.glsl) with the phase function at
// this point's view ray through the sprite's plane, the sun's light varied across it as T varies.
vec4 sprite_shade(Sprite o, vec2 pc, float scene, float depth) {
    float soft = clamp(0.5 + 0.5 * (scene - depth) / o.radius, 0.0, 1.0);
    float e = exp(-o.falloff), form = dot(pc * pc, o.conic.xz) + 2.0 * o.conic.y * pc.x * pc.y;
    float profile = max(exp(-0.5 * form) - e, 0.0) / (1.0 - e);
    float a = (1.0 - exp(-o.tau * profile)) * o.coverage * soft;
    if (!(a > 0.0)) return vec4(0.0);              // past the footprint's cut (the square's corners) or behind the scene
    vec2 q = pc * (o.radius * o.stretch);          // the point's side spans stretch × diameter
    vec3 ray = normalize(o.center + q.x * camera_right + q.y * camera_up - camera_pos);
    vec4 ai = octave_exponents();                                        // octave i: exp(e_i (h.pc - e_i var))
    vec4 across = exp(clamp(ai * (dot(o.slope.xy, pc) - ai * o.slope.z), -40.0, 40.0));
    vec3 J = sun_part(o.octaves * across, dot(ray, light_dir), o.sun) + diffusion_light(o.field, ray, o.sun) + o.ambient;
    return vec4(min(J, vec3(HDR_MAX)) * a, a);   // volume.glsl: the blends never reach inf in float16
}
