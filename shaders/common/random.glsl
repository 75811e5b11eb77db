// Deterministic per-sample random numbers: a PCG hash seeds a per-invocation state, so the same
// (pixel, frame, seed, sample) always gives the same stream and a new frame gives new noise.
#ifndef FOVEA_RANDOM_GLSL
#define FOVEA_RANDOM_GLSL

uint pcg_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

uint rng_seed(uvec2 texel, uint frame, uint seed, uint sample_index) {
    return pcg_hash(texel.x + pcg_hash(texel.y + pcg_hash(frame + pcg_hash(seed + pcg_hash(sample_index)))));
}

// Uniform in [0, 1): 24 mantissa bits so 1.0 is never returned.
float rng_next(inout uint state) {
    state = pcg_hash(state);
    return float(state >> 8u) * (1.0 / 16777216.0);
}

vec2 rng_next2(inout uint state) {
    return vec2(rng_next(state), rng_next(state));
}

// One uniform number in [0, 1) per (texel, frame, seed, salt), independent of the path's stream
// (another salt): which texels a sparse space traces. Rust: sampling::unit_hash.
float unit_hash(uvec2 texel, uint frame_index, uint seed, uint salt) {
    return float(rng_seed(texel, frame_index, seed, salt) >> 8u) * (1.0 / 16777216.0);
}

#endif
