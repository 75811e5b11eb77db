// Screen-clipped Visual-Polar layout (beyond the paper): GLSL twin of
// renderer/src/sampling/visual_polar_clipped.rs, function by function, same f32 operations.
// Each column keeps its rows but lays them on the on-screen part of its circle only: up to 4
// angular intervals, concatenated into an arc of total angle A; row y of a column with n rows sits
// at arc position a = y/n·A. The intervals are computed once per frame in Rust and read here from
// a per-column table (two RGBA32F texels per column: interval starts, cumulative ends), so this
// file only looks them up.
//
// The includer provides the table from its own binding (the trace: `sampling_table`; the passes
// back to the screen: a texel buffer):  vec4 vp_table_texel(uint i). A frame's table is its
// columns' arcs (2 texels each), then the screen-aware ρ axis' knots (VP_AXIS_KNOT_TEXELS; Rust
// visual_polar_screen_axis.rs); the view's table holds this frame's, then the previous frame's
// (the denoisers reproject through those): VpParams.arcs_base picks the frame.
#ifndef FOVEA_SAMPLING_VISUAL_POLAR_CLIPPED_GLSL
#define FOVEA_SAMPLING_VISUAL_POLAR_CLIPPED_GLSL

#include "visual_polar_math.glsl"

// Rust ColumnArcs. Unused slots repeat the total in `end` and the last interval's end angle in
// `start`, so lookups need no count.
struct VpArcs {
    vec4 start;  // φ where each interval starts, [0, 2π)
    vec4 end;    // cumulative arc length at each interval's end; end.w = A
};

vec4 vp_table_texel(uint i);

// Rust AXIS_PIECES and AXIS_KNOT_TEXELS (pieces + 1 knots, 4 per texel, padded to whole columns).
const uint VP_AXIS_PIECES = 128u;
const int VP_AXIS_SEARCH_STEPS = 7; // log2(VP_AXIS_PIECES)
const uint VP_AXIS_KNOT_TEXELS = 34u;

// Column slots one frame's table takes: its columns' arcs and the knots (the previous frame's
// table starts there).
uint vp_table_frame_columns(uint grid_width) {
    return grid_width + VP_AXIS_KNOT_TEXELS / 2u;
}

VpArcs vp_column_arcs(uint col) {
    return VpArcs(vp_table_texel(2u * col), vp_table_texel(2u * col + 1u));
}

// Knot j of the screen-aware axis of P's frame: r (pixels) at w = 1 − √(1 − p) = j / VP_AXIS_PIECES.
float vp_axis_knot(VpParams P, uint j) {
    return vp_table_texel(2u * (P.arcs_base + P.grid.x) + j / 4u)[j % 4u];
}

// Rust ScreenAxis::r_of_p: r piecewise linear in w = 1 − √(1 − p), p the periphery fraction
// (past p = 1: w = 1 + √(p − 1), r along the last piece).
float vp_axis_r_of_p(VpParams P, float p) {
    float q = 1.0 - p;
    float w = 1.0 - (q < 0.0 ? -sqrt(-q) : sqrt(q));
    float x = w * float(VP_AXIS_PIECES);
    uint i = uint(clamp(floor(x), 0.0, float(VP_AXIS_PIECES - 1u)));
    float t = x - float(i);
    float a = vp_axis_knot(P, i);
    float b = vp_axis_knot(P, i + 1u);
    return a + (b - a) * t;
}

// Rust ScreenAxis::p_of_r: the piece holding r by halving, then linear inside it.
float vp_axis_p_of_r(VpParams P, float r) {
    uint lo = 0u;
    uint hi = VP_AXIS_PIECES;
    for (int s = 0; s < VP_AXIS_SEARCH_STEPS; ++s) {
        uint mid = (lo + hi) / 2u;
        if (vp_axis_knot(P, mid) <= r) lo = mid;
        else hi = mid;
    }
    float a = vp_axis_knot(P, lo);
    float b = vp_axis_knot(P, lo + 1u);
    float t = b > a ? (r - a) / (b - a) : 0.0;
    float v = 1.0 - (float(lo) + t) / float(VP_AXIS_PIECES);
    return 1.0 - (v < 0.0 ? -(v * v) : v * v);
}

// The layout's ρ axis (Rust VisualPolar::r_of_u / u_of_r): the paper's, or past the fovea the
// screen-aware axis' knots.
float vp_layout_r_of_u(VpParams P, float u) {
    if (P.screen_axis && u >= P.u_f) return vp_axis_r_of_p(P, (u - P.u_f) / (1.0 - P.u_f));
    return vp_r_of_u(P, u);
}

float vp_layout_u_of_r(VpParams P, float r) {
    if (P.screen_axis && r >= P.r_f) return P.u_f + vp_axis_p_of_r(P, r) * (1.0 - P.u_f);
    return vp_u_of_r(P, r);
}

