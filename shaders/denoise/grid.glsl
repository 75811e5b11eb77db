// Addressing of a sampling grid (texel = sample) for the denoisers. The space-specific half —
// GRID_ROWS_WRAP, struct Grid, grid_make, grid_rows, grid_tap, grid_column_tap, grid_from_screen,
// grid_nearest, grid_bilinear — is one include per sampling space (shaders/sampling/<space>_grid.glsl), chosen
// by the kernel variant like the tracer's mapping; what every space shares is here.
// The parameters come as the four SamplingParams slots (push constants).
#ifndef FOVEA_DENOISE_GRID_GLSL
#define FOVEA_DENOISE_GRID_GLSL

// r mod n for any sign (GLSL's % is undefined for negative operands).
int grid_wrap(int r, int n) {
    return r - n * int(floor(float(r) / float(n)));
}

// Filter loops visit taps column by column: the row count of a column (divisions and a floor
// in Visual-Polar) is then computed once per column instead of once or twice per tap, which is
// most of a VP tap's cost on lavapipe. A tap found this way is exactly grid_tap's (same
// expression) and always holds a sample (its row is wrapped into the column).
struct GridColumn {
    int col;
    int rows;        // rows of `col`
    int rows_here;   // rows of the centre's column
};

#if defined(SAMPLING_CARTESIAN)
#include "../sampling/cartesian_grid.glsl"
#elif defined(SAMPLING_VISUAL_POLAR)
#include "../sampling/visual_polar_grid.glsl"
#else
#error "no sampling space selected"
#endif

// This frame's grid.
Grid grid_make(SamplingParams space) {
    return grid_make(space.grid, space.gaze, space.shape0, space.shape1);
}

// The previous frame's grid: its gaze-dependent slots on this frame's (unchanging) grid.
Grid grid_make(SamplingParams space, SamplingFrame previous) {
    return grid_make(space.grid, previous.gaze, previous.shape0, previous.shape1);
}

bool grid_holds_sample(Grid g, ivec2 t) {
    return t.x >= 0 && t.y >= 0 && t.x < g.size.x && t.y < grid_rows(g, t.x);
}

// The column `dx` texels away from t's; false when that leaves the grid.
bool grid_column(Grid g, ivec2 t, int rows_here, int dx, out GridColumn c) {
    c.col = t.x + dx;
    c.rows_here = rows_here;
    c.rows = (dx == 0 || c.col < 0 || c.col >= g.size.x) ? rows_here : grid_rows(g, c.col);
    return c.col >= 0 && c.col < g.size.x;
}

#endif
