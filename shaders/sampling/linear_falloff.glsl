// Linear falloff (Weier et al. 2016 as configured by Koskela et al. 2019): the screen's pixels,
// each traced with a probability that is 1 within the inner radius, falls linearly to the floor
// at the outer radius and stays there; the others are killed at random every frame (their lanes
// idle — that is the point of the comparison). The probability is scaled by the budget factor
// (capped at 1) so the expected count is the budget. Rust: sampling::LinearFalloff.
#ifndef FOVEA_SAMPLING_LINEAR_FALLOFF_GLSL
#define FOVEA_SAMPLING_LINEAR_FALLOFF_GLSL

#include "../common/frame.glsl"
#include "../common/random.glsl"

// The probability that the pixel whose centre lies `r` pixels from the gaze is traced.
float falloff_keep_probability(float r) {
    vec4 g = sampling.data.gaze;
    vec4 s = sampling.data.shape0;
    float ramp = clamp((r - g.z) / max(g.w - g.z, 1e-6), 0.0, 1.0);
    return min(1.0, s.y * mix(1.0, s.x, ramp));
}

bool sample_exists(ivec2 texel) {
    if (any(lessThan(texel, ivec2(0))) || any(greaterThanEqual(texel, ivec2(sampling.data.grid.xy)))) return false;
    float r = length(vec2(texel) + 0.5 - sampling.data.gaze.xy);
    return unit_hash(uvec2(texel), frame.data.frame.x, frame.data.frame.y, SPARSE_SALT_KEEP) < falloff_keep_probability(r);
}

bool sample_screen_position(ivec2 texel, vec2 jitter, out vec2 screen) {
    screen = vec2(texel) + jitter;
    return sample_exists(texel);
}

#endif
