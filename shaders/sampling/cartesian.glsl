// Cartesian sampling: a regular grid over the screen, one sample per texel jittered inside it —
// one per pixel (`cartesian`), or coarser (`uniform-budget`: grid.xy < the screen, grid.zw).
#ifndef FOVEA_SAMPLING_CARTESIAN_GLSL
#define FOVEA_SAMPLING_CARTESIAN_GLSL

// Whether `texel` holds a sample.
bool sample_exists(ivec2 texel) {
    return all(lessThan(texel, ivec2(sampling.data.grid.xy)));
}

// Screen position (pixels, y down) of the sample held by `texel`; false when the texel holds none.
bool sample_screen_position(ivec2 texel, vec2 jitter, out vec2 screen) {
    screen = vec2(texel) + jitter;
    // Exactly the texel for one sample per pixel; scaled to the screen for a coarser grid.
    if (any(notEqual(sampling.data.grid.xy, sampling.data.grid.zw))) screen *= vec2(sampling.data.grid.zw) / vec2(sampling.data.grid.xy);
    return sample_exists(texel);
}

#endif