float vp_arcs_total(VpArcs c) {
    return c.end.w;
}

// Full circles (the paper's layout, or a circle wholly on the screen) wrap on φ; clipped arcs clamp.
bool vp_arcs_wrap(VpArcs c) {
    return c.end.w >= VP_TAU;
}

// Arc position where interval i begins.
float vp_arcs_arc_start(VpArcs c, int i) {
    return i == 0 ? 0.0 : c.end[i - 1];
}

// Intervals in use (1 to 4).
int vp_arcs_count(VpArcs c) {
    return 1 + int(c.end.y > c.end.x) + int(c.end.z > c.end.y) + int(c.end.w > c.end.z);
}

// Arc position → φ (full circles: φ = a, any a; clipped: a clamped to [0, A]).
float vp_phi_of_arc(VpArcs c, float a) {
    if (vp_arcs_wrap(c)) return a;
    a = clamp(a, 0.0, vp_arcs_total(c));
    int i = int(a >= c.end.x) + int(a >= c.end.y) + int(a >= c.end.z);
    return c.start[i] + (a - vp_arcs_arc_start(c, i));
}

// φ ∈ [0, 2π) → arc position (x), its interval (y) and how far it was clamped (z, radians):
// angles in a gap clamp to the nearest end, 0 inside the arcs.
vec3 vp_arc_of_phi(VpArcs c, float phi) {
    if (vp_arcs_wrap(c)) return vec3(phi, 0.0, 0.0);
    float best = 1e30; // any distance > 2π
    float best_a = 0.0;
    int best_i = 0;
    for (int i = 0; i < 4; ++i) {
        float a0 = vp_arcs_arc_start(c, i);
        float len = c.end[i] - a0;
        if (len > 0.0) {
            float d = phi - c.start[i];
            if (d < 0.0) d += VP_TAU;
            if (d <= len) return vec3(a0 + d, float(i), 0.0);
            float to_end = d - len;
            float to_start = VP_TAU - d;
            if (to_end < best) {
                best = to_end;
                best_a = c.end[i];
                best_i = i;
            }
            if (to_start < best) {
                best = to_start;
                best_a = a0;
                best_i = i;
            }
        }
    }
    return vec3(best_a, float(best_i), best);
}

// Continuous row (level-0 units) of arc position a in a column with n rows.
float vp_arc_row(VpArcs c, float a, float n) {
    return a / vp_arcs_total(c) * n;
}

// The interval a continuous row y (level-0 units) belongs to: rows before the first interval
// count as the first, rows past the last as the last. The φ mips average only rows of one interval
// and the remap only reads those of the pixel's, so nothing is blended across a gap.
int vp_arcs_interval_of_row(VpArcs c, float y, float n) {
    int i = 0;
    for (int j = 1; j < 4; ++j)
        if (c.end[j] > c.end[j - 1] && y >= vp_arc_row(c, c.end[j - 1], n)) i = j;
    return i;
}

// Grid → screen in the screen-clipped layout.
vec2 vp_clipped_vp_to_screen(VpParams P, vec2 g) {
    uint col = vp_column_of(P, g.x);
    float n = float(vp_rows_in_column(P, col));
    VpArcs arcs = vp_column_arcs(P.arcs_base + col);
    float phi = vp_phi_of_arc(arcs, g.y / n * vp_arcs_total(arcs));
    float r = vp_layout_r_of_u(P, g.x / float(P.grid.x));
    return P.gaze + r * vec2(cos(phi), sin(phi));
}

// Screen → grid in the screen-clipped layout; y in [0, rows of the column).
vec2 vp_clipped_screen_to_vp(VpParams P, vec2 s) {
    vec2 d = s - P.gaze;
    float r = length(d);
    float phi = r > 0.0 ? atan(d.y, d.x) : 0.0;
    if (phi < 0.0) phi += VP_TAU;
    float x = vp_layout_u_of_r(P, r) * float(P.grid.x);
    uint col = vp_column_of(P, x);
    float n = float(vp_rows_in_column(P, col));
    VpArcs arcs = vp_column_arcs(P.arcs_base + col);
    float y = vp_arc_row(arcs, vp_arc_of_phi(arcs, phi).x, n);
    // y = n is φ = 2π on a full circle (row 0) or a clipped arc's far end (its last row).
    if (y >= n) y = vp_arcs_wrap(arcs) ? 0.0 : uintBitsToFloat(floatBitsToUint(n) - 1u);
    return vec2(x, y);
}

// The mapping of whichever layout P was packed with.
vec2 vp_layout_vp_to_screen(VpParams P, vec2 g) {
    return P.clipped ? vp_clipped_vp_to_screen(P, g) : vp_vp_to_screen(P, g);
}

vec2 vp_layout_screen_to_vp(VpParams P, vec2 s) {
    return P.clipped ? vp_clipped_screen_to_vp(P, s) : vp_screen_to_vp(P, s);
}

#endif
