// Visual-Polar mapping (Koskela et al., EGSR 2019): GLSL twin of
// renderer/src/sampling/visual_polar.rs. Every function mirrors the Rust one of the same name
// (same constants, same f32 order of operations) so a device test can compare them point by
// point; change both together. Design: shared/design/visual-polar.md.
//
// Grid: x = ρ (u = x / width), y = φ ∈ [0, 2π) from +x toward +y (pixels, y down). Fovea u < u_f:
// r linear in u. Periphery: u maps linearly onto p ∈ [p_f, 1], e(p) by the inverse CDF,
// r = e / e_norm · r_max. Triangular clip: fovea column c keeps n(c) = clamp(floor(H·u_c/u_f + ½),
// 1, H) rows (u_c = (c + ½)/W), the first n(c); row y of column c sits at φ = 2π·y/n(c).
//
// Headset axis (flag 4, Rust visual_polar_headset.rs): the "radius" is the true eccentricity in
// degrees (r_max = e_norm = 1, r_f = fovea°, derived here), the CDF runs over [0, e_max] with the
// exact inverse; screen offsets convert through the eye's FOV tangents (vp_headset_*).
//
// Log-polar radial law (flag 8, Rust log_polar.rs): r(u) and u(r) are Meng's kernel log-polar
// law (log_polar.glsl) with α, L in shape1.zw; no clip (u_f = 0), or composite foveation's gaze
// disc as a linear fovea (u_f, r_f) and the law from its inner column (shape0.y). The paper-axis kernels
// (VP_NORMALIZED_AXIS_ONLY) compile it out, like the headset axis.
//
// Self-contained on purpose (no layouts.glsl): the parameters come as the four vectors of the
// `SamplingParams` slots, packed by `VisualPolar::sampling_params()`, and `vp_unpack` names them.
#ifndef FOVEA_SAMPLING_VISUAL_POLAR_MATH_GLSL
#define FOVEA_SAMPLING_VISUAL_POLAR_MATH_GLSL

const float VP_ACUITY_KNEE_DEG = 5.79;
const float VP_E_MAX_DEG = 80.0;
const float VP_PI = 3.14159265358979;
const float VP_TAU = 6.28318530717959;
const int VP_NEWTON_STEPS = 12;
const float VP_E_TOP_HEADSET_DEG = 180.0;
const float VP_DEG_PER_RAD = 57.29578;
const float VP_RAD_PER_DEG = 0.017453292;
const float VP_FAR_PIXELS_PER_SCREEN = 4.0;

// Kernels specialised for the paper's normalised axis define VP_NORMALIZED_AXIS_ONLY: lavapipe
// executes both sides of every branch, so the headset axis's arithmetic (atan, sin, cos, sqrt)
// would otherwise cost every default frame. Everywhere else P.headset decides at run time.
#if defined(VP_NORMALIZED_AXIS_ONLY)
const bool VP_MAY_USE_HEADSET_AXIS = false;
const bool VP_MAY_USE_LOG_POLAR = false;
#else
const bool VP_MAY_USE_HEADSET_AXIS = true;
const bool VP_MAY_USE_LOG_POLAR = true;
#endif
// Kernels for the paper's quartic inverse CDF define VP_POLYNOMIAL_CDF_ONLY: the exact inverse's
// Newton steps would otherwise run under a mask for every peripheral sample of the default frame.
#if defined(VP_POLYNOMIAL_CDF_ONLY)
const bool VP_MAY_USE_EXACT_CDF = false;
#else
const bool VP_MAY_USE_EXACT_CDF = true;
#endif

