// Addressing of a sampling grid (texel = sample) for the denoisers. The space-specific half —
// struct Grid, grid_make, grid_rows, grid_column_wraps, grid_tap, struct GridColumn, grid_column,
// grid_column_tap, grid_from_screen, grid_nearest, grid_bilinear, grid_row_in_column — is one
// include per sampling space (shaders/sampling/<space>_grid.glsl), chosen by the kernel variant
// like the tracer's mapping; what every space shares is here.
// The parameters come as the four SamplingParams slots (push constants).
#ifndef FOVEA_DENOISE_GRID_GLSL
#define FOVEA_DENOISE_GRID_GLSL

// r mod n for any sign (GLSL's % is undefined for negative operands).
int grid_wrap(int r, int n) {
    return r - n * int(floor(float(r) / float(n)));
}

#if defined(SAMPLING_CARTESIAN)
#include "../sampling/cartesian_grid.glsl"
#elif defined(SAMPLING_VISUAL_POLAR_CLIPPED)
#include "../sampling/visual_polar_clipped_grid.glsl"
#elif defined(SAMPLING_VISUAL_POLAR)
#include "../sampling/visual_polar_grid.glsl"
#else
#error "no sampling space selected"
#endif

// This frame's grid.
Grid grid_make(SamplingParams space) {
    return grid_make(space.grid, space.gaze, space.shape0, space.shape1, false);
}

// The previous frame's grid: its gaze-dependent slots on this frame's (unchanging) grid (and, in
// a space with a per-frame table, the previous frame's half of it).
Grid grid_make(SamplingParams space, SamplingFrame previous) {
    return grid_make(space.grid, previous.gaze, previous.shape0, previous.shape1, true);
}

bool grid_holds_sample(Grid g, ivec2 t) {
    return t.x >= 0 && t.y >= 0 && t.x < g.size.x && t.y < grid_rows(g, t.x);
}

#endif
