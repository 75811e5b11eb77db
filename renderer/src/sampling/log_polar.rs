//! Log-polar sampling (Meng et al. 2018, "Kernel Foveated Rendering"; comparators.md §D) as a
//! radial law of the polar space (`VisualPolar` with `RadialLaw::LogPolar`): the grid, the φ wrap,
//! the φ-mips, the remap and the denoisers' addressing are Visual-Polar's; only r(u) differs.
//! `shaders/sampling/log_polar.glsl` mirrors every function here op for op (a device test compares
//! them); change both together.
//!
//! Normalised column u = x / w, gaze at the origin, L = ln of the extent (pixels):
//!   forward  u = K(ln r / L),  K(t) = t^α  (r ≤ 1 px ↦ u = 0: the law starts at one pixel)
//!   inverse  r = exp(L · K⁻¹(u))
//! Buffer w×h = screen / σ, rows span φ ∈ [0, 2π) as in every Visual-Polar column (no clip).
//! Areal density (samples per pixel) ρ(r) = w·h·α·(ln r / L)^(α−1) / (2π·L·r²): α > 1 moves
//! samples from the (otherwise heavily over-sampled) gaze toward the periphery.

use super::acuity::ln_f32;
use crate::error::{Error, Result};
use glam::{UVec2, Vec2};

/// Where L comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LogPolarExtent {
    /// Meng's: the farthest screen corner from the gaze (covers the screen exactly).
    FarthestCorner,
    /// Andersson & Hansson's: the screen diagonal (the buffer's resolution does not move with
    /// the gaze; some columns lie beyond the farthest corner).
    Diagonal,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LogPolarParams {
    /// Screen-to-buffer reduction per axis (Meng's 1.8).
    pub sigma: f32,
    /// Kernel exponent α of K(t) = t^α (Meng's 4; 1 is plain log-polar).
    pub alpha: f32,
    pub extent: LogPolarExtent,
}

impl Default for LogPolarParams {
    fn default() -> Self {
        LogPolarParams {
            sigma: 1.8,
            alpha: 4.0,
            extent: LogPolarExtent::FarthestCorner,
        }
    }
}

/// σ range: below 0.25 a buffer 16× the screen's pixels, above 16 a meaningless sliver.
pub const SIGMA_RANGE: (f32, f32) = (0.25, 16.0);
/// α range: Meng and Andersson & Hansson use 1–4.
pub const ALPHA_RANGE: (f32, f32) = (1.0, 8.0);

impl LogPolarParams {
    pub fn validate(&self) -> Result<()> {
        let bad = |name: &str, v: f32, (lo, hi): (f32, f32)| {
            Error::Invalid(format!(
                "log-polar: {name} must be in [{lo}, {hi}], got {v}"
            ))
        };
        if !(self.sigma >= SIGMA_RANGE.0 && self.sigma <= SIGMA_RANGE.1) {
            return Err(bad("sigma", self.sigma, SIGMA_RANGE));
        }
        if !(self.alpha >= ALPHA_RANGE.0 && self.alpha <= ALPHA_RANGE.1) {
            return Err(bad("alpha", self.alpha, ALPHA_RANGE));
        }
        Ok(())
    }

    /// The extent's radius in pixels for this gaze: e^L.
    pub fn extent_px(&self, screen: UVec2, gaze: Vec2) -> f32 {
        match self.extent {
            LogPolarExtent::FarthestCorner => gaze.max(screen.as_vec2() - gaze).abs().length(),
            LogPolarExtent::Diagonal => screen.as_vec2().length(),
        }
    }
}

/// The law for one gaze: L and α, as the GPU gets them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LogPolarLaw {
    pub l: f32,
    pub alpha: f32,
    /// The law's column where the polar space's first log-polar column starts (0 for Meng;
    /// composite foveation's gaze disc edge, `composite.rs`).
    pub inner: f32,
}

impl LogPolarLaw {
    /// `extent_px` > 1 (an extent of one pixel has no periphery).
    pub fn new(extent_px: f32, alpha: f32) -> Result<Self> {
        if !(extent_px.is_finite() && extent_px > 1.0) {
            return Err(Error::Invalid(format!(
                "log-polar: the extent must exceed one pixel, got {extent_px} px"
            )));
        }
        Ok(LogPolarLaw {
            l: ln_f32(extent_px),
            alpha,
            inner: 0.0,
        })
    }

    /// Pixels from the gaze of normalised column u. GLSL `lp_r_of_u`.
    pub fn r_of_u(&self, u: f32) -> f32 {
        exp_f32(self.l * pow_unit(u.max(0.0), 1.0 / self.alpha))
    }

    /// Normalised column of a distance r (pixels) from the gaze. GLSL `lp_u_of_r`.
    pub fn u_of_r(&self, r: f32) -> f32 {
        if r <= 1.0 {
            return 0.0;
        }
        pow_unit(ln_f32(r) / self.l, self.alpha)
    }

