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

// The random state of a path from its primary hit at world position `position` whose sample
// covers `footprint` world units (StereoNoise::Surface; docs/design/random-numbers.md). The
// position is quantised to cubes of the power of two at or below the footprint, so both eyes'
// samples of one surface neighbourhood share a cell (their footprints agree to within the
// octave); the cell, its level, the frame, the seed and the sample index go through the nested
// PCG hash, which decorrelates neighbouring cells. The grid is offset by a third of a cell, so a
// wall on a plane of the scene's round coordinates does not lie on a cell boundary, where
// rounding would send the two eyes' samples of it to different cells.
uint surface_rng_seed(vec3 position, float footprint, uint frame_index, uint seed, uint sample_index) {
    int level = int(floor(log2(max(footprint, 1e-30))));
    ivec3 cell = ivec3(floor(position * exp2(float(-level)) + 1.0 / 3.0));
    uint h = pcg_hash(seed + pcg_hash(sample_index + SURFACE_NOISE_SALT));
    h = pcg_hash(frame_index + h);
    h = pcg_hash(uint(level) + h);
    return pcg_hash(uint(cell.x) + pcg_hash(uint(cell.y) + pcg_hash(uint(cell.z) + h)));
}

// One uniform number in [0, 1) per (texel, frame, seed, salt), independent of the path's stream
// (another salt): which texels a sparse space traces. Rust: sampling::unit_hash.
float unit_hash(uvec2 texel, uint frame_index, uint seed, uint salt) {
    return float(rng_seed(texel, frame_index, seed, salt) >> 8u) * (1.0 / 16777216.0);
}

#endif
