// A-SVGF's 3×3 strata of the sampling grid (Schied et al. 2018): one gradient sample each, and the
// 1/3-resolution grid the gradient is reconstructed on. Stratum (sx, sy) holds the texels
// 3·(sx, sy) + [0, 3)². Visual-Polar (visual-polar.md §5): a stratum column has as many strata as
// its tallest column needs; strata wrap on φ (keeping the angle across columns of different
// height, like grid_column_tap), end at the grid on ρ, and a stratum whose texels are all clipped
// holds nothing.
#ifndef FOVEA_DENOISE_STRATA_GLSL
#define FOVEA_DENOISE_STRATA_GLSL

#include "grid.glsl"

const int STRATUM = int(ASVGF_STRATUM);

// Index of the stratum holding `texel` in the sample buffer (row-major over the strata grid).
uint asvgf_stratum_index(ivec2 texel, int grid_width) {
    int width = (grid_width + STRATUM - 1) / STRATUM;
    return uint((texel.y / STRATUM) * width + texel.x / STRATUM);
}

// The G-buffer visibility's w: the luminance of a sample the next frame's forward projection may
// carry as its stratum's gradient source (asvgf_forward.comp), with the sign bit set; 0 for a
// sample it may not (a miss, a texel not traced, and with resampling every texel but the
// stratum's source).
uint asvgf_source_bits(float luminance) {
    return luminance < 0.0 ? 0u : (floatBitsToUint(luminance) | 0x80000000u);
}

bool asvgf_is_source(uint bits) {
    return (bits & 0x80000000u) != 0u;
}

float asvgf_source_luminance(uint bits) {
    return uintBitsToFloat(bits & 0x7fffffffu);
}

ivec2 strata_size(Grid g) {
    return (g.size + STRATUM - 1) / STRATUM;
}

// Strata in stratum column sx (Visual-Polar rows grow with ρ: the last column is the tallest).
int strata_rows(Grid g, int sx) {
    int col = min(STRATUM * sx + STRATUM - 1, g.size.x - 1);
    return (grid_rows(g, col) + STRATUM - 1) / STRATUM;
}

bool stratum_holds_samples(Grid g, ivec2 s) {
    return s.x >= 0 && s.y >= 0 && s.x < strata_size(g).x && s.y < strata_rows(g, s.x);
}

// A texel of stratum s holding a sample, near its centre: where the edge-stopping functions read
// the stratum's surface.
ivec2 stratum_centre_texel(Grid g, ivec2 s) {
    int col = min(STRATUM * s.x + 1, g.size.x - 1);
    return ivec2(col, clamp(STRATUM * s.y + 1, 0, grid_rows(g, col) - 1));
}

// The stratum `o` strata away from s (o.y in strata of s's column); false when it leaves the
// strata grid (on x always; on y only where the rows of the stratum column's tallest grid column
// do not wrap, grid_column_wraps). Across stratum columns the angle is kept as the share of the
// column's rows: exact for full circles; on the screen-clipped layout's clipped arcs an
// approximation of the neighbour (the gradient's edge-stopping weights the tap).
bool strata_tap(Grid g, ivec2 s, ivec2 o, out ivec2 tap) {
    tap = s + o;
    if (tap.x < 0 || tap.x >= strata_size(g).x) return false;
    int n1 = strata_rows(g, tap.x);
    // Keep the angle across stratum columns of different height.
    int n0 = o.x == 0 ? n1 : strata_rows(g, s.x);
    tap.y = int(floor((float(s.y) + 0.5 + float(o.y)) * float(n1) / float(n0)));
    if (!grid_column_wraps(g, min(STRATUM * tap.x + STRATUM - 1, g.size.x - 1))) return tap.y >= 0 && tap.y < n1;
    tap.y = grid_wrap(tap.y, n1);
    return true;
}

#endif
