//! The acuity model behind the Visual-Polar ρ axis: Reddy's V(e), the paper's CDF (Eq. 2) and its
//! generalisation to a density exponent k, the fitted inverse (Eq. 3) and the exact one. Every
//! function has a GLSL twin in `shaders/sampling/visual_polar_math.glsl` computing op for op the
//! same f32 arithmetic (tests/vp_mapping.rs holds them to < 1e-3 px on the device).

/// Reddy's acuity knee (degrees): V(e) is flat below it.
pub const ACUITY_KNEE_DEG: f32 = 5.79;
/// The paper's maximum "eccentricity": the normalised distance that r_max maps to.
pub const E_MAX_DEG: f32 = 80.0;
/// Steps of the exact inverse: from the polynomial guess 3 suffice for k = 1; the rest cover other
/// density exponents, where some steps may fall back to bisection.
const NEWTON_STEPS: u32 = 12;
/// Reddy's acuity model V(e) in cycles per degree.
pub fn acuity(e: f32) -> f32 {
    if e <= ACUITY_KNEE_DEG {
        60.0
    } else {
        let t = 0.3 * e + 1.0;
        449.4 / (t * t)
    }
}

/// ln x (x > 0, normal) in plain f32 arithmetic, mirrored op for op by `vp_ln` in the GLSL, so
/// that both sides agree to ~1 ulp: driver `log`s differ by several ulp (lavapipe's does), and the
/// exact inverse CDF turns one ulp of ln(0.3e + 1) near e = 80 into ~3e-4 px at r_max ≈ 1900 px
/// (the CDF is flat there). x = m·2^k with m ∈ [√½, √2); ln m = 2s(1 + s²/3 + s⁴/5 + s⁶/7 + s⁸/9),
/// s = (m − 1)/(m + 1), |s| ≤ 0.172 (truncation < 1e-9).
// 0.693_147_2 is ln 2 spelled as the GLSL twin spells it (the point is op-for-op agreement).
#[allow(clippy::approx_constant)]
pub fn ln_f32(x: f32) -> f32 {
    let bits = x.to_bits();
    // frexp: x = m·2^k, m ∈ [0.5, 1).
    let mut k = ((bits >> 23) & 0xff) as i32 - 126;
    let mut m = f32::from_bits((bits & 0x007f_ffff) | 0x3f00_0000);
    if m < 0.707_106_77 {
        m *= 2.0;
        k -= 1;
    }
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let q = (((0.111_111_11 * s2 + 0.142_857_15) * s2 + 0.2) * s2 + 0.333_333_34) * s2;
    k as f32 * 0.693_147_2 + (2.0 * s + 2.0 * s * q)
}

/// Eq. 2 of the paper, literally: CDF(d) = (1/(0.3d+1) + ln(0.3d+1))·166.4π − 612.3 (d ≥ 5.79),
/// ≈ (π/30)∫₀^d V(e)·e de. Below the knee it continues as the fovea part ∝ d² (continuous).
pub fn cdf_eq2(d: f32) -> f32 {
    const A: f32 = 166.4 * std::f32::consts::PI;
    if d < ACUITY_KNEE_DEG {
        let t0 = 0.3 * ACUITY_KNEE_DEG + 1.0;
        let c0 = (1.0 / t0 + ln_f32(t0)) * A - 612.3;
        c0 * (d / ACUITY_KNEE_DEG) * (d / ACUITY_KNEE_DEG)
    } else {
        let t = 0.3 * d + 1.0;
        (1.0 / t + ln_f32(t)) * A - 612.3
    }
}

/// ∫ t^a dt = t^(a+1)/(a+1), written with `a1 = a + 1` (ln t when a1 = 0).
fn power_antiderivative(t: f32, a1: f32) -> f32 {
    if a1.abs() < 1e-6 {
        t.ln()
    } else {
        t.powf(a1) / a1
    }
}

/// Generalised Eq. 2: (π/30)∫₀^d V(e)^k·e de; exactly `cdf_eq2` for k = 1 (the paper's constants).
/// Past the knee, with t = 0.3e + 1: ∫ e·t^(−2k) de = (1/0.09)·∫ (t − 1)·t^(−2k) dt.
pub fn cdf(d: f32, k: f32) -> f32 {
    if k == 1.0 {
        return cdf_eq2(d);
    }
    const S: f32 = std::f32::consts::PI / 30.0;
    let dk = d.min(ACUITY_KNEE_DEG);
    let fovea = S * 60f32.powf(k) * 0.5 * dk * dk;
    if d <= ACUITY_KNEE_DEG {
        return fovea;
    }
    let g =
        |t: f32| power_antiderivative(t, 2.0 - 2.0 * k) - power_antiderivative(t, 1.0 - 2.0 * k);
    let t0 = 0.3 * ACUITY_KNEE_DEG + 1.0;
    fovea + S * 449.4f32.powf(k) / 0.09 * (g(0.3 * d + 1.0) - g(t0))
}

/// d cdf / d d, for Newton (the fovea part of `cdf_eq2` is scaled to continuity, so use it there).
pub fn cdf_derivative(d: f32, k: f32) -> f32 {
    if d < ACUITY_KNEE_DEG {
        return 2.0 * cdf(ACUITY_KNEE_DEG, k) * d / (ACUITY_KNEE_DEG * ACUITY_KNEE_DEG);
    }
    if k == 1.0 {
        let t = 0.3 * d + 1.0;
        return 166.4 * std::f32::consts::PI * 0.3 * (t - 1.0) / (t * t);
    }
    std::f32::consts::PI / 30.0 * acuity(d).powf(k) * d
}

