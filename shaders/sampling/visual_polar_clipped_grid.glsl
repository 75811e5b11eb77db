// Screen-clipped Visual-Polar grid addressing for the denoisers (included by denoise/grid.glsl):
// the paper's grid (visual_polar_grid.glsl) with each column's rows laid on the on-screen part of
// its circle (visual_polar_clipped.glsl: up to 4 arcs, concatenated). Rows wrap only in columns
// whose circle lies wholly on the screen; elsewhere a column ends at its arc's ends, and a tap never
// crosses from one arc to the next (the two lie on different borders of the screen). A step across
// columns keeps the screen angle φ, through both columns' arcs, and is dropped where φ is off the
// screen in the other column. The arcs are the view's sampling table (this frame's columns, then
// the previous frame's), bound as `grid_columns`.
#ifndef FOVEA_VISUAL_POLAR_CLIPPED_GRID_GLSL
#define FOVEA_VISUAL_POLAR_CLIPPED_GRID_GLSL

#include "visual_polar_clipped.glsl"
#include "visual_polar_grid_common.glsl"

// Above every binding of the kernels that include this file.
layout(set = 0, binding = 31) uniform samplerBuffer grid_columns;

vec4 vp_table_texel(uint i) {
    return texelFetch(grid_columns, int(i));
}

// An angle off the other column's arcs by up to this many of its rows still lands on its end row:
// the circle at a neighbouring radius meets the border a little earlier or later.
const float GRID_ARC_SLACK_ROWS = 0.5;

Grid grid_make(uvec4 grid, vec4 gaze, vec4 shape0, vec4 shape1, bool previous) {
    Grid g = vp_grid_make(grid, gaze, shape0, shape1);
    g.vp.arcs_base = previous ? vp_table_frame_columns(grid.x) : 0u;
    return g;
}

VpArcs grid_arcs(Grid g, int col) {
    return vp_column_arcs(g.vp.arcs_base + uint(col));
}

// Full circles wrap on φ; clipped arcs end.
bool grid_column_wraps(Grid g, int col) {
    return vp_arcs_wrap(grid_arcs(g, col));
}

// φ ∈ [0, 2π) of continuous row position y in a column (arcs a, n rows).
float grid_phi_of_row(VpArcs a, float y, float n) {
    float phi = vp_phi_of_arc(a, y / n * vp_arcs_total(a));
    return phi - VP_TAU * floor(phi / VP_TAU);
}

// Continuous row position of angle φ in a column (arcs a, n rows); false where φ is off the screen
// there by more than GRID_ARC_SLACK_ROWS (y is then the nearest arc end).
bool grid_row_of_phi(VpArcs a, float phi, float n, out float y) {
    vec3 r = vp_arc_of_phi(a, phi);
    y = vp_arc_row(a, r.x, n);
    return r.z / vp_arcs_total(a) * n <= GRID_ARC_SLACK_ROWS;
}

// Whether row position y lies on the same arc of a column (arcs a, n rows) as row position y0.
bool grid_same_arc(VpArcs a, float n, float y0, float y) {
    if (vp_arcs_wrap(a)) return true;
    return y >= 0.0 && y < n && vp_arcs_interval_of_row(a, y0, n) == vp_arcs_interval_of_row(a, y, n);
}

// A column of a filter's footprint with both columns' arcs, fetched once per column.
struct GridColumn {
    int col;
    int rows;        // rows of `col`
    int rows_here;   // rows of the centre's column
    VpArcs arcs;
    VpArcs arcs_here;
};

// The column `dx` texels away from t's; false when that leaves the grid.
bool grid_column(Grid g, ivec2 t, int rows_here, int dx, out GridColumn c) {
    c.col = t.x + dx;
    c.rows_here = rows_here;
    bool inside = c.col >= 0 && c.col < g.size.x;
    c.arcs_here = grid_arcs(g, t.x);
    bool same = dx == 0 || !inside;
    c.rows = same ? rows_here : grid_rows(g, c.col);
    c.arcs = same ? c.arcs_here : grid_arcs(g, c.col);
    return inside;
}

