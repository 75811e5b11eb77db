#version 460
// BMFR per-block fit (Koskela et al. 2019, §3): one workgroup per 32×32 block solves the
// least-squares problem [10 features | RGB] (1024 × 13, one row per texel) by Householder QR and
// back-substitution, giving 10 weights per colour channel. Rows of texels without a sample or
// without a hit are zero. Each lane keeps its own BMFR_BLOCK² / BMFR_FIT_LANES rows in registers;
// the column sums a reflection needs are reduced in shared memory, one lane per column (two
// barriers per reduction: lavapipe pays for every barrier with a pass over all lanes, so a
// log-depth tree of barriers costs it more than 13 lanes summing a column each).
// Positions are min/max-scaled per block where their range exceeds 1; features except the
// constant get uniform noise of ±params.x (stochastic regularisation: no exactly collinear
// columns). A column left with a near-zero norm is skipped (weight 0): rank-deficient blocks.
// Writes BMFR_WEIGHT_TEXELS texels per block: 10 × rgb weights, then the position offset and scale.
//! variants per space
#include "../../common/layouts.glsl"
#include "../../common/random.glsl"
#include "../../denoise/bmfr.glsl"

layout(local_size_x = BMFR_FIT_LANES) in;
layout(push_constant) uniform Push { BmfrBlockPush p; } push;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D noisy;               // accumulated rgb
layout(set = 0, binding = 1, rgba16f) uniform readonly image2D normal;              // accumulated
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D features_position;   // xyz, w footprint (0: miss)
layout(set = 0, binding = 3, rgba32f) uniform writeonly image2D weights;

const int LANES = int(BMFR_FIT_LANES);
const int ROWS = BMFR_SIDE * BMFR_SIDE / LANES;
const int COLUMNS = int(BMFR_FEATURES) + 3;
// A column whose remaining norm² (below the rows of R built so far) is below this share of its
// initial norm² lies in the span of the columns before it (≈ 3e-4 relative norm: fp32 round-off
// leaves ~1e-6, the ±1e-2 regularisation noise ~1e-2 on O(1) features); an all-zero column too.
const float BMFR_MIN_RELATIVE_NORM2 = 1e-7;
const float BMFR_MIN_NORM2 = 1e-20;

shared float sums[COLUMNS][LANES];
shared float totals[COLUMNS];
shared float pivot_values[COLUMNS];
shared float r_rows[BMFR_FEATURES][COLUMNS];
shared int pivots[BMFR_FEATURES];
shared vec3 solved[BMFR_FEATURES];

// Sums sums[j][·] over the lanes into totals[j] (min or max for the scaling pass).
void reduce(int lane, int op) {
    barrier();
    if (lane < COLUMNS) {
        float acc = sums[lane][0];
        for (int l = 1; l < LANES; ++l) {
            float b = sums[lane][l];
            acc = op == 0 ? acc + b : (op == 1 ? min(acc, b) : max(acc, b));
        }
        totals[lane] = acc;
    }
    barrier();
}

