//! Tests of the Visual-Polar mapping (`visual_polar.rs`).

use super::*;
use crate::sampling::test_draws::{draw_screen_samples, DENSITY_DRAWS};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

fn vp(w: u32, h: u32, gx: f32, gy: f32, params: VisualPolarParams) -> VisualPolar {
    VisualPolar::new(UVec2::new(w, h), Vec2::new(gx, gy), params)
        .expect("valid visual-polar parameters")
}

fn with_inverse(inverse_cdf: InverseCdf) -> VisualPolarParams {
    VisualPolarParams {
        inverse_cdf,
        ..Default::default()
    }
}

/// f64 bisection on the generalised CDF: the reference the f32 Newton solver is held to.
fn bisect_inverse(p: f64, k: f32) -> f64 {
    let target = p * cdf(E_MAX_DEG, k) as f64;
    let cdf64 = |d: f64| -> f64 {
        if k == 1.0 && d >= 5.79 {
            let t = 0.3 * d + 1.0;
            (1.0 / t + t.ln()) * 166.4 * std::f64::consts::PI - 612.3
        } else {
            cdf(d as f32, k) as f64 // only used off the k = 1 periphery (f32 is ample there)
        }
    };
    let (mut lo, mut hi) = (0.0f64, 4.0 * E_MAX_DEG as f64);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if cdf64(mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn csv_vectors_reproduced() {
    let Some(path) = fovea_test_kit::data::shared_data("vp_mapping_vectors.csv") else {
        return;
    };
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    let (mut rows, mut worst) = (0, 0.0f32);
    for line in text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("screen_w"))
    {
        let f: Vec<&str> = line.split(',').collect();
        let n = |i: usize| f[i].trim().parse::<f32>().unwrap();
        let mode = match f[4] {
            "poly" => InverseCdf::Polynomial,
            "exact" => InverseCdf::Exact,
            other => panic!("unknown mode {other}"),
        };
        let s = vp(n(0) as u32, n(1) as u32, n(2), n(3), with_inverse(mode));
        let (u, phi) = (n(5), n(6));
        let r = s.r_of_u(u);
        // Through the grid API too: x = u·width, y = φ/2π · rows of that column.
        let x = u * s.grid_size().x as f32;
        let col = (x.floor() as u32).min(s.grid_size().x - 1);
        let y = phi / TAU * s.rows_in_column(col) as f32;
        let p = s.vp_to_screen(Vec2::new(x, y));
        let err = (r - n(7))
            .abs()
            .max((p.x - n(8)).abs())
            .max((p.y - n(9)).abs());
        assert!(err < 1e-3, "row {line}: r {r} screen {p} (err {err})");
        worst = worst.max(err);
        rows += 1;
    }
    assert!(rows >= 600, "only {rows} vectors read");
    println!("{rows} vectors, worst error {worst:.2e} px");
}

#[test]
fn polynomial_matches_exact_inverse() {
    let p_f = fovea_fraction(ACUITY_KNEE_DEG, 1.0);
    let cdf_max = cdf(E_MAX_DEG, 1.0);
    let (mut worst_poly, mut worst_newton) = (0.0f64, 0.0f64);
    for i in 0..=2000 {
        let p = p_f + (1.0 - p_f) * i as f32 / 2000.0;
        let exact = bisect_inverse(p as f64, 1.0);
        worst_poly = worst_poly.max((inverse_cdf_poly(p) as f64 - exact).abs());
        worst_newton = worst_newton.max(
            (inverse_cdf_exact(1.0 - p, 1.0, cdf_max, E_MAX_DEG, E_MAX_DEG) as f64 - exact).abs(),
        );
        // The quartic's inverse (used by screen → VP) undoes Eq. 3.
        let back = poly_fraction_of(inverse_cdf_poly(p), cdf_max);
        assert!((back - p).abs() < 2e-6, "poly inverse at p {p}: {back}");
    }
    println!("poly vs exact: {worst_poly:.4}°, f32 Newton vs f64 bisection: {worst_newton:.2e}°");
    assert!(worst_poly < 0.05, "polynomial off by {worst_poly}°");
    assert!(worst_newton < 1e-4, "Newton off by {worst_newton}°");
    // Other density exponents go through the generalised CDF (Newton from the k = 1 guess).
    for k in [0.5f32, 1.5, 2.0] {
        let cdf_max = cdf(E_MAX_DEG, k);
        let p_f = fovea_fraction(ACUITY_KNEE_DEG, k);
        for i in 0..=200 {
            let p = p_f + (1.0 - p_f) * i as f32 / 200.0;
            let err = (inverse_cdf_exact(1.0 - p, k, cdf_max, E_MAX_DEG, E_MAX_DEG) as f64
                - bisect_inverse(p as f64, k))
            .abs();
            assert!(err < 1e-3, "k {k} p {p}: Newton off by {err}°");
        }
    }
}

#[test]
fn cdf_generalisation_is_consistent() {
    // Eq. 2 is (π/30)∫V·e: the generalised form at k = 1 (paper constants rounded) agrees closely.
    let general = |d: f32| {
        let s = std::f32::consts::PI / 30.0;
        let t = 0.3 * d + 1.0;
        let t0 = 0.3 * ACUITY_KNEE_DEG + 1.0;
        s * 60.0 * 0.5 * 5.79 * 5.79
            + s * 449.4 / 0.09 * ((t.ln() + 1.0 / t) - (t0.ln() + 1.0 / t0))
    };
    assert!((cdf_eq2(80.0) / general(80.0) - 1.0).abs() < 3e-3);
    assert!((cdf_eq2(ACUITY_KNEE_DEG) - 105.05).abs() < 0.05);
    assert!((cdf_eq2(80.0) - 1091.3).abs() < 0.1);
    for k in [0.5f32, 1.5] {
        // Numerical derivative of cdf matches cdf_derivative (and so the Newton steps are right).
        for d in [2.0f32, 10.0, 40.0, 75.0] {
            let num = (cdf(d + 0.01, k) - cdf(d - 0.01, k)) / 0.02;
            assert!(
                (num / cdf_derivative(d, k) - 1.0).abs() < 2e-2,
                "k {k} d {d}"
            );
        }
    }
}

const GAZES_1280: [(f32, f32); 4] = [
    (640.0, 720.0),
    (1279.0, 720.0),
    (200.0, 300.0),
    (10.0, 10.0),
];

#[test]
fn round_trips() {
    let mut rng = Pcg64::seed_from_u64(4);
    for (w, h, scale) in [(1280u32, 1440u32, 1.0f32), (640, 720, 0.5)] {
        for (gx, gy) in GAZES_1280 {
            for mode in [InverseCdf::Polynomial, InverseCdf::Exact] {
                let s = vp(w, h, gx * scale, gy * scale, with_inverse(mode));
                let grid = s.grid_size();
                let mut worst = 0.0f32;
                for _ in 0..10_000 {
                    let p = Vec2::new(
                        rng.random::<f32>() * w as f32,
                        rng.random::<f32>() * h as f32,
                    );
                    let g = s.screen_to_vp(p);
                    let n = s.rows_in_column((g.x as u32).min(grid.x - 1)) as f32;
                    assert!(g.x >= 0.0 && g.x <= grid.x as f32 + 1e-3 && g.y >= 0.0 && g.y < n);
                    worst = worst.max((s.vp_to_screen(g) - p).length());
                }
                assert!(
                    worst < 5e-3,
                    "{w}x{h} gaze ({gx},{gy}) {mode:?}: {worst} px"
                );
                // And grid → screen → grid (away from the gaze, where φ is ill-conditioned, and
                // from column edges, where a rounding can pick the neighbour's φ step).
                for _ in 0..10_000 {
                    let x = rng.random::<f32>() * grid.x as f32;
                    if x.fract() < 1e-3 || x.fract() > 1.0 - 1e-3 {
                        continue;
                    }
                    let y = rng.random::<f32>() * s.rows_in_column(x as u32) as f32;
                    let p = s.vp_to_screen(Vec2::new(x, y));
                    if (p - s.gaze()).length() < 1.0 {
                        continue;
                    }
                    let g = s.screen_to_vp(p);
                    let n = s.rows_in_column(x as u32) as f32;
                    let dy = (g.y - y).abs().min(n - (g.y - y).abs());
                    assert!(
                        (g.x - x).abs() < 2e-3 && dy < 1e-2,
                        "({x},{y}) -> {p} -> {g}"
                    );
                }
            }
        }
    }
}

#[test]
fn phi_wraps() {
    let s = vp(1280, 1440, 200.0, 300.0, Default::default());
    for x in [0.5f32, 50.3, 204.5, 300.0, 852.9] {
        let n = s.rows_in_column(x as u32) as f32;
        for y in [0.0f32, 0.25, n * 0.5, n - 0.1] {
            let a = s.vp_to_screen(Vec2::new(x, y));
            assert!((s.vp_to_screen(Vec2::new(x, y + n)) - a).length() < 1e-2);
            assert!((s.vp_to_screen(Vec2::new(x, y - n)) - a).length() < 1e-2);
        }
        // Just below and just above φ = 0 land at the two ends of the column.
        let r = s.r_of_u(x / s.grid_size().x as f32);
        let below = s.screen_to_vp(s.gaze() + r * Vec2::new(1e-3f32.cos(), -1e-3f32.sin()));
        let above = s.screen_to_vp(s.gaze() + r * Vec2::new(1e-3f32.cos(), 1e-3f32.sin()));
        let dy = 1e-3 / TAU * n;
        assert!(
            (below.y - (n - dy)).abs() < 1e-3 && below.y < n,
            "x {x}: {below}"
        );
        assert!((above.y - dy).abs() < 1e-3, "x {x}: {above}");
    }
}

#[test]
fn derived_numbers() {
    let s = vp(1280, 1440, 640.0, 720.0, Default::default());
    assert!((s.p_fovea() - 0.0963).abs() < 1e-4, "p_f {}", s.p_fovea());
    assert!((s.u_fovea() - 0.24).abs() < 1e-6);
    assert_eq!(s.grid_size(), UVec2::new(853, 960));
    assert_eq!(
        vp(640, 720, 320.0, 360.0, Default::default()).grid_size(),
        UVec2::new(427, 480)
    );
    let share = s.sample_count() as f64 / (1280.0 * 1440.0);
    let clipped = 1.0 - s.sample_count() as f64 / (853.0 * 960.0);
    println!(
        "grid 853x960, samples {}, traced share {share:.4}, clipped {clipped:.4}",
        s.sample_count()
    );
    assert!((share / 0.391 - 1.0).abs() < 0.01, "traced share {share}");
    assert!((clipped - 0.12).abs() < 0.002, "clipped {clipped}");
    // The sample count does not depend on the gaze (FarthestCorner).
    assert_eq!(
        vp(1280, 1440, 10.0, 10.0, Default::default()).sample_count(),
        s.sample_count()
    );
    // Clip layout: column 0 keeps a couple of rows, the last fovea column nearly all, then full.
    assert_eq!(s.rows_in_column(0), 2);
    assert!(s.rows_in_column(204) >= 958 && s.rows_in_column(205) == 960);
    assert!(s.is_valid_texel(IVec2::new(0, 1)) && !s.is_valid_texel(IVec2::new(0, 2)));
    assert!(!s.is_valid_texel(IVec2::new(853, 0)) && !s.is_valid_texel(IVec2::new(-1, 0)));
    let acuity_clip = VisualPolarParams::default().acuity_exact_clip_fraction();
    assert!(
        (acuity_clip - 0.088).abs() < 1e-3,
        "acuity-exact clip {acuity_clip}"
    );
}

/// Ring edges: 4 fovea rings, then `rings_periphery` up to `e_end`.
fn ring_edges(fovea: f32, e_end: f32, rings_periphery: usize) -> Vec<f32> {
    (0..=4)
        .map(|i| fovea * i as f32 / 4.0)
        .chain(
            (1..=rings_periphery)
                .map(|i| fovea + (e_end - fovea) * i as f32 / rings_periphery as f32),
        )
        .collect()
}

/// Screen-space sample density per eccentricity ring (ρ = distance / r_max · 80), on screen, held
/// to the target integrated over the ring's on-screen pixels by [`ring_counts`]' χ² test.
fn ring_density(s: &VisualPolar, rings_periphery: usize, significance: f64) -> RingFit {
    let k = s.params().density_exponent;
    let f = s.params().fovea_deg;
    let edges = ring_edges(f, E_MAX_DEG, rings_periphery);
    let grid = s.grid_size();
    // Target densities: uniform fovea; periphery ∝ V^k with the periphery's whole sample budget.
    let n_fovea = grid.x as f32 * grid.y as f32 * s.u_fovea() * 0.5;
    let fovea_density = n_fovea / (std::f32::consts::PI * s.r_fovea() * s.r_fovea());
    let n_periph = (grid.x as f32 * (1.0 - s.u_fovea())) * grid.y as f32;
    let scale = (E_MAX_DEG / s.r_max()).powi(2) / (60.0 * (cdf(E_MAX_DEG, k) - cdf(f, k)));
    let target = |rho: f32| {
        if rho < f {
            fovea_density
        } else {
            n_periph * acuity(rho).powf(k) * scale
        }
    };
    let rho_of = |p: Vec2| (p - s.gaze()).length() / s.r_max() * E_MAX_DEG;
    ring_counts(
        s,
        &edges,
        &rho_of,
        &|p| target(rho_of(p)) as f64,
        significance,
    )
}

/// The grid's samples per ring of `ecc` (a screen position's ring coordinate) against `expected`
/// (the target samples in the pixel at a position, summed over the ring's on-screen pixels), as
/// a χ² goodness-of-fit test (`fovea_test_kit::chi2`): [`DENSITY_DRAWS`] samples drawn with the
/// grid's density (`draw_screen_samples`) are counted per ring on screen, the rest off screen;
/// each ring expects its share of the target, the off-screen cell the remainder.
struct RingFit {
    /// (ring start, measured/target, samples per pixel) for rings with ≥ 500 pixels.
    rows: Vec<(f32, f32, f32)>,
    /// The off-screen share of the samples.
    offscreen: f32,
    fit: Result<fovea_test_kit::chi2::Chi2, String>,
}

fn ring_counts(
    s: &VisualPolar,
    edges: &[f32],
    ecc: &dyn Fn(Vec2) -> f32,
    expected_in_pixel: &dyn Fn(Vec2) -> f64,
    significance: f64,
) -> RingFit {
    let (w, h) = (s.screen().x as usize, s.screen().y as usize);
    let rings = edges.len() - 1;
    let ring = |rho: f32| edges.iter().rposition(|&e| e <= rho).filter(|&i| i < rings);
    let mut target = vec![0f64; rings];
    let mut pixels = vec![0u64; rings];
    for y in 0..h {
        for x in 0..w {
            let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            if let Some(i) = ring(ecc(p)) {
                target[i] += expected_in_pixel(p);
                pixels[i] += 1;
            }
        }
    }
    let kept = s.sample_count();
    // Per ring on screen, then off screen (or beyond the last ring).
    let mut observed = vec![0f64; rings + 1];
    for p in draw_screen_samples(s, DENSITY_DRAWS, 17) {
        let on_screen = p.x >= 0.0 && p.y >= 0.0 && p.x < w as f32 && p.y < h as f32;
        match ring(ecc(p)).filter(|_| on_screen) {
            Some(i) => observed[i] += 1.0,
            None => observed[rings] += 1.0,
        }
    }
    let n = DENSITY_DRAWS as f64;
    let mut expected: Vec<f64> = target.iter().map(|t| n * t / kept as f64).collect();
    let on_screen: f64 = expected.iter().sum();
    expected.push(n - on_screen);
    let fit = if on_screen > n * (1.0 + 1e-3) {
        Err(format!(
            "the target puts {on_screen:.0} of {n} samples on screen"
        ))
    } else {
        fovea_test_kit::chi2::chi2_test(&observed, &expected, significance)
    };
    let rows = (0..rings)
        .filter(|&i| pixels[i] >= 500) // rings barely on screen: their ratio says little
        .map(|i| {
            (
                edges[i],
                (observed[i] / expected[i]) as f32,
                (observed[i] / n * kept as f64 / pixels[i] as f64) as f32,
            )
        })
        .collect();
    RingFit {
        rows,
        offscreen: (observed[rings] / n) as f32,
        fit,
    }
}

#[test]
fn ring_density_follows_acuity() {
    let centre = (640.0, 720.0);
    let cases = [
        (1280u32, 1440u32, centre, VisualPolarParams::default()),
        (1280, 1440, (1270.0, 720.0), VisualPolarParams::default()),
        (1280, 1440, (10.0, 10.0), VisualPolarParams::default()),
        (640, 720, (320.0, 360.0), with_inverse(InverseCdf::Exact)),
        (
            640,
            720,
            (100.0, 150.0),
            VisualPolarParams {
                density_exponent: 1.5,
                ..Default::default()
            },
        ),
    ];
    let significance = fovea_test_kit::chi2::sidak(0.01, cases.len());
    let mut failures = Vec::new();
    for (w, h, (gx, gy), params) in cases {
        let s = vp(w, h, gx, gy, params);
        let RingFit {
            rows,
            offscreen,
            fit,
        } = ring_density(&s, 16, significance);
        let fovea: Vec<f32> = rows
            .iter()
            .filter(|r| r.0 < params.fovea_deg)
            .map(|r| r.2)
            .collect();
        let case = format!("{w}x{h} gaze ({gx},{gy}) k {}", params.density_exponent);
        println!(
            "{case}: off-screen {:.1} %, fovea spp {:?}, periphery ratio {:?}, {fit:?}",
            100.0 * offscreen,
            fovea.iter().map(|d| format!("{d:.2}")).collect::<Vec<_>>(),
            rows.iter()
                .filter(|r| r.0 >= params.fovea_deg)
                .map(|r| format!("{:.3}", r.1))
                .collect::<Vec<_>>()
        );
        if let Err(e) = fit {
            failures.push(format!("{case}: {e}"));
        }
        for &(rho, _, density) in &rows {
            if rho < params.fovea_deg {
                assert!(
                    density >= 1.0,
                    "fovea ring at ρ {rho}: {density} samples/pixel"
                );
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Bad user parameters are errors naming the parameter, never panics.
#[test]
fn invalid_parameters_are_errors() {
    let screen = UVec2::new(640, 720);
    let gaze = Vec2::new(320.0, 360.0);
    let cases: Vec<(VisualPolarParams, &str)> = vec![
        (
            VisualPolarParams {
                clip_fraction: 0.0,
                ..Default::default()
            },
            "clip_fraction",
        ),
        (
            VisualPolarParams {
                clip_fraction: 0.5,
                ..Default::default()
            },
            "clip_fraction",
        ),
        (
            VisualPolarParams {
                clip_fraction: -0.1,
                ..Default::default()
            },
            "clip_fraction",
        ),
        (
            VisualPolarParams {
                clip_fraction: f32::NAN,
                ..Default::default()
            },
            "clip_fraction",
        ),
        (
            VisualPolarParams {
                axis_scale: 0.0,
                ..Default::default()
            },
            "axis_scale",
        ),
        (
            VisualPolarParams {
                axis_scale: f32::INFINITY,
                ..Default::default()
            },
            "axis_scale",
        ),
        (
            VisualPolarParams {
                fovea_deg: 0.0,
                ..Default::default()
            },
            "fovea_deg",
        ),
        (
            VisualPolarParams {
                fovea_deg: 80.0,
                ..Default::default()
            },
            "fovea_deg",
        ),
        (
            VisualPolarParams {
                density_exponent: -1.0,
                ..Default::default()
            },
            "density_exponent",
        ),
        (
            VisualPolarParams {
                density_exponent: f32::NAN,
                ..Default::default()
            },
            "density_exponent",
        ),
        (
            VisualPolarParams {
                radius_mode: RadiusMode::Fixed(0.0),
                ..Default::default()
            },
            "radius_mode",
        ),
        (
            VisualPolarParams {
                radius_mode: RadiusMode::Fixed(f32::NAN),
                ..Default::default()
            },
            "radius_mode",
        ),
    ];
    for (params, name) in cases {
        match VisualPolar::new(screen, gaze, params) {
            Err(e) => assert!(
                e.to_string().contains(name),
                "{params:?}: error '{e}' should name {name}"
            ),
            Ok(_) => panic!("{params:?} accepted"),
        }
    }
    assert!(
        VisualPolar::new(UVec2::new(0, 720), gaze, Default::default())
            .unwrap_err()
            .to_string()
            .contains("screen")
    );
    assert!(
        VisualPolar::new(screen, Vec2::new(f32::NAN, 0.0), Default::default())
            .unwrap_err()
            .to_string()
            .contains("gaze")
    );
    // The acuity-exact clip and an off-screen gaze are fine.
    let exact_clip = VisualPolarParams::default().acuity_exact_clip_fraction();
    VisualPolar::new(
        screen,
        gaze,
        VisualPolarParams {
            clip_fraction: exact_clip,
            ..Default::default()
        },
    )
    .unwrap();
    VisualPolar::new(screen, Vec2::new(-50.0, 900.0), Default::default()).unwrap();
}

/// The paper's Eq. 3 (`shared/design/visual-polar.md` §3) in f64, written out here so the
/// mapping is checked against the paper rather than against itself.
fn paper_eq3(p: f64) -> f64 {
    25.09 * p.powi(4) + 0.1680 * p.powi(3) + 27.61 * p * p + 23.87 * p + 3.232
}

/// The paper's default layout (§4) by hand, for a grid `grid` around `gaze` at `r_max`: column
/// c keeps all rows beyond u_f = 0.24 (the 12 % triangular clip) and round(H·u/u_f) rows inside
/// it; the texel centre (x, y) lies at φ = 2π·y/rows, at r = u/u_f · r_f in the fovea and at
/// r = e(p)/e(1) · r_max beyond, p running linearly from p_f = CDF(5.79)/CDF(80) to 1.
struct PaperLayout {
    grid: (u32, u32),
    gaze: (f64, f64),
    r_max: f64,
}

impl PaperLayout {
    const U_F: f64 = 0.24;
    const P_F: f64 = 0.096257; // the vectors' header (vp_mapping_vectors.csv)

    fn rows(&self, col: u32) -> u32 {
        let (w, h) = self.grid;
        let u = (col as f64 + 0.5) / w as f64;
        if u >= Self::U_F {
            h
        } else {
            ((h as f64 * u / Self::U_F + 0.5).floor() as u32).clamp(1, h)
        }
    }

    fn screen(&self, x: f64, y: f64) -> (f64, f64) {
        let u = x / self.grid.0 as f64;
        let r_f = paper_eq3(Self::P_F) / paper_eq3(1.0) * self.r_max;
        let r = if u < Self::U_F {
            u / Self::U_F * r_f
        } else {
            let p = Self::P_F + (u - Self::U_F) / (1.0 - Self::U_F) * (1.0 - Self::P_F);
            paper_eq3(p) / paper_eq3(1.0) * self.r_max
        };
        let phi = y / self.rows(x as u32) as f64 * std::f64::consts::TAU;
        (self.gaze.0 + r * phi.cos(), self.gaze.1 + r * phi.sin())
    }
}

/// The `SamplingSpace` view of the paper's layout on 160×180 against the layout worked out by
/// hand from the paper: sizes, the sample count, the GPU parameters and every texel's screen
/// position; clipped and out-of-grid positions have no sample.
#[test]
fn sampling_space_impl() {
    use crate::sampling::SamplingSpace;
    let s = vp(160, 180, 80.0, 90.0, Default::default());
    let space: &dyn SamplingSpace = &s;
    assert_eq!(space.name(), "vp");
    assert_eq!(space.shader_variant(), "visual_polar");
    // Each axis × 2/3, rounded.
    assert_eq!(space.grid_size(), UVec2::new(107, 120));
    assert_eq!(space.screen_size(), UVec2::new(160, 180));
    // Every corner is hypot(80, 90) from the centred gaze.
    let r_max = 80f64.hypot(90.0);
    let paper = PaperLayout {
        grid: (107, 120),
        gaze: (80.0, 90.0),
        r_max,
    };
    // 26 fovea columns (u < 0.24) keep 1 577 rows between them, the other 81 all 120: 11 297
    // texels, the 12 % clip of 107 × 120 = 11 299.2 up to rounding.
    let by_hand: u64 = (0..107).map(|c| paper.rows(c) as u64).sum();
    assert_eq!(by_hand, 11_297);
    assert_eq!(space.sample_count(), by_hand);
    // The GPU parameters: gaze, r_max, k; u_f, p_f, r_f (the fovea edge, 5.79° on Eq. 3's axis)
    // and e(1) of Eq. 3 (the polynomial's own normaliser).
    let params = space.params();
    let close = |got: f32, want: f64, tol: f64| (got as f64 - want).abs() <= tol;
    assert!(
        close(params.gaze.x, 80.0, 0.0)
            && close(params.gaze.y, 90.0, 0.0)
            && close(params.gaze.z, r_max, 1e-4)
            && close(params.gaze.w, 1.0, 0.0),
        "gaze {:?}",
        params.gaze
    );
    let r_f = paper_eq3(PaperLayout::P_F) / paper_eq3(1.0) * r_max;
    assert!(
        close(params.shape0.x, PaperLayout::U_F, 1e-6)
            && close(params.shape0.y, PaperLayout::P_F, 1e-5)
            && close(params.shape0.z, r_f, 1e-3)
            && close(params.shape0.w, paper_eq3(1.0), 1e-4),
        "shape0 {:?} (want u_f 0.24, p_f {}, r_f {r_f}, e(1) {})",
        params.shape0,
        PaperLayout::P_F,
        paper_eq3(1.0)
    );
    let g = s.grid_size();
    let (mut mapped, mut worst) = (0u64, 0f64);
    for x in 0..g.x {
        for y in 0..g.y {
            let t = Vec2::new(x as f32, y as f32) + 0.5;
            let valid = y < paper.rows(x);
            match space.grid_to_screen(t) {
                Some(p) => {
                    assert!(valid, "clipped texel ({x}, {y}) mapped");
                    mapped += 1;
                    let (px, py) = paper.screen(x as f64 + 0.5, y as f64 + 0.5);
                    let err = (p.x as f64 - px).hypot(p.y as f64 - py);
                    worst = worst.max(err);
                    assert!(err < 2e-3, "texel ({x}, {y}): {p}, by hand ({px}, {py})");
                    let back = space
                        .screen_to_grid(p)
                        .expect("a sample's position has a grid position");
                    assert!(
                        (back.x - t.x).abs() < 2e-2,
                        "({x}, {y}): x {} vs {}",
                        back.x,
                        t.x
                    );
                }
                None => assert!(!valid, "valid texel ({x}, {y}) not mapped"),
            }
        }
    }
    assert_eq!(mapped, by_hand);
    println!("160x180: every texel within {worst:.1e} px of the paper's layout by hand");
    for bad in [
        Vec2::new(-0.5, 0.5),
        Vec2::new(0.5, -0.5),
        Vec2::new(g.x as f32 + 0.5, 0.5),
        Vec2::new(0.5, g.y as f32),
        Vec2::NAN,
        Vec2::new(1e30, 0.5),
    ] {
        assert_eq!(space.grid_to_screen(bad), None, "{bad}");
    }
    assert_eq!(space.screen_to_grid(Vec2::NAN), None);
    // A corner of the screen is at r_max: still inside the grid (the last column).
    assert!(space.screen_to_grid(Vec2::ZERO).is_some());
    // With a fixed radius, positions beyond it have no sample.
    let fixed = vp(
        160,
        180,
        80.0,
        90.0,
        VisualPolarParams {
            radius_mode: RadiusMode::Fixed(50.0),
            ..Default::default()
        },
    );
    assert_eq!(SamplingSpace::screen_to_grid(&fixed, Vec2::ZERO), None);
    assert!(SamplingSpace::screen_to_grid(&fixed, Vec2::new(100.0, 90.0)).is_some());
}

#[path = "visual_polar_headset_tests.rs"]
mod headset;
