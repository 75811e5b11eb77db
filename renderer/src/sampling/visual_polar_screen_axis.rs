//! The screen-aware ρ axis (`VpLayout::ScreenAware`): the screen-clipped layout's rows
//! with the periphery's columns placed by the acuity mass that lies on the screen.
//!
//! The paper places columns by V(e)^k·e (the acuity mass of the whole circle at e). Once each
//! column's rows are repacked onto the on-screen part of its circle, a column whose circle is
//! mostly off the screen packs all its rows into a short arc, and the outermost columns get denser
//! again (1.3 samples per pixel at 75–80° with the gaze in a corner). Here u ∈ [u_f, 1] follows the
//! CDF of V(e)^k·e·A(r)/2π instead (A: the on-screen angle of the circle of radius r), so that
//! samples per pixel = rows / (A·r) × columns per pixel of radius ∝ V(e)^k everywhere on the
//! screen. The fovea (u < u_f, r linear) is the paper's.
//!
//! The CDF has no closed form; it is integrated here per gaze and kept as r at `AXIS_PIECES + 1`
//! knots uniform in w = 1 − √(1 − p), p = (u − u_f)/(1 − u_f), r piecewise linear in w between
//! them. Near the far corner A(r) falls linearly to 0, so the mass left beyond r goes as
//! (r_end − r)² and r(p) has an infinite slope at p = 1: linear in p, the last piece put as many
//! columns by the corner as anywhere in it (2× the acuity target in the outermost 5°); in w it is
//! linear there. The knots travel to
//! the GPU after the column arcs in the sampling table (`texels`), and
//! `shaders/sampling/visual_polar_clipped.glsl` (`vp_axis_r_of_p`, `vp_axis_p_of_r`) evaluates
//! them op for op as `r_of_p` and `p_of_r` do, so both sides map with the same f32 numbers.

use super::acuity::acuity;
use super::visual_polar_clipped::on_screen_arcs;
use glam::{UVec2, Vec2};
use std::f32::consts::TAU;

/// Linear pieces of r(p): a few columns each at the default grids (427–853 columns), and 7
/// halvings for the GPU's inverse.
pub const AXIS_PIECES: usize = 128;
/// Halvings of `p_of_r`'s search: log2(AXIS_PIECES).
const SEARCH_STEPS: u32 = AXIS_PIECES.trailing_zeros();
/// Texels the knots take in the sampling table: AXIS_PIECES + 1 floats, 4 per texel, padded to an
/// even count so the previous frame's table starts on a column (2 texels) boundary.
pub const AXIS_KNOT_TEXELS: usize = (AXIS_PIECES + 1).div_ceil(4).next_multiple_of(2);
/// Trapezoid steps of the mass integral: A(r) has kinks where the circle meets a corner; at 1024
/// steps the knots move < 0.05 px against 8192 steps on a 1280×1440 screen.
const MASS_STEPS: usize = 1024;

/// r at the knots p = j / AXIS_PIECES, from the fovea's edge r_f to the axis' end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScreenAxis {
    knots: [f32; AXIS_PIECES + 1],
}

/// On-screen angle of the circle of radius `r` around `gaze`: 2π wholly on the screen, 0 wholly
/// off it (`on_screen_arcs` returns a full circle for both).
fn on_screen_angle(gaze: Vec2, r: f32, screen: UVec2) -> f32 {
    let arcs = on_screen_arcs(gaze, r, screen);
    if !arcs.wraps() {
        return arcs.total();
    }
    let s = screen.as_vec2();
    let nearest = gaze.clamp(Vec2::ZERO, s);
    let far = gaze.max(s - gaze).abs().length();
    let misses_rect = (gaze - nearest).length() >= r;
    if misses_rect || r >= far {
        0.0
    } else {
        TAU
    }
}

