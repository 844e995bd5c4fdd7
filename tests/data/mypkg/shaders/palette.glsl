// The plugin's own include: its colours (linear HDR).
const vec3 GLOW_UP = vec3(4.0, 0.0, 0.0);
const vec3 GLOW_DOWN = vec3(0.0, 0.0, 4.0);