    /// Samples per screen pixel at distance r of a w×h buffer (the paper's definition, |det J|
    /// of the forward map): for tests and plots.
    pub fn density(&self, r: f64, grid: UVec2) -> f64 {
        if r <= 1.0 {
            return 0.0;
        }
        let (l, a) = (self.l as f64, self.alpha as f64);
        let t = r.ln() / l;
        grid.x as f64 * grid.y as f64 * a * t.powf(a - 1.0) / (std::f64::consts::TAU * l * r * r)
    }
}

/// t^a for t ≥ 0 (t = 0 ↦ 0) by exp(a·ln t), op for op as GLSL `lp_pow_unit`.
pub fn pow_unit(t: f32, a: f32) -> f32 {
    if t <= 0.0 {
        return 0.0;
    }
    exp_f32(a * ln_f32(t))
}

/// e^x in plain f32 arithmetic, op for op as GLSL `lp_exp` (the driver's exp may be several ulp
/// off): x = k·ln2 + f (Cody–Waite, two-part ln 2), |f| ≤ ½ln2, e^f by its degree-7 Taylor
/// polynomial (truncation < 2e-9 relative), scaled by 2^k. Valid for |x| < 87.
// 0.693_145_75 / 1.428_606_8e-6 are ln 2 split so k·hi is exact; spelled as the GLSL twin.
#[allow(clippy::approx_constant)]
pub fn exp_f32(x: f32) -> f32 {
    let k = (x * 1.442_695 + 0.5).floor();
    let f = (x - k * 0.693_145_75) - k * 1.428_606_8e-6;
    let p = ((((((1.984_127e-4 * f + 1.388_888_9e-3) * f + 8.333_333e-3) * f + 4.166_666_8e-2)
        * f
        + 0.166_666_67)
        * f
        + 0.5)
        * f
        + 1.0)
        * f
        + 1.0;
    p * f32::from_bits(((k as i32 + 127) as u32) << 23)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exp_matches_f64_and_inverts_ln() {
        for i in 0..4000 {
            let x = -20.0 + i as f32 * 0.01;
            let want = (x as f64).exp();
            assert!(((exp_f32(x) as f64 - want) / want).abs() < 4e-7, "exp({x})");
        }
        for r in [1.5f32, 2.0, 10.0, 240.0, 1926.0] {
            assert!((exp_f32(ln_f32(r)) - r).abs() < 4e-6 * r, "r {r}");
        }
    }

    #[test]
    fn law_round_trips_and_ends_at_the_extent() {
        let law = LogPolarLaw::new(240.8, 4.0).unwrap();
        assert!((law.r_of_u(1.0) - 240.8).abs() < 1e-3);
        assert!((law.r_of_u(0.0) - 1.0).abs() < 1e-6);
        for i in 1..1000 {
            let u = i as f32 / 1000.0;
            let back = law.u_of_r(law.r_of_u(u));
            assert!((back - u).abs() < 2e-5 * u.max(0.05), "u {u} -> {back}");
        }
        for r in [1.01f32, 2.0, 5.0, 50.0, 200.0] {
            assert!((law.r_of_u(law.u_of_r(r)) - r).abs() < 1e-4 * r, "r {r}");
        }
    }

    use crate::sampling::{RadialLaw, SamplingSpace, VisualPolar, VisualPolarParams, VpLayout};

    fn space(screen: UVec2, gaze: Vec2, lp: LogPolarParams) -> VisualPolar {
        VisualPolar::new(
            screen,
            gaze,
            VisualPolarParams {
                radial: RadialLaw::LogPolar(lp),
                ..Default::default()
            },
        )
        .unwrap()
    }

    #[test]
    fn the_buffer_is_screen_over_sigma_and_every_texel_is_a_sample() {
        let s = space(
            UVec2::new(320, 360),
            Vec2::new(160.0, 180.0),
            LogPolarParams::default(),
        );
        assert_eq!(
            s.grid_size(),
            UVec2::new(178, 200),
            "320/1.8, 360/1.8 rounded"
        );
        assert_eq!(SamplingSpace::sample_count(&s), 178 * 200, "no clip");
        assert_eq!(
            (s.name(), s.trace_variant(), s.shader_variant()),
            ("log-polar", "log_polar", "visual_polar")
        );
        // L: the farthest corner (Meng) or the diagonal (Andersson & Hansson), whatever the gaze.
        let corner = space(
            UVec2::new(320, 360),
            Vec2::new(40.0, 300.0),
            LogPolarParams::default(),
        );
        assert!((corner.log_polar().unwrap().l - (280.0f32.hypot(300.0)).ln()).abs() < 1e-5);
        let diag = space(
            UVec2::new(320, 360),
            Vec2::new(40.0, 300.0),
            LogPolarParams {
                extent: LogPolarExtent::Diagonal,
                ..Default::default()
            },
        );
        assert!((diag.log_polar().unwrap().l - 320f32.hypot(360.0).ln()).abs() < 1e-5);
        // Meng blurs the outer half of the buffer.
        assert!((s.blur_start() - s.r_of_u(0.5)).abs() < 1e-4);
    }

    #[test]
    fn grid_and_screen_round_trip() {
        for (gaze, extent) in [
            (Vec2::new(160.0, 180.0), LogPolarExtent::FarthestCorner),
            (Vec2::new(30.0, 330.0), LogPolarExtent::Diagonal),
        ] {
            let s = space(
                UVec2::new(320, 360),
                gaze,
                LogPolarParams {
                    extent,
                    ..Default::default()
                },
            );
            let g = s.grid_size();
            for x in 0..g.x {
                for y in (0..g.y).step_by(7) {
                    let p = Vec2::new(x as f32 + 0.37, y as f32 + 0.61);
                    let screen = s.grid_to_screen(p).unwrap();
                    let back = s.screen_to_grid(screen).unwrap();
                    // ln r loses ~1e-7 relative near the gaze, where a column spans < 0.01 px.
                    assert!(
                        (back - p).abs().max_element() < 2e-3,
                        "{p} -> {screen} -> {back}"
                    );
                }
            }
            for (px, py) in [(1.5f32, 0.5f32), (0.0, 0.0), (319.5, 359.5), (200.0, 17.0)] {
                let q = Vec2::new(px, py);
                if (q - gaze).length() > 2.0 {
                    let back = s.grid_to_screen(s.screen_to_grid(q).unwrap()).unwrap();
                    assert!(
                        (back - q).length() < 1e-3 * (q - gaze).length(),
                        "{q} -> {back}"
                    );
                }
            }
        }
    }

    /// Samples per ring around a centred gaze (full rings, inside the inscribed circle) against
    /// the integral of the paper's density ρ(r)·2πr (f64 midpoint rule): Pearson's χ² over the
    /// rings and the rest of the screen (`test_draws`: samples drawn with the grid's density),
    /// at 1 % over both exponents.
    #[test]
    fn samples_per_ring_follow_the_papers_density() {
        use crate::sampling::test_draws::{draw_screen_samples, DENSITY_DRAWS};
        let alphas = [1.0f32, 4.0];
        let significance = fovea_test_kit::chi2::sidak(0.01, alphas.len());
        for alpha in alphas {
            let s = space(
                UVec2::new(320, 360),
                Vec2::new(160.0, 180.0),
                LogPolarParams {
                    alpha,
                    ..Default::default()
                },
            );
            let (g, law) = (s.grid_size(), *s.log_polar().unwrap());
            assert_eq!(
                s.sample_count(),
                g.x as u64 * g.y as u64,
                "no texel clipped"
            );
            let edges = [2.0f64, 8.0, 20.0, 45.0, 80.0, 120.0, 159.0];
            let rings = edges.len() - 1;
            let mut observed = vec![0f64; rings + 1];
            for p in draw_screen_samples(&s, DENSITY_DRAWS, 5) {
                let r = (p - s.gaze()).length() as f64;
                let ring = edges.windows(2).position(|e| r >= e[0] && r < e[1]);
                observed[ring.unwrap_or(rings)] += 1.0;
            }
            let draws = DENSITY_DRAWS as f64;
            let mut expected: Vec<f64> = edges
                .windows(2)
                .map(|e| {
                    let n = 20_000;
                    let dr = (e[1] - e[0]) / n as f64;
                    let samples: f64 = (0..n)
                        .map(|i| e[0] + (i as f64 + 0.5) * dr)
                        .map(|r| law.density(r, g) * std::f64::consts::TAU * r * dr)
                        .sum();
                    draws * samples / s.sample_count() as f64
                })
                .collect();
            expected.push(draws - expected.iter().sum::<f64>());
            let fit = fovea_test_kit::chi2::chi2_test(&observed, &expected, significance);
            println!("α {alpha}: per ring {observed:?} vs {expected:.0?}: {fit:?}");
            assert!(fit.is_ok(), "α {alpha}: {}", fit.unwrap_err());
        }
    }

    #[test]
    fn the_law_refuses_what_it_does_not_take() {
        let lp = RadialLaw::LogPolar(LogPolarParams::default());
        let bad = VisualPolarParams {
            radial: lp,
            layout: VpLayout::ScreenClipped,
            ..Default::default()
        };
        let e = VisualPolar::new(UVec2::new(64, 72), Vec2::new(32.0, 36.0), bad)
            .unwrap_err()
            .to_string();
        assert!(e.contains("log-polar") && e.contains("layout"), "{e}");
    }

    #[test]
    fn bad_parameters_name_the_field() {
        let e = LogPolarParams {
            sigma: 0.0,
            ..Default::default()
        }
        .validate()
        .unwrap_err()
        .to_string();
        assert!(e.contains("sigma"), "{e}");
        let e = LogPolarParams {
            alpha: f32::NAN,
            ..Default::default()
        }
        .validate()
        .unwrap_err()
        .to_string();
        assert!(e.contains("alpha"), "{e}");
        assert!(LogPolarLaw::new(1.0, 4.0).is_err());
    }
}