impl ScreenAxis {
    /// The axis for one gaze: the periphery from `r_f` to `r_end` pixels, eccentricity
    /// `e = r · ecc_per_px` (the paper's normalised degrees), density exponent `k`. `None` when no
    /// acuity mass lies on the screen beyond the fovea (then the paper's axis applies).
    pub fn new(
        gaze: Vec2,
        screen: UVec2,
        r_f: f32,
        r_end: f32,
        ecc_per_px: f32,
        k: f32,
    ) -> Option<ScreenAxis> {
        if !(r_f > 0.0 && r_end > r_f && ecc_per_px > 0.0 && r_end.is_finite()) {
            return None;
        }
        let density = |r: f64| {
            let e = r * ecc_per_px as f64;
            acuity(e as f32).powf(k) as f64 * e * on_screen_angle(gaze, r as f32, screen) as f64
        };
        // Fixed arrays: the renderer rebuilds the space on every gaze change and must not allocate.
        let mut mass = [0f64; MASS_STEPS + 1];
        let dr = (r_end - r_f) as f64 / MASS_STEPS as f64;
        let mut previous = density(r_f as f64);
        for i in 1..=MASS_STEPS {
            let here = density(r_f as f64 + i as f64 * dr);
            mass[i] = mass[i - 1] + 0.5 * (previous + here) * dr;
            previous = here;
        }
        let total = mass[MASS_STEPS];
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let mut knots = [0f32; AXIS_PIECES + 1];
        knots[0] = r_f;
        knots[AXIS_PIECES] = r_end;
        let mut step = 0;
        for (j, knot) in knots.iter_mut().enumerate().take(AXIS_PIECES).skip(1) {
            let w = j as f64 / AXIS_PIECES as f64;
            let target = (1.0 - (1.0 - w) * (1.0 - w)) * total;
            while step + 1 < MASS_STEPS && mass[step + 1] < target {
                step += 1;
            }
            let span = mass[step + 1] - mass[step];
            let t = if span > 0.0 {
                ((target - mass[step]) / span).clamp(0.0, 1.0)
            } else {
                0.0
            };
            *knot = (r_f as f64 + (step as f64 + t) * dr) as f32;
        }
        Some(ScreenAxis { knots })
    }

    /// r (pixels) at periphery fraction p ∈ [0, 1]. Past p = 1 (a texel's far edge in the last
    /// column, a radius beyond r_end) w continues as 1 + √(p − 1) and r along the last piece, so
    /// the axis stays monotonic and invertible, as the paper's does beyond u = 1. GLSL
    /// `vp_axis_r_of_p`.
    pub fn r_of_p(&self, p: f32) -> f32 {
        let q = 1.0 - p;
        let w = 1.0 - q.abs().sqrt().copysign(q);
        let x = w * AXIS_PIECES as f32;
        let i = x.floor().clamp(0.0, (AXIS_PIECES - 1) as f32) as usize;
        let t = x - i as f32;
        let (a, b) = (self.knots[i], self.knots[i + 1]);
        a + (b - a) * t
    }

