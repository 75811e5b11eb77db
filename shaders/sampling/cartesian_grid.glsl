// Cartesian grid addressing for the denoisers (included by denoise/grid.glsl): the grid is the
// screen (or a coarser regular grid); nothing outside it.
#ifndef FOVEA_CARTESIAN_GRID_GLSL
#define FOVEA_CARTESIAN_GRID_GLSL

struct Grid {
    ivec2 size;
};

Grid grid_make(uvec4 grid, vec4 gaze, vec4 shape0, vec4 shape1, bool previous) {
    Grid g;
    g.size = ivec2(grid.xy);
    return g;
}

// Rows of column `col` that hold samples.
int grid_rows(Grid g, int col) {
    return g.size.y;
}

// Rows end at the grid like columns.
bool grid_column_wraps(Grid g, int col) {
    return false;
}

#include "../denoise/grid_column.glsl"

// The texel `o` steps away from the sample texel `t`; false when that leaves the grid.
bool grid_tap(Grid g, ivec2 t, ivec2 o, out ivec2 tap) {
    tap = t + o;
    return all(greaterThanEqual(tap, ivec2(0))) && all(lessThan(tap, g.size));
}

// The tap `dy` rows away from t, in column c; false when it leaves the grid.
bool grid_column_tap(GridColumn c, ivec2 t, int dy, out ivec2 tap) {
    tap = ivec2(c.col, t.y + dy);
    return tap.y >= 0 && tap.y < c.rows;
}

// Continuous grid position (texel centres at +½) of a screen position; false off the grid.
bool grid_from_screen(Grid g, vec2 screen, out vec2 p) {
    p = screen;
    return all(greaterThanEqual(p, vec2(0.0))) && all(lessThan(p, vec2(g.size)));
}

// The texel holding continuous grid position p (from grid_from_screen).
ivec2 grid_nearest(Grid g, vec2 p) {
    return clamp(ivec2(floor(p)), ivec2(0), g.size - 1);
}

// Bilinear footprint of continuous grid position p: four texels and their weights (taps may lie
// outside the grid: check grid_holds_sample).
void grid_bilinear(Grid g, vec2 p, out ivec2 taps[4], out vec4 w) {
    vec2 f = p - 0.5;
    ivec2 i0 = ivec2(floor(f));
    vec2 t = f - vec2(i0);
    taps[0] = i0;
    taps[1] = i0 + ivec2(0, 1);
    taps[2] = i0 + ivec2(1, 0);
    taps[3] = i0 + ivec2(1, 1);
    w = vec4((1.0 - t.x) * (1.0 - t.y), (1.0 - t.x) * t.y, t.x * (1.0 - t.y), t.x * t.y);
}

// Row of continuous grid position p as a row of column `col` (rows are the same everywhere).
float grid_row_in_column(Grid g, vec2 p, int col) {
    return p.y;
}

#endif
