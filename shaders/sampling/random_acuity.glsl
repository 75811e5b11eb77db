// Random acuity samples (Koskela et al. 2018, comparators.md): Visual-Polar's texels, each tracing
// one sample at a position drawn afresh every frame, uniformly over the grid's kept texels and
// mapped to the screen by Visual-Polar's mapping — so the samples follow the same acuity density
// as VP's, but neighbouring lanes trace unrelated rays (the coherence comparator). The draw
// rejects clipped texels, at most RANDOM_ACUITY_TRIES times; a texel whose draws all miss traces
// nothing. The way back splats each sample to its pixel (passes/splat.comp). Paper layout only.
// Rust: sampling::RandomAcuity.
#ifndef FOVEA_SAMPLING_RANDOM_ACUITY_GLSL
#define FOVEA_SAMPLING_RANDOM_ACUITY_GLSL

#include "../common/frame.glsl"
#include "../common/random.glsl"
#include "visual_polar_params.glsl"

// The grid position (texel units) of the sample `texel` holds this frame; false when none.
bool random_acuity_grid_position(ivec2 texel, out vec2 g) {
    VpParams P = sampling_vp_params();
    g = vec2(0.0);
    if (!vp_is_valid_texel(P, texel)) return false;
    uvec2 t = uvec2(texel);
    vec2 size = vec2(P.grid);
    for (uint k = 0u; k < RANDOM_ACUITY_TRIES; ++k) {
        uint salt = SPARSE_SALT_POSITION + 2u * k;
        vec2 draw = vec2(unit_hash(t, frame.data.frame.x, frame.data.frame.y, salt),
                         unit_hash(t, frame.data.frame.x, frame.data.frame.y, salt + 1u)) * size;
        if (vp_is_valid_texel(P, min(ivec2(floor(draw)), ivec2(P.grid) - 1))) {
            g = draw;
            return true;
        }
    }
    return false;
}

bool sample_exists(ivec2 texel) {
    vec2 g;
    return random_acuity_grid_position(texel, g);
}

// The jitter is not used: the draw is already continuous.
bool sample_screen_position(ivec2 texel, vec2 jitter, out vec2 screen) {
    vec2 g;
    screen = vec2(0.0);
    if (!random_acuity_grid_position(texel, g)) return false;
    screen = vp_vp_to_screen(sampling_vp_params(), g);
    return true;
}

// Screen pixels between samples around this one: Visual-Polar's texel footprint at the drawn
// position (the neighbouring texel's sample lies anywhere on the screen).
#define SAMPLING_HAS_FOOTPRINT
float sample_footprint(ivec2 texel, vec2 screen) {
    vec2 g;
    if (!random_acuity_grid_position(texel, g)) return 1.0;
    VpParams P = sampling_vp_params();
    float across = length(vp_vp_to_screen(P, g + vec2(1.0, 0.0)) - screen);
    float along = length(vp_vp_to_screen(P, g + vec2(0.0, 1.0)) - screen);
    return max(max(across, along), 1e-3);
}

#endif
