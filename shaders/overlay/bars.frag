#version 430
// Frame-time bars: one column per recorded frame; full height = 50 ms; guide lines at 16.7 and 33.3 ms.
in vec2 v_uv;
out vec4 frag;
layout(binding = 0) uniform sampler2D frame_ms;

void main() {
    float ms = texture(frame_ms, vec2(v_uv.x, 0.5)).r;
    float h = ms / 50.0;
    vec3 c = ms < 16.7 ? vec3(0.2, 0.9, 0.3) : (ms < 33.3 ? vec3(0.95, 0.8, 0.2) : vec3(0.95, 0.25, 0.2));
    vec4 bg = vec4(0.0, 0.0, 0.0, 0.45);
    vec4 col = v_uv.y < h ? vec4(c, 0.9) : bg;
    float px = fwidth(v_uv.y);
    if (abs(v_uv.y - 16.7 / 50.0) < px || abs(v_uv.y - 33.3 / 50.0) < px) col = vec4(1.0, 1.0, 1.0, 0.6);
    frag = col;
}
