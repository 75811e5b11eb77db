// Visual-Polar grid addressing for the denoisers (included by denoise/grid.glsl;
// visual-polar.md §5): φ (y) wraps; ρ (x) ends at the grid — filter taps beyond it are dropped
// (the kernels renormalise), bilinear taps clamp; column c keeps only its first n(c) rows
// (clipped texels hold no sample and are never read); a step across columns keeps the angle, row
// y of column c being at 2π(y + ½)/n(c). Parameters unpacked by vp_unpack.
#ifndef FOVEA_VISUAL_POLAR_GRID_GLSL
#define FOVEA_VISUAL_POLAR_GRID_GLSL

#include "visual_polar_grid_common.glsl"

Grid grid_make(uvec4 grid, vec4 gaze, vec4 shape0, vec4 shape1, bool previous) {
    return vp_grid_make(grid, gaze, shape0, shape1);
}

// Rows (φ) wrap around; columns (ρ) end at the grid.
bool grid_column_wraps(Grid g, int col) {
    return true;
}

#include "../denoise/grid_column.glsl"

// The texel `o` steps away from the sample texel `t` (o.y in φ steps of t's own column); false
// when that leaves the grid (on ρ only).
bool grid_tap(Grid g, ivec2 t, ivec2 o, out ivec2 tap) {
    int c = t.x + o.x;
    tap = t;
    if (c < 0 || c >= g.size.x) return false;
    int n0 = grid_rows(g, t.x);
    int n1 = o.x == 0 ? n0 : grid_rows(g, c);
    // The angle of the offset row's centre, as a row of column c.
    int r = int(floor((float(t.y) + 0.5 + float(o.y)) * float(n1) / float(n0)));
    tap = ivec2(c, grid_wrap(r, n1));
    return true;
}

// The tap `dy` rows (of t's column) away from t, in column c (always in the grid: φ wraps).
bool grid_column_tap(GridColumn c, ivec2 t, int dy, out ivec2 tap) {
    int r = int(floor((float(t.y) + 0.5 + float(dy)) * float(c.rows) / float(c.rows_here)));
    tap = ivec2(c.col, grid_wrap(r, c.rows));
    return true;
}

// Continuous grid position (texel centres at +½; y in rows of column floor(x)) of a screen
// position; false beyond the grid's last column.
bool grid_from_screen(Grid g, vec2 screen, out vec2 p) {
    p = vp_screen_to_vp(g.vp, screen);
    return p.x < float(g.size.x);
}

// The texel holding continuous grid position p (from grid_from_screen).
ivec2 grid_nearest(Grid g, vec2 p) {
    int c = clamp(int(floor(p.x)), 0, g.size.x - 1);
    return ivec2(c, grid_wrap(int(floor(p.y)), grid_rows(g, c)));
}

// Bilinear footprint of continuous grid position p: four texels and their weights. The two
// columns clamp on ρ and each gets p's angle in its own row count (neighbouring fovea columns
// differ), rows wrapping.
void grid_bilinear(Grid g, vec2 p, out ivec2 taps[4], out vec4 w) {
    vec2 f = p - 0.5;
    int c0 = int(floor(f.x));
    float wx = f.x - float(c0);
    float n_p = float(grid_rows(g, clamp(int(floor(p.x)), 0, g.size.x - 1)));
    for (int i = 0; i < 2; ++i) {
        int c = clamp(c0 + i, 0, g.size.x - 1);
        int n = grid_rows(g, c);
        float y = p.y * float(n) / n_p - 0.5;
        int r0 = int(floor(y));
        float wy = y - float(r0);
        float wc = i == 0 ? 1.0 - wx : wx;
        taps[2 * i] = ivec2(c, grid_wrap(r0, n));
        taps[2 * i + 1] = ivec2(c, grid_wrap(r0 + 1, n));
        w[2 * i] = wc * (1.0 - wy);
        w[2 * i + 1] = wc * wy;
    }
}

// Row of continuous grid position p (rows of column floor(p.x)) at the same angle in column `col`.
float grid_row_in_column(Grid g, vec2 p, int col) {
    float from = float(grid_rows(g, clamp(int(floor(p.x)), 0, g.size.x - 1)));
    return p.y * float(grid_rows(g, col)) / from;
}

#endif