struct VpParams {
    uvec2 grid;      // VP grid size in texels
    vec2 screen;     // screen size in pixels
    vec2 gaze;       // gaze in screen pixels
    float r_max;     // pixels that e_norm maps to (headset: 1, the axis is degrees)
    float k;         // density exponent
    float u_f;       // fovea width in u (2 · clip fraction)
    float p_f;       // CDF fraction at the fovea edge
    float r_f;       // fovea radius in pixels (headset: fovea°)
    float e_norm;    // e(1): e_poly(1) for the polynomial, 80 for the exact inverse (headset: 1)
    float e_max;     // where the CDF is normalised: 80 (headset: the farthest corner's true eccentricity)
    float cdf_max;   // cdf(e_max, k)
    bool exact;      // exact inverse CDF instead of the paper's quartic
    bool clipped;    // rows on the on-screen arcs: map with visual_polar_clipped.glsl (vp_layout_*)
    bool screen_axis; // screen-aware ρ axis: the periphery through the table's knots (visual_polar_clipped.glsl)
    bool headset;    // true-eccentricity axis through the FOV tangents
    vec2 gaze_tan;   // headset: the gaze in tangent space
    vec2 tan_scale;  // headset: tangent units per pixel
    float far;       // headset: where samples beyond their ray's horizon are parked (pixels)
    bool log_polar;  // the radial law is Meng's kernel log-polar (log_polar.glsl)
    float lp_alpha;  // log-polar: kernel exponent α
    float lp_l;      // log-polar: L = ln of the extent (pixels)
    float lp_inner;  // log-polar: the law's column where the first log-polar column starts (composite: the gaze disc's edge; shape0.y)
    uint arcs_base;  // screen-clipped layout: first column of this frame's arcs in the table (0; the previous frame's follow this frame's)
};

// Reddy's acuity V(e), cycles per degree.
float vp_acuity(float e) {
    if (e <= VP_ACUITY_KNEE_DEG) return 60.0;
    float t = 0.3 * e + 1.0;
    return 449.4 / (t * t);
}

// ln x (x > 0, normal) in plain arithmetic, op for op as Rust's ln_f32: the driver's log may be
// several ulp off, which the exact inverse CDF near e = 80 amplifies to ~1e-3 px.
float vp_ln(float x) {
    int k;
    float m = frexp(x, k); // x = m·2^k, m ∈ [0.5, 1)
    if (m < 0.70710677) {
        m *= 2.0;
        k -= 1;
    }
    float s = (m - 1.0) / (m + 1.0);
    float s2 = s * s;
    float q = (((0.11111111 * s2 + 0.14285715) * s2 + 0.2) * s2 + 0.33333334) * s2;
    float l = float(k) * 0.6931472 + (2.0 * s + 2.0 * s * q);
    return l;
}

#include "log_polar.glsl"

// Eq. 2 literally (d >= 5.79); below the knee the fovea part ∝ d², continuous.
float vp_cdf_eq2(float d) {
    const float A = 166.4 * VP_PI;
    if (d < VP_ACUITY_KNEE_DEG) {
        float t0 = 0.3 * VP_ACUITY_KNEE_DEG + 1.0;
        float c0 = (1.0 / t0 + vp_ln(t0)) * A - 612.3;
        float c = c0 * (d / VP_ACUITY_KNEE_DEG) * (d / VP_ACUITY_KNEE_DEG);
        return c;
    }
    float t = 0.3 * d + 1.0;
    float c = (1.0 / t + vp_ln(t)) * A - 612.3;
    return c;
}

// ∫ t^a dt with a1 = a + 1 (ln t when a1 = 0).
float vp_power_antiderivative(float t, float a1) {
    return abs(a1) < 1e-6 ? log(t) : pow(t, a1) / a1;
}

float vp_g(float t, float k) {
    return vp_power_antiderivative(t, 2.0 - 2.0 * k) - vp_power_antiderivative(t, 1.0 - 2.0 * k);
}

// Generalised Eq. 2: (π/30)∫₀^d V(e)^k·e de; exactly vp_cdf_eq2 for k = 1.
float vp_cdf(float d, float k) {
    if (k == 1.0) return vp_cdf_eq2(d);
    const float S = VP_PI / 30.0;
    float dk = min(d, VP_ACUITY_KNEE_DEG);
    float fovea = S * pow(60.0, k) * 0.5 * dk * dk;
    if (d <= VP_ACUITY_KNEE_DEG) return fovea;
    float t0 = 0.3 * VP_ACUITY_KNEE_DEG + 1.0;
    return fovea + S * pow(449.4, k) / 0.09 * (vp_g(0.3 * d + 1.0, k) - vp_g(t0, k));
}

float vp_cdf_derivative(float d, float k) {
    if (d < VP_ACUITY_KNEE_DEG)
        return 2.0 * vp_cdf(VP_ACUITY_KNEE_DEG, k) * d / (VP_ACUITY_KNEE_DEG * VP_ACUITY_KNEE_DEG);
    if (k == 1.0) {
        float t = 0.3 * d + 1.0;
        return 166.4 * VP_PI * 0.3 * (t - 1.0) / (t * t);
    }
    return VP_PI / 30.0 * pow(vp_acuity(d), k) * d;
}

