// The clouds' own distance for the media passes (atmos/composition.py): "cloud_distance" holds
// (a·d, a), premultiplied. Returns (a, d): the clouds' coverage and their transmittance-weighted
// distance from the camera (0 where no cloud covers the pixel).
vec2 cloud_cover_distance(vec2 premultiplied) {
    float a = clamp(premultiplied.y, 0.0, 1.0);
    return vec2(a, a > 0.0 ? max(premultiplied.x / premultiplied.y, 0.0) : 0.0);
}