void main() {
    int lane = int(gl_LocalInvocationID.x);
    ivec2 block = ivec2(gl_WorkGroupID.xy);
    Grid g = grid_make(push.p.space);
    ivec2 shift = 16 - push.p.config.xy;

    bool valid[ROWS];
    vec3 pos[ROWS];
    vec3 nrm[ROWS];
    vec3 rgb[ROWS];
    for (int i = 0; i < ROWS; ++i) {
        int s = i * LANES + lane;
        ivec2 t;
        valid[i] = bmfr_block_texel(g, block, ivec2(s % BMFR_SIDE, s / BMFR_SIDE), shift, t);
        vec4 p = valid[i] ? imageLoad(features_position, t) : vec4(0.0);
        valid[i] = valid[i] && p.w > 0.0;
        pos[i] = p.xyz;
        nrm[i] = valid[i] ? imageLoad(normal, t).xyz : vec3(0.0);
        rgb[i] = valid[i] ? imageLoad(noisy, t).rgb : vec3(0.0);
    }

    // Per-block position range: min in sums[0..2], max in sums[3..5] (one min and one max pass).
    for (int j = 0; j < COLUMNS; ++j) sums[j][lane] = 3.0e38;
    for (int i = 0; i < ROWS; ++i) {
        for (int a = 0; a < 3; ++a) sums[a][lane] = min(sums[a][lane], valid[i] ? pos[i][a] : 3.0e38);
    }
    reduce(lane, 1);
    vec3 lo = vec3(totals[0], totals[1], totals[2]);
    barrier();
    for (int j = 0; j < COLUMNS; ++j) sums[j][lane] = -3.0e38;
    for (int i = 0; i < ROWS; ++i) {
        for (int a = 0; a < 3; ++a) sums[a][lane] = max(sums[a][lane], valid[i] ? pos[i][a] : -3.0e38);
    }
    reduce(lane, 2);
    vec3 range = vec3(totals[0], totals[1], totals[2]) - lo;
    bvec3 wide = greaterThan(range, vec3(1.0));
    vec3 offset = mix(vec3(0.0), lo, wide);
    vec3 scale = mix(vec3(1.0), 1.0 / max(range, vec3(1.0)), wide);

    // The matrix rows this lane owns.
    float m[ROWS][COLUMNS];
    uint seed = pcg_hash(uint(push.p.config.z) * 7919u + uint(block.y * 4096 + block.x));
    float amplitude = push.p.params.x;
    for (int i = 0; i < ROWS; ++i) {
        float f[10];
        bmfr_features(nrm[i], pos[i], offset, scale, f);
        uint state = pcg_hash(seed + uint(i * LANES + lane));
        for (int k = 0; k < 10; ++k) {
            float noise = k == 0 ? 0.0 : amplitude * (2.0 * rng_next(state) - 1.0);
            m[i][k] = valid[i] ? f[k] + noise : 0.0;
        }
        for (int c = 0; c < 3; ++c) m[i][10 + c] = rgb[i][c];
    }

    // Initial column norms², the scale the rank test compares with.
    for (int j = 0; j < COLUMNS; ++j) {
        float s = 0.0;
        for (int i = 0; i < ROWS; ++i) s += m[i][j] * m[i][j];
        sums[j][lane] = s;
    }
    reduce(lane, 0);
    float initial_norm2[10];
    for (int k = 0; k < 10; ++k) initial_norm2[k] = totals[k];

    // Householder QR, column by column; `pivot` is the next row of R (skipped columns take none).
    int pivot = 0;
    for (int k = 0; k < int(BMFR_FEATURES); ++k) {
        barrier();
        // Column k below the pivot (selected with constant indices: private arrays indexed by a
        // loop variable turn into scratch memory), its dot products with every column, and the
        // pivot row broadcast.
        float x[ROWS];
        for (int i = 0; i < ROWS; ++i) {
            float xk = 0.0;
            for (int c = 0; c < COLUMNS; ++c) xk = c == k ? m[i][c] : xk;
            x[i] = i * LANES + lane >= pivot ? xk : 0.0;
        }
        for (int j = 0; j < COLUMNS; ++j) {
            float s = 0.0;
            for (int i = 0; i < ROWS; ++i) s += x[i] * m[i][j];
            sums[j][lane] = s;
        }
        // Rows < LANES are lane-major in slot i = 0: the pivot row (< 10) is lane `pivot`'s.
        if (lane == pivot) {
            for (int j = 0; j < COLUMNS; ++j) pivot_values[j] = m[0][j];
        }
        reduce(lane, 0);
        float norm2 = totals[k];
        float start2 = 0.0;
        for (int c = 0; c < 10; ++c) start2 = c == k ? initial_norm2[c] : start2;
        if (norm2 <= max(BMFR_MIN_RELATIVE_NORM2 * start2, BMFR_MIN_NORM2)) {
            if (lane == 0) pivots[k] = -1;
            continue;
        }
        float xp = pivot_values[k];
        float alpha = xp > 0.0 ? -sqrt(norm2) : sqrt(norm2);
        // vᵀv / 2 with v = x − α e_pivot.
        float half_vv = norm2 - alpha * xp;
        float tau[COLUMNS];
        for (int j = 0; j < COLUMNS; ++j) tau[j] = j > k ? (totals[j] - alpha * pivot_values[j]) / half_vv : 0.0;
        for (int i = 0; i < ROWS; ++i) {
            int r = i * LANES + lane;
            float vk = r == pivot ? x[i] - alpha : x[i];
            for (int j = 0; j < COLUMNS; ++j) {
                m[i][j] -= vk * tau[j];
                if (j == k && r >= pivot) m[i][j] = r == pivot ? alpha : 0.0;
            }
        }
        if (lane == 0) pivots[k] = pivot;
        pivot += 1;
    }

    // R's rows and Qᵀ·rgb are rows 0..pivot − 1, slot 0 of lanes 0..9.
    barrier();
    if (lane < int(BMFR_FEATURES)) {
        for (int j = 0; j < COLUMNS; ++j) r_rows[lane][j] = m[0][j];
    }
    barrier();
    if (lane < 3) {
        float w[10];
        for (int k = 9; k >= 0; --k) {
            int p = pivots[k];
            float s = 0.0;
            if (p >= 0) {
                s = r_rows[p][10 + lane];
                for (int j = k + 1; j < 10; ++j) s -= r_rows[p][j] * w[j];
                s /= r_rows[p][k];
            }
            w[k] = isnan(s) || isinf(s) ? 0.0 : s;
        }
        for (int k = 0; k < 10; ++k) solved[k][lane] = w[k];
    }
    barrier();
    ivec2 base = ivec2(block.x * int(BMFR_WEIGHT_TEXELS), block.y);
    if (lane < 10) imageStore(weights, base + ivec2(lane, 0), vec4(solved[lane], 0.0));
    if (lane == 10) imageStore(weights, base + ivec2(10, 0), vec4(offset, 0.0));
    if (lane == 11) imageStore(weights, base + ivec2(11, 0), vec4(scale, 0.0));
}
