// Addressing of a sampling grid (texel = sample) for the denoisers, one implementation per space,
// chosen by the kernel variant like the tracer's (SAMPLING_CARTESIAN / SAMPLING_VISUAL_POLAR).
// Cartesian: the screen; nothing outside it. Visual-Polar (visual-polar.md §5): φ (y) wraps; ρ (x)
// ends at the grid — filter taps beyond it are dropped (the kernels renormalise), bilinear taps
// clamp; column c keeps only its first n(c) rows (clipped texels hold no sample and are never
// read); a step across columns keeps the angle, row y of column c being at 2π(y + ½)/n(c).
// The parameters come as the four SamplingParams slots (push constants; unpacked by vp_unpack).
#ifndef FOVEA_DENOISE_GRID_GLSL
#define FOVEA_DENOISE_GRID_GLSL

#include "../sampling/visual_polar_math.glsl"

struct Grid {
    ivec2 size;
#if defined(SAMPLING_VISUAL_POLAR)
    VpParams vp;
#endif
};

Grid grid_make(uvec4 grid, vec4 gaze, vec4 shape0, vec4 shape1) {
    Grid g;
    g.size = ivec2(grid.xy);
#if defined(SAMPLING_VISUAL_POLAR)
    g.vp = vp_unpack(grid, gaze, shape0, shape1);
#endif
    return g;
}

// This frame's grid.
Grid grid_make(SamplingParams space) {
    return grid_make(space.grid, space.gaze, space.shape0, space.shape1);
}

// The previous frame's grid: its gaze-dependent slots on this frame's (unchanging) grid.
Grid grid_make(SamplingParams space, SamplingFrame previous) {
    return grid_make(space.grid, previous.gaze, previous.shape0, previous.shape1);
}

// Rows of column `col` that hold samples.
int grid_rows(Grid g, int col) {
#if defined(SAMPLING_VISUAL_POLAR)
    return int(vp_rows_in_column(g.vp, uint(col)));
#else
    return g.size.y;
#endif
}

bool grid_holds_sample(Grid g, ivec2 t) {
    return t.x >= 0 && t.y >= 0 && t.x < g.size.x && t.y < grid_rows(g, t.x);
}

// r mod n for any sign (GLSL's % is undefined for negative operands).
int grid_wrap(int r, int n) {
    return r - n * int(floor(float(r) / float(n)));
}

// The texel `o` steps away from the sample texel `t` (o.y in φ steps of t's own column); false
// when that leaves the grid (Cartesian: any side; Visual-Polar: ρ only).
bool grid_tap(Grid g, ivec2 t, ivec2 o, out ivec2 tap) {
#if defined(SAMPLING_VISUAL_POLAR)
    int c = t.x + o.x;
    tap = t;
    if (c < 0 || c >= g.size.x) return false;
    int n0 = grid_rows(g, t.x);
    int n1 = o.x == 0 ? n0 : grid_rows(g, c);
    // The angle of the offset row's centre, as a row of column c.
    int r = int(floor((float(t.y) + 0.5 + float(o.y)) * float(n1) / float(n0)));
    tap = ivec2(c, grid_wrap(r, n1));
    return true;
#else
    tap = t + o;
    return all(greaterThanEqual(tap, ivec2(0))) && all(lessThan(tap, g.size));
#endif
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

// The column `dx` texels away from t's; false when that leaves the grid.
bool grid_column(Grid g, ivec2 t, int rows_here, int dx, out GridColumn c) {
    c.col = t.x + dx;
    c.rows_here = rows_here;
    c.rows = (dx == 0 || c.col < 0 || c.col >= g.size.x) ? rows_here : grid_rows(g, c.col);
    return c.col >= 0 && c.col < g.size.x;
}

// The tap `dy` rows (of t's column) away from t, in column c; false when it leaves the grid.
bool grid_column_tap(GridColumn c, ivec2 t, int dy, out ivec2 tap) {
#if defined(SAMPLING_VISUAL_POLAR)
    int r = int(floor((float(t.y) + 0.5 + float(dy)) * float(c.rows) / float(c.rows_here)));
    tap = ivec2(c.col, grid_wrap(r, c.rows));
    return true;
#else
    tap = ivec2(c.col, t.y + dy);
    return tap.y >= 0 && tap.y < c.rows;
#endif
}

// Continuous grid position (texel centres at +½; Visual-Polar y in rows of column floor(x)) of a
// screen position; false where the grid holds no sample there.
bool grid_from_screen(Grid g, vec2 screen, out vec2 p) {
#if defined(SAMPLING_VISUAL_POLAR)
    p = vp_screen_to_vp(g.vp, screen);
    return p.x < float(g.size.x);
#else
    p = screen;
    return all(greaterThanEqual(p, vec2(0.0))) && all(lessThan(p, vec2(g.size)));
#endif
}

// The texel holding continuous grid position p (from grid_from_screen).
ivec2 grid_nearest(Grid g, vec2 p) {
#if defined(SAMPLING_VISUAL_POLAR)
    int c = clamp(int(floor(p.x)), 0, g.size.x - 1);
    return ivec2(c, grid_wrap(int(floor(p.y)), grid_rows(g, c)));
#else
    return clamp(ivec2(floor(p)), ivec2(0), g.size - 1);
#endif
}

// Bilinear footprint of continuous grid position p: four texels and their weights. Cartesian taps
// may lie outside the grid (check grid_holds_sample). Visual-Polar: the two columns clamp on ρ and
// each gets p's angle in its own row count (neighbouring fovea columns differ), rows wrapping.
void grid_bilinear(Grid g, vec2 p, out ivec2 taps[4], out vec4 w) {
    vec2 f = p - 0.5;
    int c0 = int(floor(f.x));
    float wx = f.x - float(c0);
#if defined(SAMPLING_VISUAL_POLAR)
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
#else
    int r0 = int(floor(f.y));
    float wy = f.y - float(r0);
    taps[0] = ivec2(c0, r0);
    taps[1] = ivec2(c0, r0 + 1);
    taps[2] = ivec2(c0 + 1, r0);
    taps[3] = ivec2(c0 + 1, r0 + 1);
    w = vec4((1.0 - wx) * (1.0 - wy), (1.0 - wx) * wy, wx * (1.0 - wy), wx * wy);
#endif
}

#endif
