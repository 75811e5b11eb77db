//! Tests of the headset-aware eccentricity axis (`visual_polar_headset.rs`).

use super::*;
use crate::sampling::visual_polar_headset::FAR_PIXELS_PER_SCREEN;

/// FOVE 0 (config/headsets/fove0.toml) and the Pimax Crystal's left eye (asymmetric, wider).
fn fove0() -> FovTangents {
    FovTangents::from_angles_deg(-45.0, 45.0, -48.4, 48.4)
}
fn pimax_left() -> FovTangents {
    FovTangents::from_angles_deg(-51.7, 41.7, -51.9, 51.9)
}

fn headset(fov: FovTangents) -> VisualPolarParams {
    VisualPolarParams {
        eccentricity: Eccentricity::Headset(fov),
        ..Default::default()
    }
}

/// Centre, near an edge and in a corner of a w×h screen.
fn gazes(w: u32, h: u32) -> [(&'static str, Vec2); 3] {
    let s = Vec2::new(w as f32, h as f32);
    [
        ("centre", s * 0.5),
        ("edge", s * Vec2::new(0.97, 0.5)),
        ("corner", s * Vec2::new(0.02, 0.03)),
    ]
}

/// The angle between the view directions of two pixels, from the FOV definition, in f64.
fn angle_between(fov: FovTangents, screen: Vec2, a: Vec2, b: Vec2) -> f64 {
    let dir = |p: Vec2| {
        let x = -fov.left as f64 + p.x as f64 / screen.x as f64 * (fov.left + fov.right) as f64;
        let y = -fov.up as f64 + p.y as f64 / screen.y as f64 * (fov.up + fov.down) as f64;
        let n = (x * x + y * y + 1.0).sqrt();
        [x / n, y / n, 1.0 / n]
    };
    let (u, v) = (dir(a), dir(b));
    let dot = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    let cross = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2])
        .sqrt()
        .atan2(dot)
        .to_degrees()
}

#[test]
fn true_eccentricity_matches_the_view_directions() {
    let mut rng = Pcg64::seed_from_u64(4);
    for fov in [fove0(), pimax_left()] {
        for (w, h) in [(640u32, 720u32), (1280, 1440)] {
            let screen = Vec2::new(w as f32, h as f32);
            for (name, gaze) in gazes(w, h) {
                let s = vp(w, h, gaze.x, gaze.y, headset(fov));
                let corners = [
                    Vec2::ZERO,
                    Vec2::new(screen.x, 0.0),
                    Vec2::new(0.0, screen.y),
                    screen,
                ];
                let e_max = corners
                    .iter()
                    .map(|&c| angle_between(fov, screen, gaze, c))
                    .fold(0.0, f64::max);
                let got = s.headset().unwrap().e_max as f64;
                assert!((got - e_max).abs() < 1e-3, "{name}: e_max {got} vs {e_max}");
                for _ in 0..2000 {
                    let p = Vec2::new(
                        rng.random::<f32>() * screen.x,
                        rng.random::<f32>() * screen.y,
                    );
                    let want = angle_between(fov, screen, gaze, p);
                    let e = s.true_eccentricity(p).unwrap() as f64;
                    assert!((e - want).abs() < 1e-3, "{name} {p}: {e}° vs {want}°");
                }
            }
        }
    }
}

