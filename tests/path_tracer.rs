//! The path tracer against answers known in advance: the furnace, analytic direct lighting
//! (next-event estimation through the alias table, area and punctual lights), depth semantics,
//! 1/√spp convergence and determinism.

use fovea_renderer::frame::{CameraPose, FrameInput, RenderSettings};
use fovea_renderer::passes::tonemap::ToneCurve;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::Cartesian;
use fovea_scene::{Camera, Material, PunctualLight, Scene};
use fovea_tests::scenes::{add_quad, furnace, lambert};
use fovea_tests::{
    assert_clean, assert_pictures_equal, gpu, mean_rgb, rmse, save_preview, Picture,
};
use glam::{Mat4, UVec2, Vec3};

fn renderer(
    ctx: &std::sync::Arc<fovea_renderer::vk::Context>,
    scene: &Scene,
    size: u32,
    seed: u32,
) -> Renderer {
    let space = Box::new(Cartesian::new(UVec2::splat(size)));
    let settings = RenderSettings {
        seed,
        tone_curve: ToneCurve::Clamp,
        ..Default::default()
    };
    Renderer::new(ctx, scene, space, settings).unwrap()
}

fn pose(scene: &Scene, size: u32) -> CameraPose {
    CameraPose::from_scene_camera(&scene.cameras[0], size, size)
}

#[test]
fn furnace_converges_to_the_geometric_series_for_each_depth() {
    let ctx = gpu();
    let (albedo, emission) = (0.5f32, 1.0f32);
    let scene = furnace(albedo, emission);
    let mut r = renderer(&ctx, &scene, 16, 7);
    for depth in 1..=4u32 {
        let image = r
            .render_reference(&pose(&scene, 16), 64, depth, |_| {})
            .unwrap();
        let expected: f64 = (0..depth)
            .map(|k| (emission * albedo.powi(k as i32)) as f64)
            .sum();
        let mean = mean_rgb(&image);
        for c in mean {
            assert!(
                (c - expected).abs() < 0.01 * expected,
                "depth {depth}: mean {c} vs analytic {expected}"
            );
        }
        // Every direction sees the same radiance: each quadrant of the view agrees (single
        // pixels are too noisy near the box's corners, where next-event estimation is weakest).
        for q in 0..4 {
            let quadrant: Vec<[f32; 4]> = image
                .iter()
                .enumerate()
                .filter(|(i, _)| ((i % 16) / 8) + 2 * ((i / 16) / 8) == q)
                .map(|(_, p)| *p)
                .collect();
            let m = mean_rgb(&quadrant)[1];
            assert!(
                (m - expected).abs() < 0.03 * expected,
                "depth {depth}: quadrant {q} mean {m} vs {expected}"
            );
        }
    }
    assert_clean(&ctx);
}

/// Irradiance at `p` (normal +y) from a uniformly emitting polygon of radiance `l` (Lambert).
fn polygon_irradiance(p: Vec3, polygon: &[Vec3], l: f32) -> f32 {
    let n = Vec3::Y;
    let mut sum = 0.0;
    for i in 0..polygon.len() {
        let a = (polygon[i] - p).normalize();
        let b = (polygon[(i + 1) % polygon.len()] - p).normalize();
        let angle = a.dot(b).clamp(-1.0, 1.0).acos();
        sum += angle * n.dot(a.cross(b).normalize());
    }
    0.5 * l * sum.abs()
}

#[test]
fn direct_light_matches_lamberts_formula_and_the_inverse_square_law() {
    let ctx = gpu();
    let light = |e: f32| Material {
        double_sided: true,
        ..lambert(0.0, e)
    };
    let mut scene = Scene {
        materials: vec![lambert(1.0, 0.0), light(5.0), light(2.0)],
        mesh_names: vec!["m".into()],
        ..Default::default()
    };
    add_quad(
        &mut scene,
        [
            Vec3::new(-5.0, 0.0, -5.0),
            Vec3::new(-5.0, 0.0, 5.0),
            Vec3::new(5.0, 0.0, 5.0),
            Vec3::new(5.0, 0.0, -5.0),
        ],
        0,
    );
    let quad = [
        Vec3::new(-0.5, 2.0, -0.5),
        Vec3::new(0.5, 2.0, -0.5),
        Vec3::new(0.5, 2.0, 0.5),
        Vec3::new(-0.5, 2.0, 0.5),
    ];
    add_quad(&mut scene, quad, 1);
    let tri = [
        Vec3::new(1.0, 1.5, 0.0),
        Vec3::new(1.5, 1.5, 0.0),
        Vec3::new(1.0, 1.5, 0.8),
    ];
    add_quad(&mut scene, [tri[0], tri[1], tri[2], tri[2]], 2); // second triangle is degenerate (zero area)
    let point = (Vec3::new(-1.0, 1.2, 0.3), Vec3::splat(3.0));
    scene.punctual_lights.push(PunctualLight::Point {
        position: point.0,
        intensity: point.1,
        range: None,
    });
    // Looking straight down from (0, 1, 0) with a narrow field of view.
    let half = 0.05f32;
    scene.cameras.push(Camera {
        world_from_view: Mat4::from_translation(Vec3::Y)
            * Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2),
        yfov: 2.0 * half.atan(),
        aspect: None,
        znear: 0.01,
        name: "down".into(),
    });
    let size = 16;
    let mut r = renderer(&ctx, &scene, size, 3);
    let image = r
        .render_reference(&pose(&scene, size), 256, 2, |_| {})
        .unwrap();

    let mut expected = 0.0f64;
    let n = 32;
    for i in 0..n {
        for j in 0..n {
            let p = Vec3::new(
                (2.0 * (i as f32 + 0.5) / n as f32 - 1.0) * half,
                0.0,
                (2.0 * (j as f32 + 0.5) / n as f32 - 1.0) * half,
            );
            let to_point = point.0 - p;
            let e = polygon_irradiance(p, &quad, 5.0)
                + polygon_irradiance(p, &tri, 2.0)
                + point.1.x * to_point.normalize().y / to_point.length_squared();
            expected += (e / std::f32::consts::PI) as f64;
        }
    }
    expected /= (n * n) as f64;
    let mean = mean_rgb(&image)[0];
    save_preview("direct_light.png", size, size, &image);
    assert!(
        (mean - expected).abs() < 0.01 * expected,
        "mean radiance {mean} vs analytic {expected}"
    );
    assert_clean(&ctx);
}

