// A broken include (tests/test_shader_path.py): line 3 calls what does not exist.
vec3 piece() {
    return no_such_function(1.0);
}
