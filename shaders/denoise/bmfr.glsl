// BMFR (Koskela et al. 2019, TOG) helpers shared by its kernels: which block a texel belongs to
// (and which texel a block's row is), the features of a texel, and the reprojection both temporal
// passes take the same taps with.
//
// Blocks: BMFR_BLOCK² texels, the grid shifted by `shift` = 16 − offset ∈ [2, 32] texels per axis
// (offset ∈ [−16, 14] changes every frame), so block b starts at b·32 − shift and the grid needs
// one block more than it covers: ceil(size / 32) + 1 per axis (bmfr_block_count).
//
// Visual-Polar: ρ (x) is blocked like the Cartesian x. φ (y) wraps, and columns have different
// row counts n(c) (the fovea's triangular clip). The design note's staircase clip would make n(c)
// constant inside each block column, which changes the traced layout (tracer, mips, remap); BMFR
// does not do that. Instead a block column of reference height N (its tallest column) places each
// texel (c, y) at the virtual row v = floor((y + ½)·N / n(c)) — the same angle at height N — and
// blocks are 32 consecutive virtual rows counted from v = shift, wrapping at N. Every valid texel
// has exactly one virtual row, hence exactly one block, blocks cross the φ seam like any other
// angle, and clipped texels (y ≥ n(c)) never enter a fit. A virtual row that is not some texel's
// own (columns shorter than N) is an empty (zero) row of the least-squares matrix.
#ifndef FOVEA_DENOISE_BMFR_GLSL
#define FOVEA_DENOISE_BMFR_GLSL

#include "grid.glsl"

const int BMFR_SIDE = int(BMFR_BLOCK);

// Reprojection accepts a previous sample whose position (moved into this frame's camera-relative
// space) lies within this many texel footprints (world distance to the nearer neighbour texel,
// the larger over the two grid axes: bilinear taps lie up to ~1.4 texels away) plus a share of the
// depth, and whose normal is within ~25°.
const float BMFR_REPROJECT_FOOTPRINTS = 2.0;
const float BMFR_REPROJECT_DEPTH_SLACK = 0.01;
const float BMFR_REPROJECT_NORMAL_COS = 0.9;
// A history length cap that keeps the count exact in fp32 (the α floors bound the weights long
// before it).
const float BMFR_MAX_HISTORY = 1024.0;

ivec2 bmfr_block_count(Grid g) {
    return (g.size + BMFR_SIDE - 1) / BMFR_SIDE + 1;
}

#if defined(SAMPLING_VISUAL_POLAR)
// Rows of the tallest column of block column bx (rows grow with ρ: its last column in the grid).
int bmfr_reference_rows(Grid g, int bx, int shift_x) {
    return grid_rows(g, clamp(bx * BMFR_SIDE - shift_x + BMFR_SIDE - 1, 0, g.size.x - 1));
}

// Virtual row of texel row y of a column with n rows, at height big_n (integer: exact).
int bmfr_virtual_row(int y, int n, int big_n) {
    return ((2 * y + 1) * big_n) / (2 * n);
}
#endif

// The block of texel t (which must hold a sample) and its slot (column, row) inside the block.
void bmfr_block_of(Grid g, ivec2 t, ivec2 shift, out ivec2 block, out ivec2 slot) {
    int x = t.x + shift.x;
#if defined(SAMPLING_VISUAL_POLAR)
    int bx = x / BMFR_SIDE;
    int big_n = bmfr_reference_rows(g, bx, shift.x);
    int u = grid_wrap(bmfr_virtual_row(t.y, grid_rows(g, t.x), big_n) + shift.y, big_n);
    block = ivec2(bx, u / BMFR_SIDE);
    slot = ivec2(x % BMFR_SIDE, u % BMFR_SIDE);
#else
    ivec2 p = t + shift;
    block = p / BMFR_SIDE;
    slot = p % BMFR_SIDE;
#endif
}

// The texel in `slot` of `block`; false when that slot holds no sample (outside the grid, a
// clipped texel, a virtual row without a texel of its own).
bool bmfr_block_texel(Grid g, ivec2 block, ivec2 slot, ivec2 shift, out ivec2 t) {
    t.x = block.x * BMFR_SIDE - shift.x + slot.x;
#if defined(SAMPLING_VISUAL_POLAR)
    t.y = 0;
    if (t.x < 0 || t.x >= g.size.x) return false;
    int big_n = bmfr_reference_rows(g, block.x, shift.x);
    int u = block.y * BMFR_SIDE + slot.y;
    if (u >= big_n) return false;
    int n = grid_rows(g, t.x);
    int v = grid_wrap(u - shift.y, big_n);
    t.y = ((2 * v + 1) * n) / (2 * big_n);
    return bmfr_virtual_row(t.y, n, big_n) == v;
#else
    t.y = block.y * BMFR_SIDE - shift.y + slot.y;
    return grid_holds_sample(g, t);
#endif
}

// Positions enter the features min/max-scaled per block where the block's range exceeds 1:
// p' = (p − offset)·scale (offset 0 and scale 1 elsewhere).
void bmfr_features(vec3 normal, vec3 position, vec3 offset, vec3 scale, out float f[10]) {
    vec3 p = (position - offset) * scale;
    f[0] = 1.0;
    f[1] = normal.x;
    f[2] = normal.y;
    f[3] = normal.z;
    f[4] = p.x;
    f[5] = p.y;
    f[6] = p.z;
    f[7] = p.x * p.x;
    f[8] = p.y * p.y;
    f[9] = p.z * p.z;
}

// Bilinear taps of the previous frame (through the previous frame's space) that show this
// surface: the same kind (`kind` and the history's position w: > 0 surface, < 0 emitter, 0 miss),
// and for hits the previous position (moved by `shift` into this
// frame's camera-relative space) within `tolerance` and the normal within ~25°. Rejected taps
// weigh 0; false when nothing usable is left. Reads the history images `prev_position`
// (xyz camera-relative, w the kind) and `prev_normal`, which a kernel that defines
// BMFR_REPROJECT binds before including this file.
#if defined(BMFR_REPROJECT)
bool bmfr_reproject(Grid prev, vec2 prev_screen, vec3 p, vec3 n, float kind, float tolerance, vec3 shift,
                    out ivec2 taps[4], out vec4 w) {
    w = vec4(0.0);
    for (int i = 0; i < 4; ++i) taps[i] = ivec2(0);
    vec2 q;
    if (prev_screen == vec2(-1.0) || !grid_from_screen(prev, prev_screen, q)) return false;
    grid_bilinear(prev, q, taps, w);
    for (int i = 0; i < 4; ++i) {
        if (w[i] <= 0.0 || !grid_holds_sample(prev, taps[i])) {
            w[i] = 0.0;
            continue;
        }
        vec4 pp = imageLoad(prev_position, taps[i]);
        vec3 pn = imageLoad(prev_normal, taps[i]).xyz;
        bool same = sign(pp.w) == sign(kind);
        if (kind != 0.0 && same) {
            float len = length(pn);
            same = distance(p, pp.xyz + shift) <= tolerance && len > 0.0 && dot(n, pn) >= BMFR_REPROJECT_NORMAL_COS * len;
        }
        if (!same || any(isnan(pp))) w[i] = 0.0;
    }
    return w.x + w.y + w.z + w.w >= 0.01;
}

float bmfr_tolerance(float footprint, float depth) {
    return BMFR_REPROJECT_FOOTPRINTS * footprint + BMFR_REPROJECT_DEPTH_SLACK * depth;
}
#endif

#endif
