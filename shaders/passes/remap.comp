#version 460
// Visual-Polar image → screen by backward mapping (visual-polar.md §6): every screen pixel finds
// its VP coordinate and samples there. ρ: bilinear between the two nearest columns (clamped at
// the ends); φ: wrapped, bilinear inside each column (its own row count), trilinear across the
// φ-only mips with the level picked from the pixel's φ footprint in that column.
// Screen-clipped layout (visual_polar_clipped.glsl): a column whose rows cover only its on-screen
// arcs is read along its arc position, clamped to the rows of the pixel's own arc at every level
// (no wrap, nothing across a gap); its rows are denser along φ by 2π/A, which the footprint uses.
// Near the border a pixel's angle may lie outside the outer column's arcs (that circle leaves the
// screen sooner): such a clamped column is trusted only within one of its φ texels of the pixel,
// beyond that the inner column (whose arcs hold the pixel) answers alone.
// Samples jittered inside their texel (screen-space TAA) are read where they were traced:
// sample_offset shifts the lookup by the jitter, in texels along ρ and in level-0 rows along φ.
// Two variants: lavapipe executes both sides of every branch, so the paper's layout with the
// normalised ρ axis and the quartic inverse CDF gets a kernel with the screen-clipped path, the
// headset axis and the exact CDF compiled out; `clipped` is the general kernel.
//! variant paper: VP_LAYOUT_PAPER VP_NORMALIZED_AXIS_ONLY VP_POLYNOMIAL_CDF_ONLY
//! variant clipped: VP_LAYOUT_CLIPPED
#include "../common/layouts.glsl"
#include "../sampling/visual_polar_clipped.glsl"
#include "../sampling/phi_mips.glsl"

#if defined(VP_LAYOUT_PAPER)
const bool VP_LAYOUT_MAY_CLIP = false;
#else
const bool VP_LAYOUT_MAY_CLIP = true;
#endif

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { RemapPush p; } push;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D mips;          // all levels, stacked
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D screen_color;
layout(set = 0, binding = 3) uniform samplerBuffer vp_columns;                // VisualPolar::column_table

vec4 vp_table_texel(uint i) {
    return texelFetch(vp_columns, int(i));
}

vec4 fetch(uint level, uint height, uint col, uint row) {
    return imageLoad(mips, ivec2(col, phi_mip_offset(level, height) + row));
}

// Linear along φ at one level; y0 = continuous row coordinate at level 0 (texel centres at +½).
vec4 sample_phi(uint col, uint rows0, float y0, uint level, uint height) {
    int m = int(phi_mip_rows(rows0, level));
    float y = y0 / float(1u << level) - 0.5;
    float f = floor(y);
    // y0 stays within half a row of [0, rows0), so both rows are at most one period off: adding
    // or subtracting m wraps them (an integer % becomes a per-lane scalar division on lavapipe).
    int a = int(f);
    a += a < 0 ? m : (a >= m ? -m : 0);
    int b = a + 1 == m ? 0 : a + 1;
    return mix(fetch(level, height, col, uint(a)), fetch(level, height, col, uint(b)), y - f);
}

// Linear along φ at one level, clamped to the rows whose centres lie in [lo0, hi0) (level-0 rows:
// one arc of a clipped column, the rule of vp_arcs_interval_of_row).
vec4 sample_phi_clamped(uint col, uint rows0, float y0, float lo0, float hi0, uint level, uint height) {
    float m = float(phi_mip_rows(rows0, level));
    float scale = float(1u << level);
    float first = max(ceil(lo0 / scale - 0.5), 0.0);
    float last = min(ceil(hi0 / scale - 0.5) - 1.0, m - 1.0);
    if (last < first) {
        // The arc is narrower than one row of this level: its nearest row.
        first = clamp(floor(y0 / scale), 0.0, m - 1.0);
        last = first;
    }
    float y = clamp(y0 / scale - 0.5, first, last);
    float f = floor(y);
    uint a = uint(f);
    uint b = min(a + 1u, uint(last));
    return mix(fetch(level, height, col, a), fetch(level, height, col, b), y - f);
}

// Level of detail from the φ footprint: one pixel spans 1/r radians, rows0/arc rows per radian.
float phi_lod(uint rows0, float arc, float r, uint levels) {
    float footprint = float(rows0) / (arc * max(r, 0.5));
    return clamp(log2(max(footprint, 1.0)), 0.0, float(levels - 1u));
}

