// Included by test/broken_include.comp.
float helper() {
    float x = 1.0;
    return x + not_declared;
}