/// grid → screen → grid and screen → grid → screen, wherever the sample is on the screen.
#[test]
fn headset_mapping_round_trips() {
    let mut rng = Pcg64::seed_from_u64(5);
    for fov in [fove0(), pimax_left()] {
        let (w, h) = (640u32, 720u32);
        for (name, gaze) in gazes(w, h) {
            let s = vp(w, h, gaze.x, gaze.y, headset(fov));
            let g = s.grid_size();
            let (mut worst_grid, mut worst_screen, mut checked) = (0f32, 0f32, 0);
            for _ in 0..20_000 {
                let col = rng.random_range(0..g.x);
                let row = rng.random_range(0..s.rows_in_column(col));
                let t = Vec2::new(
                    col as f32 + rng.random::<f32>().min(0.999),
                    row as f32 + rng.random::<f32>().min(0.999),
                );
                let p = s.vp_to_screen(t);
                if !(p.x >= 0.0 && p.y >= 0.0 && p.x < w as f32 && p.y < h as f32) {
                    continue;
                }
                checked += 1;
                let back = s.screen_to_vp(p);
                // φ compared in rows, across the seam.
                let n = s.rows_in_column(col) as f32;
                let dy = (back.y - t.y).rem_euclid(n);
                worst_grid = worst_grid.max((back.x - t.x).abs()).max(dy.min(n - dy));
            }
            for _ in 0..20_000 {
                let p = Vec2::new(
                    rng.random::<f32>() * w as f32,
                    rng.random::<f32>() * h as f32,
                );
                worst_screen = worst_screen.max((s.vp_to_screen(s.screen_to_vp(p)) - p).length());
            }
            println!("{name}: {checked} on-screen samples, grid round trip {worst_grid:.2e} texels, screen {worst_screen:.2e} px");
            assert!(checked > 5000, "{name}: only {checked} samples on screen");
            assert!(
                worst_grid < 2e-3,
                "{name}: grid round trip off by {worst_grid} texels"
            );
            assert!(
                worst_screen < 1e-2,
                "{name}: screen round trip off by {worst_screen} px"
            );
        }
    }
}

/// In the fovea the ρ axis is linear in true degrees: a column's samples all lie at the same true
/// eccentricity u/u_f · fovea°, whatever their direction.
#[test]
fn headset_fovea_is_linear_in_true_degrees() {
    for fov in [fove0(), pimax_left()] {
        for (name, gaze) in gazes(640, 720) {
            let s = vp(640, 720, gaze.x, gaze.y, headset(fov));
            let g = s.grid_size();
            let fovea_cols = (s.u_fovea() * g.x as f32) as u32;
            for col in 1..fovea_cols {
                let x = col as f32 + 0.5;
                let want = x / g.x as f32 / s.u_fovea() * s.params().fovea_deg;
                for row in 0..s.rows_in_column(col) {
                    let p = s.vp_to_screen(Vec2::new(x, row as f32 + 0.5));
                    let e = s.true_eccentricity(p).unwrap();
                    assert!(
                        (e - want).abs() < 1e-3,
                        "{name} column {col} row {row}: {e}° vs {want}°"
                    );
                }
            }
        }
    }
}

