#version 460
// One level of the φ-only mip chain of a Visual-Polar image: level l+1 averages pairs of φ rows
// of level l inside each column (building level 1 also copies level 0 into the stack, so the
// remap reads one image). ρ is never filtered: the remap magnifies (or keeps) ρ, while one screen
// pixel near the gaze spans many φ rows (visual-polar.md §6).
// Screen-clipped layout (visual_polar_clipped.glsl): a column whose rows cover only its on-screen
// arcs neither wraps (an odd last row keeps its own value) nor averages across the gap between two
// arcs (a pair split by a gap keeps the row on the output row's side).
// Two variants: lavapipe executes both sides of every branch, so the paper's layout with the
// normalised ρ axis gets a kernel with the screen-clipped path and the headset axis compiled out;
// `clipped` is the general kernel (either layout, either axis).
//! variant paper: VP_LAYOUT_PAPER VP_NORMALIZED_AXIS_ONLY
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
layout(push_constant) uniform Push { MipPhiPush p; } push;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D vp_color; // the traced image
layout(set = 0, binding = 2, rgba32f) uniform image2D mips;              // all levels, stacked
layout(set = 0, binding = 3) uniform samplerBuffer vp_columns;           // VisualPolar::column_table

vec4 vp_table_texel(uint i) {
    return texelFetch(vp_columns, int(i));
}

void main() {
    VpParams P = vp_unpack(push.p.space.grid, push.p.space.gaze, push.p.space.shape0, push.p.space.shape1);
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (uint(t.x) >= P.grid.x) return;
    uint src = push.p.config.x;
    uint rows0 = vp_rows_in_column(P, uint(t.x));
    uint src_rows = phi_mip_rows(rows0, src);
    // Rows past the column's count are never read by the remap.
    if (uint(t.y) >= phi_mip_rows(rows0, src + 1u)) return;
    uint a = 2u * uint(t.y);
    uint b = a + 1u == src_rows ? 0u : a + 1u; // a < src_rows: wraps without a per-lane division
    vec4 va, vb;
    if (src == 0u) {
        va = imageLoad(vp_color, ivec2(t.x, a));
        vb = imageLoad(vp_color, ivec2(t.x, b));
        imageStore(mips, ivec2(t.x, a), va);
        if (b != 0u) imageStore(mips, ivec2(t.x, b), vb);
    } else {
        uint offset = phi_mip_offset(src, P.grid.y);
        va = imageLoad(mips, ivec2(t.x, offset + a));
        vb = imageLoad(mips, ivec2(t.x, offset + b));
    }
    vec4 v = 0.5 * (va + vb);
    if (VP_LAYOUT_MAY_CLIP && P.clipped) {
        VpArcs arcs = vp_column_arcs(uint(t.x));
        if (!vp_arcs_wrap(arcs)) {
            // Rows by their centres, in level-0 rows.
            float n = float(rows0);
            float scale = float(1u << src);
            if (a + 1u == src_rows) {
                v = va;
            } else {
                int ia = vp_arcs_interval_of_row(arcs, (float(a) + 0.5) * scale, n);
                int ib = vp_arcs_interval_of_row(arcs, (float(a) + 1.5) * scale, n);
                if (ia != ib) {
                    int io = vp_arcs_interval_of_row(arcs, (float(t.y) + 0.5) * 2.0 * scale, n);
                    v = io == ib ? vb : va;
                }
            }
        }
    }
    imageStore(mips, ivec2(t.x, phi_mip_offset(src + 1u, P.grid.y) + uint(t.y)), v);
}