// Slots as packed by VisualPolar::sampling_params(): grid = (grid w, grid h, screen w, screen h),
// shape1.y = flags (1 exact inverse CDF, 2 screen-clipped layout, 4 headset axis, 16 screen-aware ρ axis, 8 log-polar
// law: shape1.zw = (α, L)), and
// - paper axis: gaze = (x, y, r_max, k), shape0 = (u_f, p_f, r_f, e_norm),
//   shape1 = (cdf_max, flags, fovea° (unused here), 0);
// - headset axis: gaze = (x, y, G.x, k), shape0 = (u_f, p_f, fovea°, G.y),
//   shape1 = (e_max, flags, scale.x, scale.y); r_max = e_norm = 1 and cdf_max = cdf(e_max, k)
//   are derived (as VisualPolar::new computes them).
VpParams vp_unpack(uvec4 grid, vec4 gaze, vec4 shape0, vec4 shape1) {
    VpParams p;
    uint flags = uint(shape1.y);
    p.grid = grid.xy;
    p.screen = vec2(grid.zw);
    p.gaze = gaze.xy;
    p.k = gaze.w;
    p.u_f = shape0.x;
    p.p_f = shape0.y;
    p.r_f = shape0.z;
    p.exact = VP_MAY_USE_EXACT_CDF && (flags & 1u) != 0u;
    p.clipped = (flags & 2u) != 0u;
    p.screen_axis = (flags & 16u) != 0u;
    p.headset = VP_MAY_USE_HEADSET_AXIS && (flags & 4u) != 0u;
    p.r_max = p.headset ? 1.0 : gaze.z;
    p.e_norm = p.headset ? 1.0 : shape0.w;
    p.e_max = p.headset ? shape1.x : VP_E_MAX_DEG;
    p.cdf_max = p.headset ? vp_cdf(shape1.x, p.k) : shape1.x;
    p.gaze_tan = vec2(gaze.z, shape0.w);
    p.tan_scale = shape1.zw;
    p.far = VP_FAR_PIXELS_PER_SCREEN * (p.screen.x + p.screen.y);
    p.log_polar = VP_MAY_USE_LOG_POLAR && (flags & 8u) != 0u;
    p.lp_alpha = shape1.z;
    p.lp_l = shape1.w;
    p.lp_inner = shape0.y;
    p.arcs_base = 0u;
    return p;
}

// Eq. 3, the paper's quartic (p = CDF(e)/CDF(80), meant for p >= p_f).
float vp_inverse_cdf_poly(float p) {
    return (((25.09 * p + 0.1680) * p + 27.61) * p + 23.87) * p + 3.232;
}

float vp_inverse_cdf_poly_derivative(float p) {
    return ((100.36 * p + 0.504) * p + 55.22) * p + 23.87;
}

// ln(1 + x), op for op as Rust's log1p_f32: 2·atanh(x/(2 + x)) for small |x| (accurate relative
// to the result), vp_ln(1 + x) otherwise.
float vp_log1p(float x) {
    if (abs(x) >= 0.5) return vp_ln(1.0 + x);
    float s = x / (2.0 + x);
    float s2 = s * s;
    float q = (((0.11111111 * s2 + 0.14285715) * s2 + 0.2) * s2 + 0.33333334) * s2;
    return 2.0 * s + 2.0 * s * q;
}

// cdf(e_max, k) − cdf(e, k) (Rust cdf_tail): for k = 1 past the knee A·(ln(1 + x) − x/t_max),
// x = 0.3(e_max − e)/t, accurate relative to itself where the CDF is flat (near e_max).
float vp_cdf_tail(float e, float k, float e_max, float cdf_max) {
    if (k != 1.0 || e < VP_ACUITY_KNEE_DEG) return cdf_max - vp_cdf(e, k);
    const float A = 166.4 * VP_PI;
    float t = 0.3 * e + 1.0;
    float t_max = 0.3 * e_max + 1.0;
    float x = 0.3 * (e_max - e) / t;
    return A * (vp_log1p(x) - x / t_max);
}