// `trust` (out): 1 − the clamp distance in this column's φ texels, at least 0.
vec4 sample_column_clipped(VpParams P, VpArcs arcs, uint col, float phi, float r, uint levels, out float trust) {
    uint rows0 = vp_rows_in_column(P, col);
    float n = float(rows0);
    vec3 ai = vp_arc_of_phi(arcs, phi);
    int i = int(ai.y);
    trust = max(1.0 - vp_arc_row(arcs, ai.z, n), 0.0);
    float y0 = vp_arc_row(arcs, ai.x, n) - push.p.sample_offset.y;
    float lo0 = i == 0 ? -1e30 : vp_arc_row(arcs, vp_arcs_arc_start(arcs, i), n);
    float hi0 = i == vp_arcs_count(arcs) - 1 ? 1e30 : vp_arc_row(arcs, arcs.end[i], n);
    float lod = phi_lod(rows0, vp_arcs_total(arcs), r, levels);
    uint l0 = uint(lod);
    uint l1 = min(l0 + 1u, levels - 1u);
    vec4 v0 = sample_phi_clamped(col, rows0, y0, lo0, hi0, l0, P.grid.y);
    vec4 v1 = sample_phi_clamped(col, rows0, y0, lo0, hi0, l1, P.grid.y);
    return mix(v0, v1, lod - float(l0));
}

vec4 sample_column(VpParams P, uint col, float phi, float r, uint levels, out float trust) {
    trust = 1.0;
    if (VP_LAYOUT_MAY_CLIP && P.clipped) {
        VpArcs arcs = vp_column_arcs(col);
        if (!vp_arcs_wrap(arcs)) return sample_column_clipped(P, arcs, col, phi, r, levels, trust);
    }
    uint rows0 = vp_rows_in_column(P, col);
    float y0 = phi / VP_TAU * float(rows0) - push.p.sample_offset.y;
    float lod = phi_lod(rows0, VP_TAU, r, levels);
    uint l0 = uint(lod);
    float t = lod - float(l0);
    // The coarser level only where the footprint lies between two levels. A loop rather than a
    // second call: lavapipe leaves a loop once no lane of its batch needs another pass, and away
    // from the gaze (most of the screen) one pixel spans at most one row, so it reads level 0 only.
    uint last = t > 0.0 ? l0 + 1u : l0;
    vec4 v = vec4(0.0);
    for (uint l = l0; l <= last; ++l)
        v += (l == l0 ? 1.0 - t : t) * sample_phi(col, rows0, y0, l, P.grid.y);
    return v;
}

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(t, imageSize(screen_color)))) return;
    VpParams P = vp_unpack(push.p.space.grid, push.p.space.gaze, push.p.space.shape0, push.p.space.shape1);
    vec2 d = vec2(t) + 0.5 - P.gaze;
    float r = length(d);
    float phi = r > 0.0 ? atan(d.y, d.x) : 0.0;
    if (phi < 0.0) phi += VP_TAU;
    // Texel centres at integers; a jittered sample sits sample_offset texels beside its centre.
    float u = VP_LAYOUT_MAY_CLIP ? vp_layout_u_of_r(P, vp_axis_of_offset(P, d, r)) : vp_u_of_r(P, vp_axis_of_offset(P, d, r));
    float x = clamp(u * float(P.grid.x) - 0.5 - push.p.sample_offset.x, 0.0, float(P.grid.x - 1u));
    uint c0 = uint(x);
    uint c1 = min(c0 + 1u, P.grid.x - 1u);
    uint levels = max(push.p.config.x, 1u);
    float trust0, trust1;
    vec4 v0 = sample_column(P, c0, phi, r, levels, trust0);
    vec4 v1 = c1 == c0 ? v0 : sample_column(P, c1, phi, r, levels, trust1);
    float w1 = x - float(c0);
    if (c1 != c0 && trust1 < 1.0) {
        // Paper layout and full circles: trust is 1, plain linear along ρ.
        float a0 = (1.0 - w1) * trust0;
        float a1 = w1 * trust1;
        if (a0 + a1 > 0.0) w1 = a1 / (a0 + a1);
    }
    imageStore(screen_color, t, mix(v0, v1, w1));
}
