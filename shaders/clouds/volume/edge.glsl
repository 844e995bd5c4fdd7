// The cloud volume's radial edge fade (float64 reference: atmos/plugins/clouds/volume/edge.py).
// uv: position in the volume's footprint, (0, 0) at cell (0, *, 0)'s corner, (1, 1) at the far one;
// r = |2 uv - 1| (1 on the inscribed circle), weight = 1 - smoothstep(1 - fade, 1, r); fade <= 0: 1.
// The volume's density is multiplied by it; a far field continues the clouds with 1 - weight.
float cloud_edge_weight(vec2 uv, float fade) {
    if (fade <= 0.0) return 1.0;
    float r = length(2.0 * uv - 1.0);
    return 1.0 - smoothstep(1.0 - fade, 1.0, r);
}