// Exact inverse from the tail fraction q = 1 − p: safeguarded Newton from the quartic's guess
// (bisection when a step leaves the bracket), as in Rust's inverse_cdf_exact.
// e_top: the bracket's top, 80 (paper) or 180 (headset axis, normalised at e_max ≤ 180).
float vp_inverse_cdf_exact(float q, float k, float cdf_max, float e_max, float e_top) {
    float target = q * cdf_max;
    float lo = 0.0;
    float hi = q >= 0.0 ? e_top : 4.0 * e_top;
    float e = clamp(vp_inverse_cdf_poly(1.0 - q), lo, hi);
    for (int i = 0; i < VP_NEWTON_STEPS; ++i) {
        float f = target - vp_cdf_tail(e, k, e_max, cdf_max);
        if (f < 0.0) lo = e; else hi = e;
        float next = e - f / max(vp_cdf_derivative(e, k), 1e-6);
        e = (next >= lo && next <= hi) ? next : 0.5 * (lo + hi);
    }
    return e;
}

// Inverse of Eq. 3 (p from e): Newton on the quartic from the exact CDF fraction.
float vp_poly_fraction_of(float e, float cdf_max) {
    float p = vp_cdf_eq2(e) / cdf_max;
    for (int i = 0; i < 3; ++i)
        p -= (vp_inverse_cdf_poly(p) - e) / vp_inverse_cdf_poly_derivative(p);
    return p;
}

uint vp_rows_in_column(VpParams P, uint col) {
    uint h = P.grid.y;
    float u_c = (float(col) + 0.5) / float(P.grid.x);
    if (u_c >= P.u_f) return h;
    return clamp(uint(floor(float(h) * u_c / P.u_f + 0.5)), 1u, h);
}

bool vp_is_valid_texel(VpParams P, ivec2 t) {
    return t.x >= 0 && t.y >= 0 && uint(t.x) < P.grid.x && uint(t.y) < vp_rows_in_column(P, uint(t.x));
}

float vp_r_of_u(VpParams P, float u) {
    if (P.log_polar) {
        if (u < P.u_f) return u / P.u_f * P.r_f;
        return lp_r_of_u(P.lp_inner + (u - P.u_f) / (1.0 - P.u_f) * (1.0 - P.lp_inner), P.lp_l, P.lp_alpha);
    }
    if (u < P.u_f) return u / P.u_f * P.r_f;
    float e_top = P.headset ? VP_E_TOP_HEADSET_DEG : VP_E_MAX_DEG;
    float e = P.exact
        ? vp_inverse_cdf_exact((1.0 - u) / (1.0 - P.u_f) * (1.0 - P.p_f), P.k, P.cdf_max, P.e_max, e_top)
        : vp_inverse_cdf_poly(P.p_f + (u - P.u_f) / (1.0 - P.u_f) * (1.0 - P.p_f));
    return e / P.e_norm * P.r_max;
}

// atan on [0, 1] in plain arithmetic, op for op as Rust's atan_unit (visual_polar_headset.rs):
// the driver's atan may be ~1e-5 relative off.
float vp_atan_unit(float z) {
    float base = 0.0;
    float w = z;
    if (z > 0.41421357) {
        base = 0.7853982;
        w = (z - 1.0) / (z + 1.0);
    }
    float v = w / (1.0 + sqrt(1.0 + w * w));
    float v2 = v * v;
    float q = (((((-0.07692308 * v2 + 0.09090909) * v2 - 0.11111111) * v2 + 0.14285715) * v2 - 0.2) * v2
        + 0.33333334) * v2;
    return base + 2.0 * (v - v * q);
}

// atan2(y, x) for y >= 0, in [0, π] (Rust angle_of).
float vp_angle_of(float y, float x) {
    float ax = abs(x);
    float a = y <= ax ? vp_atan_unit(ax > 0.0 ? y / ax : 0.0) : 1.5707964 - vp_atan_unit(ax / y);
    return x < 0.0 ? 3.1415927 - a : a;
}