/// The density test of the paper's axis, per ring of TRUE eccentricity: the target is uniform in
/// the fovea and ∝ V^k outside it per unit of the polar measure e·de·dφ (φ the pixel angle the
/// rows are laid on); a pixel's share is that density times e·|∂(e, φ)/∂(x, y)|.
#[test]
fn headset_ring_density_follows_acuity() {
    let (w, h) = (640u32, 720u32);
    let fovs = [("fove0", fove0()), ("pimax", pimax_left())];
    let significance = fovea_test_kit::chi2::sidak(0.01, fovs.len() * gazes(w, h).len());
    let mut failures = Vec::new();
    for (fov_name, fov) in fovs {
        for (name, gaze) in gazes(w, h) {
            let s = vp(w, h, gaze.x, gaze.y, headset(fov));
            let axis = *s.headset().unwrap();
            let (k, f) = (s.params().density_exponent, s.params().fovea_deg);
            let grid = s.grid_size();
            let n_fovea = grid.x as f64 * grid.y as f64 * s.u_fovea() as f64 * 0.5;
            let n_periph = (grid.x as f64 * (1.0 - s.u_fovea() as f64)) * grid.y as f64;
            // ∫_f^e_max V^k e de = (30/π)(cdf(e_max) − cdf(f)).
            let mass = 30.0 / std::f64::consts::PI * (cdf(axis.e_max, k) - cdf(f, k)) as f64;
            let density = |e: f32| {
                if e < f {
                    n_fovea / (std::f64::consts::PI * (f * f) as f64)
                } else {
                    n_periph * acuity(e).powf(k) as f64 / (std::f64::consts::TAU * mass)
                }
            };
            let ecc = |p: Vec2| axis.eccentricity(p - gaze);
            let in_pixel = |p: Vec2| {
                let hd = 0.25f32;
                let de_dx =
                    (ecc(p + Vec2::X * hd) - ecc(p - Vec2::X * hd)) as f64 / (2.0 * hd) as f64;
                let de_dy =
                    (ecc(p + Vec2::Y * hd) - ecc(p - Vec2::Y * hd)) as f64 / (2.0 * hd) as f64;
                let d = p - gaze;
                let r2 = d.length_squared() as f64;
                let (dphi_dx, dphi_dy) = (-d.y as f64 / r2, d.x as f64 / r2);
                let jac = (de_dx * dphi_dy - de_dy * dphi_dx).abs();
                density(ecc(p)) * ecc(p) as f64 * jac
            };
            let edges = ring_edges(f, axis.e_max, 16);
            let RingFit {
                rows,
                offscreen,
                fit,
            } = ring_counts(&s, &edges, &ecc, &in_pixel, significance);
            println!(
                "{fov_name} gaze {name}: e_max {:.1}°, off-screen {:.1} %, rings (e°, measured/target, spp) {:?}, {fit:?}",
                axis.e_max,
                100.0 * offscreen,
                rows.iter().map(|r| format!("{:.1}: {:.3} {:.2}", r.0, r.1, r.2)).collect::<Vec<_>>()
            );
            if let Err(e) = fit {
                failures.push(format!("{fov_name} gaze {name}: {e}"));
            }
            assert!(
                rows.len() >= 12,
                "{fov_name} {name}: only {} rings on screen",
                rows.len()
            );
            for &(e, _, spp) in &rows {
                if e < f {
                    assert!(
                        spp >= 1.0,
                        "{fov_name} {name}: fovea ring at {e}°: {spp} samples/pixel"
                    );
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The paper's axis stays the default and packs as before; the headset axis forces the exact
/// inverse and packs its own slots.
#[test]
fn headset_packing() {
    let paper = vp(640, 720, 320.0, 360.0, Default::default());
    let p = paper.sampling_params();
    assert_eq!(
        VisualPolarParams::default().eccentricity,
        Eccentricity::Normalized
    );
    assert_eq!(
        (p.gaze.z, p.shape0.w, p.shape1.y, p.shape1.w),
        (paper.r_max(), inverse_cdf_poly(1.0), 0.0, 0.0)
    );
    let s = vp(640, 720, 100.0, 200.0, headset(fove0()));
    let q = s.sampling_params();
    let axis = s.headset().unwrap();
    assert_eq!(q.shape1.y, 5.0, "flags: exact + headset");
    assert_eq!((q.gaze.z, q.shape0.w), (axis.gaze_tan.x, axis.gaze_tan.y));
    assert_eq!((q.shape1.z, q.shape1.w), (axis.scale.x, axis.scale.y));
    assert_eq!((q.shape0.z, q.shape1.x), (s.params().fovea_deg, axis.e_max));
    assert_eq!(axis.far, FAR_PIXELS_PER_SCREEN * (640.0 + 720.0));
    // The whole ρ axis: u = 1 is the farthest corner's true eccentricity.
    assert!((s.r_of_u(1.0) - axis.e_max).abs() < 1e-3);
    // Pixel radii for pixel-based code: the fovea is a few percent of the screen.
    assert!(
        s.r_fovea() > 10.0 && s.r_fovea() < 80.0,
        "fovea radius {} px",
        s.r_fovea()
    );
    assert!(s.radius_of_eccentricity(30.0) > s.r_fovea());
}

#[test]
fn headset_invalid_parameters_are_errors() {
    let screen = UVec2::new(640, 720);
    let gaze = Vec2::new(320.0, 360.0);
    let nan = FovTangents {
        left: f32::NAN,
        ..fove0()
    };
    let flat = FovTangents {
        left: -1.0,
        right: 1.0,
        ..fove0()
    };
    let cases: Vec<(VisualPolarParams, &str)> = vec![
        (
            VisualPolarParams {
                layout: VpLayout::ScreenClipped,
                ..headset(fove0())
            },
            "layout",
        ),
        (
            VisualPolarParams {
                radius_mode: RadiusMode::Fixed(300.0),
                ..headset(fove0())
            },
            "radius_mode",
        ),
        (headset(nan), "FOV tangents"),
        (headset(flat), "FOV tangents"),
        // A 10°-wide view whose farthest corner is within the 20° fovea.
        (
            VisualPolarParams {
                fovea_deg: 20.0,
                ..headset(FovTangents::from_angles_deg(-5.0, 5.0, -5.0, 5.0))
            },
            "fovea",
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
}
