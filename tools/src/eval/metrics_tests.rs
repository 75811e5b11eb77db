use super::*;

/// A textured test image (smooth gradient plus a checker) so SSIM has structure to compare.
fn textured(width: u32, height: u32) -> Vec<[f32; 4]> {
    (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .map(|(x, y)| {
            let v = 0.3
                + 0.3 * x as f32 / width as f32
                + if (x / 4 + y / 4) % 2 == 0 { 0.2 } else { 0.0 };
            [v, v * 0.8, v * 0.6, 1.0]
        })
        .collect()
}

/// Deterministic noise in [-amplitude, amplitude] (an LCG: no test depends on a RNG crate).
fn noisy(img: &[[f32; 4]], amplitude: f32, seed: u64) -> Vec<[f32; 4]> {
    let mut state = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
    };
    img.iter()
        .map(|p| {
            [
                p[0] + amplitude * next(),
                p[1] + amplitude * next(),
                p[2] + amplitude * next(),
                1.0,
            ]
        })
        .collect()
}

#[test]
fn identical_images_are_perfect_everywhere() {
    let img = textured(48, 40);
    let e = evaluate(&img, &img, 48, 40, Vec2::new(20.0, 10.0), 8);
    assert_eq!(e.frame.rmse, Some(0.0));
    assert_eq!(e.frame.psnr, Some(PSNR_CAP_DB));
    assert_eq!(e.frame.ssim, Some(1.0));
    for r in &e.rings {
        assert_eq!(
            (r.metrics.rmse, r.metrics.ssim),
            (Some(0.0), Some(1.0)),
            "ring {}",
            r.ring
        );
    }
    // The capped PSNR keeps the JSON numeric (no inf/NaN).
    let json: serde_json::Value = serde_json::to_value(&e).unwrap();
    assert_eq!(json["frame"]["psnr"], PSNR_CAP_DB);
    assert_eq!(json["rings"][0]["ssim"], 1.0);
}

#[test]
fn constant_offset_gives_exact_rmse_and_psnr() {
    let a = vec![[0.25f32, 0.5, 0.75, 1.0]; 30 * 20];
    // 0.125 is exact in f32, so the expected numbers are exact too.
    let b: Vec<_> = a
        .iter()
        .map(|p| [p[0] + 0.125, p[1] + 0.125, p[2] + 0.125, 1.0])
        .collect();
    let e = evaluate(&a, &b, 30, 20, Vec2::new(15.0, 10.0), 4);
    assert_eq!(e.frame.rmse, Some(0.125));
    assert!(
        (e.frame.psnr.unwrap() - 18.061_799_739_838_87).abs() < 1e-9,
        "{:?}",
        e.frame.psnr
    );
    // One channel off: MSE is averaged over R, G, B.
    let c: Vec<_> = a.iter().map(|p| [p[0] + 0.125, p[1], p[2], 1.0]).collect();
    let e = evaluate(&a, &c, 30, 20, Vec2::new(15.0, 10.0), 4);
    assert!((e.frame.rmse.unwrap() - (0.125f64 * 0.125 / 3.0).sqrt()).abs() < 1e-12);
    assert_eq!(psnr_from_mse(0.01), 20.0);
    assert_eq!(psnr_from_mse(1e-30), PSNR_CAP_DB);
}

#[test]
fn ssim_of_flat_images_follows_the_luminance_term() {
    // Flat images: variances and covariance vanish, SSIM = (2ab + C1) / (a² + b² + C1).
    let (a, b) = (0.5f64, 0.25f64);
    let x = vec![[a as f32; 4]; 20 * 20];
    let y = vec![[b as f32; 4]; 20 * 20];
    let expected = (2.0 * a * b + 1e-4) / (a * a + b * b + 1e-4);
    let e = evaluate(&x, &y, 20, 20, Vec2::new(10.0, 10.0), 2);
    assert!(
        (e.frame.ssim.unwrap() - expected).abs() < 1e-9,
        "{:?} vs {expected}",
        e.frame.ssim
    );
}

#[test]
fn ssim_drops_with_noise() {
    let img = textured(64, 48);
    let mut last = 1.0;
    for amplitude in [0.01, 0.05, 0.2] {
        let s = evaluate(
            &img,
            &noisy(&img, amplitude, 7),
            64,
            48,
            Vec2::new(32.0, 24.0),
            4,
        )
        .frame
        .ssim
        .unwrap();
        assert!(
            s < last,
            "SSIM {s} at noise {amplitude} is not below {last}"
        );
        last = s;
    }
    assert!(last < 0.8, "heavy noise still scores {last}");
}

#[test]
fn ring_pixel_counts_cover_the_image() {
    for gaze in [
        Vec2::new(32.0, 36.0),
        Vec2::new(0.0, 0.0),
        Vec2::new(63.9, 5.5),
        Vec2::new(-20.0, 100.0),
    ] {
        let rings = Rings::new(64, 72, gaze, 20);
        assert_eq!(
            rings.pixel_counts().iter().sum::<usize>(),
            64 * 72,
            "gaze {gaze}"
        );
    }
}

