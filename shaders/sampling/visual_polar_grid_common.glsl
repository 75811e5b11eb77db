// What both Visual-Polar grid addressings (visual_polar_grid.glsl, the paper's layout, and
// visual_polar_clipped_grid.glsl, the screen-clipped one) share: the grid and its rows per column.
#ifndef FOVEA_VISUAL_POLAR_GRID_COMMON_GLSL
#define FOVEA_VISUAL_POLAR_GRID_COMMON_GLSL

#include "visual_polar_math.glsl"

struct Grid {
    ivec2 size;
    VpParams vp;
};

Grid vp_grid_make(uvec4 grid, vec4 gaze, vec4 shape0, vec4 shape1) {
    Grid g;
    g.size = ivec2(grid.xy);
    g.vp = vp_unpack(grid, gaze, shape0, shape1);
    return g;
}

// Rows of column `col` that hold samples (the same count in both layouts).
int grid_rows(Grid g, int col) {
    return int(vp_rows_in_column(g.vp, uint(col)));
}

#endif
