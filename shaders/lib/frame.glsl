// The frame's constants: one std140 uniform block, written once per frame by atmos.frame_constants
// (RenderGraph.execute) and bound at uniform-buffer binding 0 for every program. Unnamed instance:
// shaders use the members by name. Only for the scene's own camera and sun; a pass with another
// camera or sun (a shadow view, a volume's index space) keeps uniforms of its own, named otherwise.
// Offsets (bytes) are what atmos/frame_constants.py packs; change both together.
#ifndef FRAME_GLSL_INCLUDED
#define FRAME_GLSL_INCLUDED
layout(std140, binding = 0) uniform Frame {
    mat4 view_proj;        //   0  projection · view
    mat4 inv_view_proj;    //  64  its inverse
    mat3 view_basis;       // 128  three vec4 columns (atmos.camera.view_basis; lib/view_ray.glsl)
    vec3 camera_pos;       // 176  world position of the camera
    float near;            // 188  the projection's near plane
    vec3 sun_dir;          // 192  unit, toward the sun (atmos.Sun.direction)
    float far;             // 204  the projection's far plane
    vec3 sun_color;        // 208  atmos.Sun.color
    float time;            // 220  seconds of frame time (SceneView.time)
    vec3 sky_ambient;      // 224  atmos.Sun.ambient
    uint frame_index;      // 236  frames advanced so far (the clock's frame)
    vec2 jitter;           // 240  this frame's subpixel jitter in pixels (0: none)
    vec2 resolution;       // 248  frame width, height in pixels
};                         // 256 bytes

// A scene vertex's clip position moved by this frame's sub-pixel jitter (temporal antialiasing,
// atmos.plugins.temporal_aa; jitter 0: unchanged). The scene's rasterised geometry (ground, terrain,
// meshes) takes it; passes that march rays through pixel centres do not.
vec4 jitter_clip(vec4 clip) {
    return vec4(clip.xy + jitter * (2.0 / resolution) * clip.w, clip.zw);
}
#endif
