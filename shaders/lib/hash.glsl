// Counter-based hash, bit for bit the same as atmos/hashing.py (uint32 arithmetic, wraparound).
// lowbias32: Chris Wellons' 2-multiply finalizer, a bijection on uint.

uint atmos_lowbias32(uint x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

// Keys (ka, kb) of the random stream (seed, step, rule, plane); stream id = rule * 256 + plane. In two
// parts where many streams share a step: atmos_step_key(seed, step), then atmos_plane_key of it.
uint atmos_step_key(uint seed, uint step) {
    return atmos_lowbias32(atmos_lowbias32(seed ^ 0x9e3779b9u) ^ step);
}

uvec2 atmos_plane_key(uint step_key, uint rule, uint plane) {
    uint k = atmos_lowbias32(step_key ^ (rule * 256u + plane));
    return uvec2(k, atmos_lowbias32(k ^ 0x68e31da4u));
}

uvec2 atmos_stream_key(uint seed, uint step, uint rule, uint plane) {
    return atmos_plane_key(atmos_step_key(seed, step), rule, plane);
}

// The random uint of one counter value (cell or word index) in the stream with keys `key`.
uint atmos_hash_counter(uint counter, uvec2 key) {
    return atmos_lowbias32(atmos_lowbias32(counter + key.x) ^ key.y);
}

// The whole chain in one call: hash of `counter` in stream `stream` (= rule*256+plane).
uint atmos_hash4(uint counter, uint seed, uint step, uint stream) {
    return atmos_hash_counter(counter, atmos_stream_key(seed, step, stream >> 8, stream & 255u));
}