#[test]
fn max_depth_adds_exactly_one_kind_of_light_per_vertex() {
    let ctx = gpu();
    let scene = fovea_tests::owned_scene("cornell-box");
    let size = 32;
    let mut r = renderer(&ctx, &scene, size, 1);
    let means: Vec<f64> = (1..=3)
        .map(|d| {
            let image = r
                .render_reference(&pose(&scene, size), 16, d, |_| {})
                .unwrap();
            if d == 1 {
                // Only the light itself is visible: most pixels are exactly black.
                let black = image
                    .iter()
                    .filter(|p| p[0] == 0.0 && p[1] == 0.0 && p[2] == 0.0)
                    .count();
                assert!(
                    black > image.len() * 9 / 10,
                    "depth 1 shows more than emission: {black} black pixels"
                );
                assert!(
                    image.iter().any(|p| p[0] > 1.0),
                    "the light is not visible at depth 1"
                );
            }
            mean_rgb(&image).iter().sum::<f64>()
        })
        .collect();
    assert!(
        means[0] < means[1] && means[1] < means[2],
        "depth means not increasing: {means:?}"
    );
    assert_clean(&ctx);
}

#[test]
fn error_falls_like_one_over_sqrt_spp() {
    let ctx = gpu();
    let scene = fovea_tests::owned_scene("cornell-box");
    let size = 40;
    let reference = renderer(&ctx, &scene, size, 100)
        .render_reference(&pose(&scene, size), 1024, 3, |_| {})
        .unwrap();
    let mut r = renderer(&ctx, &scene, size, 200);
    let low = r
        .render_reference(&pose(&scene, size), 16, 3, |_| {})
        .unwrap();
    let high = r
        .render_reference(&pose(&scene, size), 64, 3, |_| {})
        .unwrap();
    save_preview("cornell_reference_1024spp.png", size, size, &reference);
    let ratio = rmse(&low, &reference) / rmse(&high, &reference);
    // 4× the samples halves the error; the reference's own noise makes the ideal ≈ 1.96.
    assert!(
        (1.6..2.4).contains(&ratio),
        "RMSE ratio 16 → 64 spp is {ratio}, expected ≈ 2"
    );
    assert_clean(&ctx);
}

#[test]
fn same_seed_gives_identical_frames_and_new_frames_give_new_noise() {
    let ctx = gpu();
    let scene = fovea_tests::owned_scene("cornell-box");
    let size = 32;
    let camera = pose(&scene, size);
    let frame = |r: &mut Renderer, index: u32| {
        r.render_frame(&FrameInput::mono(camera, index, None).with_hdr(true))
            .unwrap();
        let mut hdr = Vec::new();
        r.read_hdr(&mut hdr).unwrap();
        hdr
    };
    let mut a = renderer(&ctx, &scene, size, 9);
    let mut b = renderer(&ctx, &scene, size, 9);
    let (a0, b0) = (frame(&mut a, 0), frame(&mut b, 0));
    assert_pictures_equal(
        "same seed and frame",
        &Picture::hdr(size, size, &b0),
        &Picture::hdr(size, size, &a0),
    );
    let a1 = frame(&mut a, 1);
    let changed = a0.iter().zip(&a1).filter(|(x, y)| x != y).count();
    assert!(
        changed > a0.len() / 2,
        "only {changed} pixels changed between frames"
    );
    let mut c = renderer(&ctx, &scene, size, 10);
    let c0 = frame(&mut c, 0);
    assert!(
        a0.iter().zip(&c0).any(|(x, y)| x != y),
        "a different seed gave the same noise"
    );
    assert_clean(&ctx);
}

#[test]
fn realtime_frames_report_exact_ray_counts_and_finite_output() {
    let ctx = gpu();
    let scene = fovea_tests::owned_scene("stress");
    let size = 48;
    let mut r = renderer(&ctx, &scene, size, 1);
    let stats = r
        .render_frame(&FrameInput::mono(pose(&scene, size), 0, None).with_hdr(true))
        .unwrap();
    assert_eq!(stats.samples_traced, (size * size) as u64);
    assert_eq!(stats.primary_rays, (size * size) as u64);
    // At most one shadow ray per hit vertex (two vertices) and one continuation per sample.
    assert!(stats.shadow_rays > 0 && stats.shadow_rays <= 2 * stats.primary_rays);
    assert!(stats.continuation_rays > 0 && stats.continuation_rays <= stats.primary_rays);
    let mut hdr = Vec::new();
    r.read_hdr(&mut hdr).unwrap();
    assert!(
        hdr.iter()
            .all(|p| p.iter().all(|c| c.is_finite() && *c >= 0.0)),
        "NaN, Inf or negative radiance"
    );
    assert!(r.timings().iter().any(|t| t.name == "trace" && t.ms > 0.0));
    assert_clean(&ctx);
}
