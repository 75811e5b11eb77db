// Visual-Polar sampling (Koskela et al., EGSR 2019): one sample per kept texel of the VP grid
// (x = ρ, y = φ), mapped to the screen by visual_polar_math.glsl with the parameters packed by
// VisualPolar::sampling_params() (the `sampling` buffer). Jitter is applied in VP space, inside the
// texel, so a sample never leaves its column. Texels cut by the fovea's triangular clip hold no
// sample. With the paper's layout positions off the screen are returned (and traced, as in the
// paper): the camera model handles any screen position. The screen-clipped layout
// (visual_polar_clipped.glsl) keeps them on it, up to the jitter across a column's radius.
#ifndef FOVEA_SAMPLING_VISUAL_POLAR_GLSL
#define FOVEA_SAMPLING_VISUAL_POLAR_GLSL

#include "visual_polar_params.glsl"

// Whether `texel` holds a sample (not clipped, inside the grid).
bool sample_exists(ivec2 texel) {
    return vp_is_valid_texel(sampling_vp_params(), texel);
}

// Screen position (pixels, y down) of the sample held by `texel`; false when the texel holds none.
bool sample_screen_position(ivec2 texel, vec2 jitter, out vec2 screen) {
    VpParams P = sampling_vp_params();
    screen = vec2(0.0);
    if (!vp_is_valid_texel(P, texel)) return false;
    // rng_next gives [0, 1): texel + jitter stays in the texel, so floor(x) is its column.
#if defined(VP_LAYOUT_PAPER_ONLY)
    // The paper-layout kernel: lavapipe would run the clipped mapping too under a branch.
    screen = vp_vp_to_screen(P, vec2(texel) + jitter);
#else
    screen = vp_layout_vp_to_screen(P, vec2(texel) + jitter);
#endif
    return true;
}

#endif
