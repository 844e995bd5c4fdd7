// View rays of a fullscreen pass: world direction through a pixel, and scene distance from depth.
// uv in [0,1]^2 (lib/fullscreen.vert's v_uv); depth is the window-space value of a depth texture.

vec3 view_ray_dir(vec2 uv, mat4 inv_view_proj, vec3 camera_pos) {
    vec4 far_p = inv_view_proj * vec4(uv * 2.0 - 1.0, 1.0, 1.0);
    return normalize(far_p.xyz / far_p.w - camera_pos);
}

// Distance from the camera to the surface behind the pixel; `none` where nothing was drawn (depth 1).
float view_ray_distance(vec2 uv, float depth, mat4 inv_view_proj, vec3 camera_pos, float none) {
    if (depth >= 1.0) return none;
    vec4 hit = inv_view_proj * vec4(uv * 2.0 - 1.0, depth * 2.0 - 1.0, 1.0);
    return length(hit.xyz / hit.w - camera_pos);
}