// Headset axis (Rust HeadsetAxis::eccentricity): true eccentricity (degrees) of offset d (pixels)
// from the gaze, atan2(|Ĝ × T̂|, Ĝ·T̂).
float vp_headset_eccentricity(VpParams P, vec2 d) {
    vec2 g = P.gaze_tan;
    vec2 t = d * P.tan_scale;
    float cx = -t.y;
    float cy = t.x;
    float cz = g.x * t.y - g.y * t.x;
    float cross_len = sqrt(cx * cx + cy * cy + cz * cz);
    float dot_gt = g.x * g.x + g.y * g.y + 1.0 + (g.x * t.x + g.y * t.y);
    return vp_angle_of(cross_len, dot_gt) * VP_DEG_PER_RAD;
}

// Headset axis (Rust HeadsetAxis::distance): pixels from the gaze along unit pixel direction dir
// to true eccentricity e (degrees): t = a·sin e / (h·cos e − b·sin e), parked at P.far beyond
// the ray's horizon.
float vp_headset_distance(VpParams P, float e, vec2 dir) {
    vec2 g = P.gaze_tan;
    vec2 dd = dir * P.tan_scale;
    float a = g.x * g.x + g.y * g.y + 1.0;
    float b = g.x * dd.x + g.y * dd.y;
    float hz = g.x * dd.y - g.y * dd.x;
    float h = sqrt(dd.x * dd.x + dd.y * dd.y + hz * hz);
    float rad = e * VP_RAD_PER_DEG;
    float s = sin(rad);
    float c = cos(rad);
    float den = h * c - b * s;
    return den > 0.0 ? min(a * s / den, P.far) : P.far;
}

// The axis value of offset d from the gaze (r = |d|): r, or the true eccentricity (headset).
float vp_axis_of_offset(VpParams P, vec2 d, float r) {
    return P.headset ? vp_headset_eccentricity(P, d) : r;
}

// Normalised ρ and pixel angle φ → screen offset from the gaze (pixels).
vec2 vp_offset_of(VpParams P, float u, float phi) {
    vec2 dir = vec2(cos(phi), sin(phi));
    float a = vp_r_of_u(P, u);
    return (P.headset ? vp_headset_distance(P, a, dir) : a) * dir;
}

float vp_u_of_r(VpParams P, float r) {
    if (P.log_polar) {
        if (P.u_f > 0.0 && r < P.r_f) return r / P.r_f * P.u_f;
        return P.u_f + (lp_u_of_r(r, P.lp_l, P.lp_alpha) - P.lp_inner) / (1.0 - P.lp_inner) * (1.0 - P.u_f);
    }
    if (r < P.r_f) return r / P.r_f * P.u_f;
    float e = r / P.r_max * P.e_norm;
    if (P.exact) return 1.0 - vp_cdf_tail(e, P.k, P.e_max, P.cdf_max) / P.cdf_max / (1.0 - P.p_f) * (1.0 - P.u_f);
    float p = vp_poly_fraction_of(e, P.cdf_max);
    return P.u_f + (p - P.p_f) / (1.0 - P.p_f) * (1.0 - P.u_f);
}

uint vp_column_of(VpParams P, float x) {
    return min(uint(floor(max(x, 0.0))), P.grid.x - 1u);
}

// Screen position (pixels) → continuous grid coordinates; y in [0, rows of the column).
// The paper's layout (Rust `paper_screen_to_vp`); vp_layout_screen_to_vp follows P.clipped.
vec2 vp_screen_to_vp(VpParams P, vec2 s) {
    vec2 d = s - P.gaze;
    float r = length(d);
    // GLSL atan(y, x) is undefined at the origin; the gaze itself maps to φ = 0 like Rust's atan2.
    float phi = r > 0.0 ? atan(d.y, d.x) : 0.0;
    if (phi < 0.0) phi += VP_TAU;
    float x = vp_u_of_r(P, vp_axis_of_offset(P, d, r)) * float(P.grid.x);
    float n = float(vp_rows_in_column(P, vp_column_of(P, x)));
    float y = phi / VP_TAU * n;
    return vec2(x, y >= n ? 0.0 : y);
}

// Continuous grid coordinates → screen position (pixels); φ wraps.
// The paper's layout (Rust `paper_vp_to_screen`); vp_layout_vp_to_screen follows P.clipped.
vec2 vp_vp_to_screen(VpParams P, vec2 g) {
    float n = float(vp_rows_in_column(P, vp_column_of(P, g.x)));
    float phi = g.y / n * VP_TAU;
    return P.gaze + vp_offset_of(P, g.x / float(P.grid.x), phi);
}

#endif