/// p_f = CDF(fovea)/CDF(80): the share of the acuity mass inside the fovea (≈ 0.0963 for k = 1).
pub fn fovea_fraction(fovea_deg: f32, k: f32) -> f32 {
    cdf(fovea_deg, k) / cdf(E_MAX_DEG, k)
}

/// Eq. 3, the paper's fitted inverse of the normalised CDF (degrees; p = CDF(e)/CDF(80)).
/// Only meant for p ≥ p_f; e(1) ≈ 79.97.
pub fn inverse_cdf_poly(p: f32) -> f32 {
    (((25.09 * p + 0.1680) * p + 27.61) * p + 23.87) * p + 3.232
}

fn inverse_cdf_poly_derivative(p: f32) -> f32 {
    ((100.36 * p + 0.504) * p + 55.22) * p + 23.87
}

/// ln(1 + x) (x > −½ … ∞) in plain f32 arithmetic, op for op as `vp_log1p` in the GLSL: for
/// small |x| through s = x/(2 + x), ln(1 + x) = 2 atanh s (accurate relative to the result, which
/// `ln_f32(1 + x)` is not: 1 + x rounds away x's low bits), otherwise `ln_f32(1 + x)`.
// The coefficients are 1/9, 1/7, 1/5, 1/3 spelled as the GLSL twin spells them.
#[allow(clippy::excessive_precision)]
pub fn log1p_f32(x: f32) -> f32 {
    if x.abs() >= 0.5 {
        return ln_f32(1.0 + x);
    }
    // |s| ≤ 0.2: the series' truncation is < 1e-8 relative.
    let s = x / (2.0 + x);
    let s2 = s * s;
    let q = (((0.111_111_11 * s2 + 0.142_857_15) * s2 + 0.2) * s2 + 0.333_333_34) * s2;
    2.0 * s + 2.0 * s * q
}

/// The CDF's tail cdf(e_max, k) − cdf(e, k), the mass beyond e; `cdf_max` = cdf(e_max, k).
/// For k = 1 past the knee it is computed without the difference of two large numbers:
/// with t = 0.3e + 1 and x = 0.3(e_max − e)/t, Eq. 2 gives A·(ln(1 + x) − x/t_max). Near e_max
/// the CDF is flat (one f32 ulp of cdf(80) ≈ 1091 is 2e-5°), so the plain difference would make
/// the exact inverse's result depend on rounding at the ~1e-3 px level; the tail is accurate
/// relative to itself, which is what lets Rust and GLSL agree there.
pub fn cdf_tail(e: f32, k: f32, e_max: f32, cdf_max: f32) -> f32 {
    if k != 1.0 || e < ACUITY_KNEE_DEG {
        return cdf_max - cdf(e, k);
    }
    const A: f32 = 166.4 * std::f32::consts::PI;
    let t = 0.3 * e + 1.0;
    let t_max = 0.3 * e_max + 1.0;
    let x = 0.3 * (e_max - e) / t;
    A * (log1p_f32(x) - x / t_max)
}

/// Exact inverse of the normalised CDF, given the tail fraction q = 1 − p: e with
/// cdf_tail(e) = q · cdf_max, cdf_max = cdf(e_max, k), e_max ≤ `e_top` (the paper: e_max = e_top
/// = 80; the headset axis: its farthest corner's true eccentricity, bracketed by 180). Working on
/// the tail keeps the far end, where the CDF is flat, well conditioned (see `cdf_tail`); callers
/// form q from u directly, not as 1 − p. Safeguarded Newton from the polynomial guess: the bracket
/// [lo, hi] shrinks every step and a Newton step leaving it is replaced by bisection (far from
/// k = 1 the quartic guess can be poor and a plain step from a flat tail overshoots into the
/// fovea). The GLSL twin does the same in f32.
pub fn inverse_cdf_exact(q: f32, k: f32, cdf_max: f32, e_max: f32, e_top: f32) -> f32 {
    let target = q * cdf_max;
    let (mut lo, mut hi) = (0.0f32, if q >= 0.0 { e_top } else { 4.0 * e_top });
    let mut e = inverse_cdf_poly(1.0 - q).clamp(lo, hi);
    for _ in 0..NEWTON_STEPS {
        // Increasing in e, zero at the root.
        let f = target - cdf_tail(e, k, e_max, cdf_max);
        if f < 0.0 {
            lo = e;
        } else {
            hi = e;
        }
        let next = e - f / cdf_derivative(e, k).max(1e-6);
        e = if next >= lo && next <= hi {
            next
        } else {
            0.5 * (lo + hi)
        };
    }
    e
}

/// Inverse of Eq. 3 (p from e, periphery): Newton on the quartic from the exact CDF fraction,
/// which the quartic fits to within 0.03°, so three steps reach f32 precision.
pub fn poly_fraction_of(e: f32, cdf_max: f32) -> f32 {
    let mut p = cdf_eq2(e) / cdf_max;
    for _ in 0..3 {
        p -= (inverse_cdf_poly(p) - e) / inverse_cdf_poly_derivative(p);
    }
    p
}