// The tap `dy` rows (of t's column) away from t, in column c: false off t's arc, or where that
// angle is off the screen in column c.
bool grid_column_tap(GridColumn c, ivec2 t, int dy, out ivec2 tap) {
    tap = t;
    float n0 = float(c.rows_here);
    float y = float(t.y) + 0.5 + float(dy);
    if (!grid_same_arc(c.arcs_here, n0, float(t.y) + 0.5, y)) return false;
    if (c.col == t.x) {
        tap = ivec2(t.x, grid_wrap(int(floor(y)), c.rows));
        return true;
    }
    float y1;
    if (!grid_row_of_phi(c.arcs, grid_phi_of_row(c.arcs_here, y, n0), float(c.rows), y1)) return false;
    int r = int(floor(y1));
    tap = ivec2(c.col, vp_arcs_wrap(c.arcs) ? grid_wrap(r, c.rows) : clamp(r, 0, c.rows - 1));
    return true;
}

// The texel `o` steps away from the sample texel `t` (o.y in rows of t's own column).
bool grid_tap(Grid g, ivec2 t, ivec2 o, out ivec2 tap) {
    GridColumn c;
    tap = t;
    return grid_column(g, t, grid_rows(g, t.x), o.x, c) && grid_column_tap(c, t, o.y, tap);
}

// Continuous grid position (texel centres at +½; y in rows of column floor(x)) of a screen
// position; false beyond the grid's last column.
bool grid_from_screen(Grid g, vec2 screen, out vec2 p) {
    p = vp_clipped_screen_to_vp(g.vp, screen);
    return p.x < float(g.size.x);
}

// The texel holding continuous grid position p (from grid_from_screen).
ivec2 grid_nearest(Grid g, vec2 p) {
    int c = clamp(int(floor(p.x)), 0, g.size.x - 1);
    int n = grid_rows(g, c);
    int r = int(floor(p.y));
    return ivec2(c, grid_column_wraps(g, c) ? grid_wrap(r, n) : clamp(r, 0, n - 1));
}

// Row of continuous grid position p (rows of column floor(p.x)) at the same angle in column `col`
// (the nearest arc end where that angle is off the screen there).
float grid_row_in_column(Grid g, vec2 p, int col) {
    int from = clamp(int(floor(p.x)), 0, g.size.x - 1);
    if (col == from) return p.y;
    float y;
    grid_row_of_phi(grid_arcs(g, col), grid_phi_of_row(grid_arcs(g, from), p.y, float(grid_rows(g, from))), float(grid_rows(g, col)), y);
    return y;
}

// Bilinear footprint of continuous grid position p: four texels and their weights. The two
// columns clamp on ρ and each gets p's angle through its own arcs (weight 0 where that angle is off
// the screen); rows wrap on full circles, and on clipped arcs clamp to the arc's ends and weigh 0
// on another arc.
void grid_bilinear(Grid g, vec2 p, out ivec2 taps[4], out vec4 w) {
    vec2 f = p - 0.5;
    int c0 = int(floor(f.x));
    float wx = f.x - float(c0);
    int cp = clamp(int(floor(p.x)), 0, g.size.x - 1);
    VpArcs ap = grid_arcs(g, cp);
    float phi = grid_phi_of_row(ap, p.y, float(grid_rows(g, cp)));
    for (int i = 0; i < 2; ++i) {
        int c = clamp(c0 + i, 0, g.size.x - 1);
        int n = grid_rows(g, c);
        VpArcs a = c == cp ? ap : grid_arcs(g, c);
        float yc = p.y;
        bool on = c == cp || grid_row_of_phi(a, phi, float(n), yc);
        float wc = on ? (i == 0 ? 1.0 - wx : wx) : 0.0;
        bool wraps = vp_arcs_wrap(a);
        int arc = vp_arcs_interval_of_row(a, yc, float(n));
        float y = yc - 0.5;
        int r0 = int(floor(y));
        float wy = y - float(r0);
        for (int k = 0; k < 2; ++k) {
            int r = wraps ? grid_wrap(r0 + k, n) : clamp(r0 + k, 0, n - 1);
            bool same = wraps || vp_arcs_interval_of_row(a, float(r) + 0.5, float(n)) == arc;
            taps[2 * i + k] = ivec2(c, r);
            w[2 * i + k] = same ? wc * (k == 0 ? 1.0 - wy : wy) : 0.0;
        }
    }
}

#endif
