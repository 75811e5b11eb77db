// Cartesian sampling: one sample per screen pixel, jittered inside the pixel.
#ifndef FOVEA_SAMPLING_CARTESIAN_GLSL
#define FOVEA_SAMPLING_CARTESIAN_GLSL

// Whether `texel` holds a sample.
bool sample_exists(ivec2 texel) {
    return all(lessThan(texel, ivec2(sampling.data.grid.xy)));
}

// Screen position (pixels, y down) of the sample held by `texel`; false when the texel holds none.
bool sample_screen_position(ivec2 texel, vec2 jitter, out vec2 screen) {
    screen = vec2(texel) + jitter;
    return sample_exists(texel);
}

#endif
