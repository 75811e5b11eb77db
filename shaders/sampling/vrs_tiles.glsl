// Variable-rate tiles (the foveation eye-tracked headsets ship through variable-rate shading): the
// screen in tiles of shape0.x pixels, each traced at one sample per pixel, per 2×2 or per 4×4
// block — rate 1 nearer the gaze than gaze.z, 2 nearer than gaze.w, else 4, by the tile's point
// nearest the gaze (the radii where Visual-Polar's density falls to 1/4 and 1/16, from the Rust
// side). One sample per block, at the pixel nearest its centre (clamped to the screen); the
// other pixels are holes the way back fills. Rust: sampling::VrsTiles.
#ifndef FOVEA_SAMPLING_VRS_TILES_GLSL
#define FOVEA_SAMPLING_VRS_TILES_GLSL

// Pixels per block side of the tile holding `texel`.
int vrs_rate(ivec2 texel) {
    float tile = sampling.data.shape0.x;
    vec2 lo = floor(vec2(texel) / tile) * tile;
    vec2 gaze = sampling.data.gaze.xy;
    float d = length(clamp(gaze, lo, lo + tile) - gaze);
    return d < sampling.data.gaze.z ? 1 : (d < sampling.data.gaze.w ? 2 : 4);
}

bool sample_exists(ivec2 texel) {
    ivec2 screen = ivec2(sampling.data.grid.xy);
    if (any(lessThan(texel, ivec2(0))) || any(greaterThanEqual(texel, screen))) return false;
    int rate = vrs_rate(texel);
    return all(equal(texel, min(texel / rate * rate + rate / 2, screen - 1)));
}

bool sample_screen_position(ivec2 texel, vec2 jitter, out vec2 screen) {
    screen = vec2(texel) + jitter;
    return sample_exists(texel);
}

#endif