#[test]
fn pixels_land_in_the_expected_rings() {
    // Gaze at the centre of 100×100: r_max = 50√2 ≈ 70.71, 10 rings of ≈ 7.07 px.
    let rings = Rings::new(100, 100, Vec2::new(50.0, 50.0), 10);
    assert!((rings.r_max - 50.0 * 2f64.sqrt()).abs() < 1e-9);
    assert_eq!(rings.ring_of(50, 50), 0); // centre (50.5, 50.5): r ≈ 0.7
    assert_eq!(rings.ring_of(80, 50), 4); // r = 30.5 → 4.31 rings
    assert_eq!(rings.ring_of(50, 10), 5); // r ≈ 39.5 (y down, above the gaze)
    assert_eq!(rings.ring_of(0, 0), 9);
    assert_eq!(rings.ring_of(99, 99), 9);
    let (r0, r1) = rings.bounds(4);
    assert!(
        (r0 - 4.0 * rings.r_max / 10.0).abs() < 1e-12
            && (r1 - 5.0 * rings.r_max / 10.0).abs() < 1e-12
    );
    // Gaze in a corner: r_max is the diagonal and the far corner is in the last ring.
    let rings = Rings::new(100, 100, Vec2::ZERO, 10);
    assert_eq!(
        (
            rings.ring_of(0, 0),
            rings.ring_of(99, 99),
            rings.ring_of(99, 0)
        ),
        (0, 9, 7)
    );
}

#[test]
fn peripheral_error_shows_only_in_outer_rings() {
    let (w, h) = (64u32, 72u32);
    let gaze = Vec2::new(32.0, 36.0);
    let reference = textured(w, h);
    let rings = Rings::new(w, h, gaze, 10);
    // Perturb every pixel farther than 0.7·r_max from the gaze.
    let test: Vec<_> = reference
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let (x, y) = (i as u32 % w, i as u32 / w);
            let r = (Vec2::new(x as f32 + 0.5, y as f32 + 0.5) - gaze).length() as f64;
            if r > 0.7 * rings.r_max {
                [p[0] + 0.3, p[1] - 0.2, p[2], 1.0]
            } else {
                *p
            }
        })
        .collect();
    let e = evaluate(&reference, &test, w, h, gaze, 10);
    // Rings 0..=4 end at 0.5·r_max ≈ 24 px: their 11×11 SSIM windows (reaching 5√2 ≈ 7.1 px) stay
    // inside the clean disc (0.7·r_max ≈ 33.7 px).
    for r in &e.rings[..5] {
        assert_eq!(
            (r.metrics.rmse, r.metrics.ssim),
            (Some(0.0), Some(1.0)),
            "inner ring {}",
            r.ring
        );
    }
    for r in &e.rings[7..] {
        assert!(
            r.metrics.rmse.unwrap() > 0.1 && r.metrics.ssim.unwrap() < 0.99,
            "outer ring {}: {:?}",
            r.ring,
            r.metrics
        );
    }
    assert!(e.frame.rmse.unwrap() > 0.0 && e.frame.ssim.unwrap() < 1.0);
}

#[test]
fn empty_rings_report_null() {
    // A gaze far outside a tiny image leaves the inner rings without pixels.
    let img = textured(4, 4);
    let e = evaluate(&img, &img, 4, 4, Vec2::new(-100.0, -100.0), 10);
    assert_eq!(e.rings[0].metrics.pixels, 0);
    assert!(e.rings[0].metrics.rmse.is_none() && e.rings[0].metrics.ssim.is_none());
    assert_eq!(
        serde_json::to_value(&e).unwrap()["rings"][0]["rmse"],
        serde_json::Value::Null
    );
}

#[test]
fn flicker_is_change_the_reference_does_not_have() {
    let px = |v: u8| [v, v, v, 255];
    let (a, b) = (px(100).repeat(4), px(140).repeat(4));
    // Still reference: the whole change is flicker; the same change in the reference: none.
    let still = flicker_map(&a, &b, &a, &a);
    assert!(
        still.iter().all(|&f| (f - 40.0 / 255.0).abs() < 1e-12),
        "{still:?}"
    );
    assert!(flicker_map(&a, &b, &a, &b).iter().all(|&f| f == 0.0));
}

#[test]
fn isolated_bright_pixels_counts_only_pixels_brighter_than_every_neighbour() {
    let (w, h) = (6usize, 5usize);
    let mut img: Vec<u8> = std::iter::repeat_n([40u8, 40, 40, 255], w * h)
        .flatten()
        .collect();
    let mut set = |x: usize, y: usize, v: u8| {
        img[4 * (y * w + x)..4 * (y * w + x) + 3].copy_from_slice(&[v, v, v])
    };
    set(2, 2, 200); // a firefly
    set(0, 0, 150); // one in the corner (three neighbours)
    set(4, 1, 220); // two bright neighbours: neither is isolated
    set(5, 1, 210);
    set(4, 3, 90); // only 50 levels above its neighbours
    assert_eq!(isolated_bright_pixels(&img, w, h, 60.0), 2);
    assert_eq!(isolated_bright_pixels(&img, w, h, 40.0), 3);
    assert_eq!(isolated_bright_pixels(&img, w, h, 200.0), 0);
}
