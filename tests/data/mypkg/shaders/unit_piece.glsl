// A piece that declares a sampler at unit 4 (tests/test_shader_path.py).
layout(binding = 4) uniform sampler2D first;