    /// Periphery fraction p of radius r (pixels, r ≥ r_f); inverse of `r_of_p`. GLSL
    /// `vp_axis_p_of_r`.
    pub fn p_of_r(&self, r: f32) -> f32 {
        let (mut lo, mut hi) = (0usize, AXIS_PIECES);
        for _ in 0..SEARCH_STEPS {
            let mid = (lo + hi) / 2;
            if self.knots[mid] <= r {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let (a, b) = (self.knots[lo], self.knots[lo + 1]);
        let t = if b > a { (r - a) / (b - a) } else { 0.0 };
        let v = 1.0 - (lo as f32 + t) / AXIS_PIECES as f32;
        1.0 - (v * v).copysign(v)
    }

    /// The knots as the sampling table holds them (`AXIS_KNOT_TEXELS` texels, 4 knots each).
    pub fn texels(&self) -> [[f32; 4]; AXIS_KNOT_TEXELS] {
        let mut out = [[0.0; 4]; AXIS_KNOT_TEXELS];
        for (j, &r) in self.knots.iter().enumerate() {
            out[j / 4][j % 4] = r;
        }
        out
    }

    /// r at the knots w = j / AXIS_PIECES (tests, reports).
    pub fn knots(&self) -> &[f32; AXIS_PIECES + 1] {
        &self.knots
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCREEN: UVec2 = UVec2::new(1280, 1440);

    fn axis(gaze: Vec2) -> ScreenAxis {
        let far = gaze.max(SCREEN.as_vec2() - gaze).length();
        ScreenAxis::new(gaze, SCREEN, 100.0, far, 80.0 / far, 1.0).unwrap()
    }

    #[test]
    fn knots_rise_from_the_fovea_to_the_far_corner_and_invert() {
        for gaze in [
            Vec2::new(640.0, 720.0),
            Vec2::splat(10.0),
            Vec2::new(0.0, 700.0),
        ] {
            let a = axis(gaze);
            assert!(
                a.knots.windows(2).all(|w| w[1] > w[0]),
                "{gaze}: {:?}",
                a.knots
            );
            // Past p = 1 too (a last column's far edge): still increasing and invertible.
            let mut last = 0.0;
            for k in 0..=6144 {
                let p = k as f32 / 4096.0;
                let r = a.r_of_p(p);
                assert!(r > last, "{gaze}: r({p}) = {r} after {last}");
                last = r;
                let back = a.p_of_r(r);
                assert!((back - p).abs() < 2e-5, "{gaze}: p {p} → {back}");
            }
        }
    }

    /// The on-screen acuity mass between consecutive knots, integrated independently (midpoint
    /// rule), is the CDF's share of the piece: (1 − w_j)² − (1 − w_{j+1})² of the total.
    #[test]
    fn every_piece_holds_its_share_of_the_on_screen_acuity_mass() {
        let gaze = Vec2::new(200.0, 300.0);
        let a = axis(gaze);
        let far = gaze.max(SCREEN.as_vec2() - gaze).length();
        let mass = |r0: f32, r1: f32| {
            let steps = 400;
            let dr = (r1 - r0) as f64 / steps as f64;
            (0..steps)
                .map(|i| {
                    let r = r0 as f64 + (i as f64 + 0.5) * dr;
                    let e = r * (80.0 / far) as f64;
                    acuity(e as f32) as f64
                        * e
                        * on_screen_angle(gaze, r as f32, SCREEN) as f64
                        * dr
                })
                .sum::<f64>()
        };
        let pieces: Vec<f64> = a.knots.windows(2).map(|w| mass(w[0], w[1])).collect();
        let total: f64 = pieces.iter().sum();
        let share = |j: usize| {
            let w = |j: usize| 1.0 - j as f64 / AXIS_PIECES as f64;
            w(j) * w(j) - w(j + 1) * w(j + 1)
        };
        // The last piece holds (1/128)² of the mass, a few of the integral's steps: absolute there.
        for (j, m) in pieces.iter().enumerate() {
            let off = (m / total - share(j)).abs();
            assert!(
                off < 0.01 * share(j) || off < 5e-5,
                "piece {j}: {} of the mass, its share {}",
                m / total,
                share(j)
            );
        }
    }

    #[test]
    fn angle_is_zero_off_the_screen_and_full_inside() {
        let gaze = Vec2::new(640.0, 720.0);
        assert_eq!(on_screen_angle(gaze, 100.0, SCREEN), TAU);
        assert_eq!(on_screen_angle(gaze, 2000.0, SCREEN), 0.0);
        let part = on_screen_angle(gaze, 700.0, SCREEN);
        assert!(part > 0.0 && part < TAU);
        // A gaze off the screen: circles that miss the rectangle hold nothing.
        assert_eq!(on_screen_angle(Vec2::new(-100.0, 720.0), 50.0, SCREEN), 0.0);
    }

    #[test]
    fn no_axis_without_mass_beyond_the_fovea() {
        assert!(ScreenAxis::new(Vec2::new(640.0, 720.0), SCREEN, 100.0, 50.0, 0.1, 1.0).is_none());
        assert!(
            ScreenAxis::new(Vec2::new(-5000.0, 720.0), SCREEN, 100.0, 200.0, 0.1, 1.0).is_none()
        );
    }
}
