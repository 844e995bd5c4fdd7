// View rays of a fullscreen pass: world direction through a pixel, and scene distance from depth.
// Built from the camera basis and the near/far planes, never by unprojecting through the inverse
// view-projection: that matrix is near-singular in float32 once far/near reaches ~1e7 (at ~1e11 its
// far-plane points are garbage), while these stay accurate at any ratio (e.g. near 0.1, far 1e10).
// The parameters are the uniforms atmos.camera.set_camera_uniforms writes:
//   view_basis  mat3, columns right·tan(fov_x/2), up·tan(fov_y/2), forward (atmos.camera.view_basis)
//   near, far   the planes of the GL projection (atmos.camera.Camera.projection)
// uv in [0,1]^2 (lib/fullscreen.vert's v_uv); depth is the window-space value of a depth texture.
// float64 reference: tests/test_view_ray.py.

// The ray through uv, not normalised: its forward component is 1, so the point at view depth z
// (distance along the forward axis) is camera_pos + z * view_ray(...).
vec3 view_ray(vec2 uv, mat3 view_basis) {
    return view_basis * vec3(uv * 2.0 - 1.0, 1.0);
}

vec3 view_ray_dir(vec2 uv, mat3 view_basis) {
    return normalize(view_ray(uv, view_basis));
}

// View depth of a window-space depth < 1: the GL projection maps view depth z to
// depth = (1/near - 1/z) / (1/near - 1/far), so z = near / ((1 - depth) + depth * (near / far)).
// 1 - depth is exact in float32 for depth >= 0.5 and nothing overflows or cancels however large
// far/near is (near / far may be 1e-11). depth 0 -> near, depth 1 -> far.
// `precise`: kept in this order. Without it a compiler may factor the sum into 1 + depth * (near/far - 1)
// (GLSL allows it; NVIDIA's does), which loses near/far's low bits (all of them at near/far 1e-11):
// up to 1.7e-4 relative near the far plane (tests/test_view_ray.py models both orders).
float view_depth(float depth, float near, float far) {
    precise float scaled = (1.0 - depth) + depth * (near / far);
    return near / scaled;
}

// Distance from the camera to the surface behind the pixel; `none` where nothing was drawn (depth 1).
float view_ray_distance(vec2 uv, float depth, mat3 view_basis, float near, float far, float none) {
    if (depth >= 1.0) return none;
    return view_depth(depth, near, far) * length(view_ray(uv, view_basis));
}
