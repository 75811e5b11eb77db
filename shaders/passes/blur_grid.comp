#version 460
// The foveated blur (visual-polar.md §7) applied in the Visual-Polar grid before the remap
// (`--blur-space grid`: no full-screen blur pass), one axis per dispatch: along φ inside
// a column (wrapped) and along ρ across columns at the same angle. Radial and tangential steps are
// orthogonal on the screen, so the two axes together are the screen blur's isotropic Gaussian of
// σ(r) pixels, measured in each axis' own texels. The grid holds 0.39–0.44 of the screen's
// texels and no full-screen blur pass is left: the remap writes the finished picture.
// A traced sample has alpha 1, one never traced (culled off the screen) 0: the sum is normalised
// by the alpha it gathered, so culled texels beyond the border do not darken it.
// The paper's layout only (the Rust side keeps the screen blur otherwise): a row is the same
// angle in every full column. `paper`: the normalised ρ axis and the quartic inverse CDF;
// `clipped`: the general kernel (exact CDF, log-polar and composite radial laws). One kernel per
// axis (`phi_*`, `rho_*`): lavapipe would run the other axis' taps under a mask.
//! variant phi_paper: BLUR_ALONG_PHI VP_NORMALIZED_AXIS_ONLY VP_POLYNOMIAL_CDF_ONLY
//! variant phi_clipped: BLUR_ALONG_PHI
//! variant rho_paper: VP_NORMALIZED_AXIS_ONLY VP_POLYNOMIAL_CDF_ONLY
//! variant rho_clipped:
#include "../common/layouts.glsl"
#include "../sampling/visual_polar_math.glsl"
#include "../common/gaussian.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { GridBlurPush p; } push;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D src;
layout(set = 0, binding = 1, rgba32f) uniform writeonly image2D dst;

// Taps per side: every texel out to 2.5σ while σ ≤ 3.2 texels (the grid holds raw samples, so no
// texel is skipped where it can be helped), evenly spaced beyond.
const int GRID_BLUR_MAX_TAPS = 8;

// Pixels from the gaze at column coordinate x (column centres at +½).
float radius_at(VpParams P, float x) {
    return vp_r_of_u(P, x / float(P.grid.x));
}

// Column `col` (`rows` rows) at level-0 row coordinate y0 ∈ [0, rows) (row centres at +½):
// linear along φ, wrapped.
vec4 at_angle(uint col, uint rows, float y0) {
    float y = y0 - 0.5;
    float f = floor(y);
    int m = int(rows);
    int a = int(f);
    a += a < 0 ? m : (a >= m ? -m : 0);
    int b = a + 1 == m ? 0 : a + 1;
    return mix(imageLoad(src, ivec2(col, a)), imageLoad(src, ivec2(col, b)), y - f);
}

// One tap `offset` texels from `t` along the pass's axis (`rows`: t's column's row count).
vec4 tap(VpParams P, ivec2 t, uint rows, int offset) {
#if defined(BLUR_ALONG_PHI)
    int m = int(rows);
    int y = t.y + offset;
    y += y < 0 ? m : (y >= m ? -m : 0);
    return imageLoad(src, ivec2(t.x, y));
#else
    uint col = uint(clamp(t.x + offset, 0, int(P.grid.x) - 1));
    uint n = vp_rows_in_column(P, col);
    // Full columns share the rows' angles; a fovea column (fewer rows) is read at the same angle.
    if (n == rows) return imageLoad(src, ivec2(col, t.y));
    return at_angle(col, n, (float(t.y) + 0.5) * float(n) / float(rows));
#endif
}

void main() {
    VpParams P = vp_unpack(push.p.space.grid, push.p.space.gaze, push.p.space.shape0, push.p.space.shape1);
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (uint(t.x) >= P.grid.x || uint(t.y) >= P.grid.y) return;
    uint rows = vp_rows_in_column(P, uint(t.x));
    vec4 centre = imageLoad(src, t);
    float x = float(t.x) + 0.5;
    float r = radius_at(P, x);
    vec4 shape = push.p.shape;
    float sigma_px = shape.w * max(r - shape.z, 0.0);
    // Pixels between neighbouring texels along this axis: an arc step, or the columns' spacing.
#if defined(BLUR_ALONG_PHI)
    float texel_px = r * VP_TAU / float(rows);
#else
    float texel_px = 0.5 * (radius_at(P, x + 1.0) - radius_at(P, x - 1.0));
#endif
    float sigma = sigma_px / max(texel_px, 1e-6);
    float spacing = max(1.0, ceil(2.5 * sigma / float(GRID_BLUR_MAX_TAPS)));
    float reach = min(ceil(2.5 * sigma / spacing), float(GRID_BLUR_MAX_TAPS));
    // Along φ never past half the circle (a tap would meet its mirror image).
#if defined(BLUR_ALONG_PHI)
    reach = min(reach, floor((float(rows) - 1.0) / (2.0 * spacing)));
#endif
    int taps = int(reach);
    // Rows past a fovea column's count are never read; nothing to blur within the fovea.
    if (uint(t.y) >= rows || taps < 1) {
        imageStore(dst, t, centre);
        return;
    }
    int step = int(spacing);
    GaussianTaps gauss = gaussian_taps(sigma / spacing);
    vec4 sum = centre;
    float weight = centre.a;
    for (int i = 1; i <= taps; ++i) {
        float w = gaussian_next(gauss);
        vec4 a = tap(P, t, rows, i * step);
        vec4 b = tap(P, t, rows, -i * step);
        sum += w * (a + b);
        weight += w * (a.a + b.a);
    }
    imageStore(dst, t, weight > 0.0 ? sum / weight : centre);
}
