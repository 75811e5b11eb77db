//! Automatic exposure (renderer/src/passes/exposure.rs): a scene 100× brighter displays as the
//! original once adapted, the adaptation follows its time constant, the meter weighs the gaze's
//! surroundings more, both eyes are displayed with the one exposure metered over both, and a
//! manual exposure is exactly its multiplier.

use fovea_renderer::frame::{CameraPose, FrameInput, RenderSettings, ViewInput};
use fovea_renderer::gpu_scene::GpuScene;
use fovea_renderer::passes::exposure::{metered_exposure, AutoExposure, Exposure};
use fovea_renderer::passes::tonemap::ToneCurve;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::{Cartesian, SamplingSpace};
use fovea_renderer::scene::Scene;
use fovea_renderer::vk::Context;
use fovea_tests::{assert_clean, gpu, light_material};
use glam::{Mat4, UVec2, Vec2};
use std::sync::Arc;

const SCREEN: UVec2 = UVec2::new(64, 72);

fn cornell() -> (Scene, CameraPose) {
    let scene = fovea_tests::owned_scene("cornell-box");
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], SCREEN.x, SCREEN.y);
    (scene, camera)
}

fn renderer(ctx: &Arc<Context>, scene: &Scene, views: usize, exposure: Exposure) -> Renderer {
    let spaces: Vec<Box<dyn SamplingSpace>> = (0..views)
        .map(|_| Box::new(Cartesian::new(SCREEN)) as Box<dyn SamplingSpace>)
        .collect();
    let settings = RenderSettings {
        exposure,
        tone_curve: ToneCurve::Neutral,
        ..Default::default()
    };
    Renderer::with_views(
        ctx,
        GpuScene::upload(ctx, scene).unwrap(),
        spaces,
        settings,
        1,
    )
    .unwrap()
}

/// Renders one frame of `views` and returns its id (waited for).
fn frame(r: &mut Renderer, views: &[ViewInput], index: u32, seconds: f32, hdr: bool) -> u64 {
    let mut input = FrameInput::views(views, index).unwrap().with_hdr(hdr);
    input.frame_seconds = seconds;
    let f = r.submit(&input, None).unwrap();
    r.wait_frame(f).unwrap();
    f
}

fn ldr(r: &Renderer, frame: u64, view: usize) -> Vec<u8> {
    let mut out = Vec::new();
    r.read_view_ldr(frame, view, &mut out).unwrap();
    out
}

fn mean_luma(rgba: &[u8]) -> f64 {
    let sum: f64 = rgba
        .chunks_exact(4)
        .map(|p| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64)
        .sum();
    sum / (rgba.len() / 4) as f64
}

fn mono(camera: CameraPose, gaze: Vec2) -> [ViewInput; 1] {
    [ViewInput {
        camera,
        gaze: Some(gaze),
    }]
}

/// The Cornell box's only light 100× brighter scales every radiance by 100 (the same seeds give
/// the same paths): once metered, the display matches the original within a few percent, and
/// the exposure is a hundredth. Switched mid-run, the exposure moves toward the new target with
/// the brightening time constant (63 % of the way, in stops, after one τ) and arrives.
#[test]
fn a_hundred_times_brighter_scene_displays_alike_after_adaptation() {
    let ctx = gpu();
    let (scene, camera) = cornell();
    let light = light_material(&scene);
    let views = mono(camera, SCREEN.as_vec2() * 0.5);
    let settings = AutoExposure::default();
    let dt = 0.05;

    let mut original = renderer(&ctx, &scene, 1, Exposure::auto());
    let mut bright = renderer(&ctx, &scene, 1, Exposure::auto());
    bright.set_emission_scale(&scene, light, 100.0).unwrap();
    let (mut a, mut b) = (0, 0);
    for i in 0..3 {
        a = frame(&mut original, &views, i, dt, false);
        b = frame(&mut bright, &views, i, dt, false);
    }
    let (ea, eb) = (
        original.frame_exposure(a).unwrap(),
        bright.frame_exposure(b).unwrap(),
    );
    let (la, lb) = (
        mean_luma(&ldr(&original, a, 0)),
        mean_luma(&ldr(&bright, b, 0)),
    );
    println!("exposure {ea} vs {eb} (×100 light); mean luma {la:.2} vs {lb:.2}");
    assert!(
        (40.0..200.0).contains(&la),
        "the Cornell box is exposed to a mid-grey mean: luma {la}"
    );
    assert!(
        (lb / la - 1.0).abs() < 0.03,
        "the ×100 scene displays within 3 %: mean luma {lb} vs {la}"
    );
    assert!(
        ((ea / eb) / 100.0 - 1.0).abs() < 0.05,
        "its exposure is a hundredth: {eb} vs {ea}"
    );

    // The light switched to ×100 in the original's run: from the next frame on (metered on
    // itself) the exposure falls toward a hundredth of the old one, as fast as the time
    // constant allows.
    original.set_emission_scale(&scene, light, 100.0).unwrap();
    let stops_to_go = 100f32.log2();
    let tau_frames = (settings.brighten_seconds / dt).round() as u32;
    let mut exposures = Vec::new();
    for i in 0..(8 * tau_frames) {
        let f = frame(&mut original, &views, 3 + i, dt, false);
        exposures.push(original.frame_exposure(f).unwrap());
    }
    let moved = |e: f32| (ea / e).log2() / stops_to_go;
    assert!(
        // (1 % for the frames' noise, which moves each frame's metered target a little.)
        exposures.windows(2).all(|w| w[1] <= w[0] * 1.01),
        "the exposure only falls while adapting to the brighter scene: {exposures:?}"
    );
    // After tau_frames frames of dt the share moved is 1 − e^(−tau_frames·dt/τ).
    let after_tau = moved(exposures[tau_frames as usize - 1]);
    let expected = 1.0 - (-(tau_frames as f32) * dt / settings.brighten_seconds).exp();
    assert!(
        (after_tau - expected).abs() < 0.08,
        "after one time constant the exposure moved {after_tau:.3} of the way in stops (expected {expected:.3})"
    );
    let last = *exposures.last().unwrap();
    assert!(
        (moved(last) - 1.0).abs() < 0.02,
        "adapted: {last} against the ×100 scene's own {eb}"
    );
    assert_clean(&ctx);
}

/// Looking at the ceiling light lowers the exposure against looking at the dark floor: the
/// meter weighs the gaze's surroundings more.
#[test]
fn the_meter_weighs_the_gaze() {
    let ctx = gpu();
    let (scene, camera) = cornell();
    let exposure_at = |gaze: Vec2| {
        let mut r = renderer(&ctx, &scene, 1, Exposure::auto());
        let f = frame(&mut r, &mono(camera, gaze), 0, 0.05, false);
        r.frame_exposure(f).unwrap()
    };
    // The light is at the top centre of the default view; the box's floor at the bottom.
    let light = exposure_at(Vec2::new(SCREEN.x as f32 * 0.5, SCREEN.y as f32 * 0.12));
    let floor = exposure_at(Vec2::new(SCREEN.x as f32 * 0.5, SCREEN.y as f32 * 0.9));
    println!("exposure with the gaze on the light {light}, on the floor {floor}");
    assert!(
        light < floor * 0.9,
        "gaze on the light: {light}, on the floor: {floor}"
    );
    assert_clean(&ctx);
}

/// The CPU meter (`metered_exposure`, what `fovea quality --display-exposure metered` holds fixed)
/// gives the device's first metered exposure of the same screen radiance, with the gaze weighted
/// and flat, on the Cornell box and on a scene 100× brighter.
#[test]
fn the_cpu_meter_gives_the_devices_first_exposure() {
    let ctx = gpu();
    let (scene, camera) = cornell();
    let light = light_material(&scene);
    let span = camera.fov_tan.y.atan() - camera.fov_tan.x.atan();
    let ppd = SCREEN.x as f32 / span.to_degrees();
    for (boost, brightness) in [(4.0, 1.0), (0.0, 1.0), (4.0, 100.0)] {
        let settings = AutoExposure {
            gaze_boost: boost,
            ..Default::default()
        };
        let mut r = renderer(&ctx, &scene, 1, Exposure::Auto(settings));
        r.set_emission_scale(&scene, light, brightness).unwrap();
        let gaze = Vec2::new(SCREEN.x as f32 * 0.3, SCREEN.y as f32 * 0.2);
        let f = frame(&mut r, &mono(camera, gaze), 0, 0.05, true);
        let device = r.frame_exposure(f).unwrap();
        let mut radiance = Vec::new();
        r.read_view_hdr(f, 0, &mut radiance).unwrap();
        let cpu = metered_exposure(&radiance, SCREEN.x, SCREEN.y, &settings, gaze, ppd);
        println!("gaze boost {boost}, light ×{brightness}: device {device}, CPU {cpu}");
        assert!(
            (device / cpu).log2().abs() < 0.01,
            "gaze boost {boost}, light ×{brightness}: the device metered {device}, the CPU {cpu}"
        );
    }
    assert_clean(&ctx);
}

/// Two eyes, one looking at the ceiling light and one turned down to the floor: both are displayed with
/// the one exposure of the frame (each eye's pixels are its radiance at that exposure), and that
/// exposure lies between what either eye alone would be metered at.
#[test]
fn both_eyes_share_one_exposure_metered_over_both() {
    let ctx = gpu();
    let (scene, camera) = cornell();
    let turned = CameraPose {
        world_from_view: camera.world_from_view * Mat4::from_rotation_x(-0.6),
        fov_tan: camera.fov_tan,
    };
    let (light, floor) = (
        Vec2::new(SCREEN.x as f32 * 0.5, SCREEN.y as f32 * 0.12),
        Vec2::new(SCREEN.x as f32 * 0.5, SCREEN.y as f32 * 0.9),
    );
    let views = [
        ViewInput {
            camera,
            gaze: Some(light),
        },
        ViewInput {
            camera: turned,
            gaze: Some(floor),
        },
    ];
    let mut stereo = renderer(&ctx, &scene, 2, Exposure::auto());
    let f = frame(&mut stereo, &views, 0, 0.05, true);
    let shared = stereo.frame_exposure(f).unwrap();
    let alone = |view: ViewInput| {
        let mut r = renderer(&ctx, &scene, 1, Exposure::auto());
        let f = frame(&mut r, &[view], 0, 0.05, false);
        r.frame_exposure(f).unwrap()
    };
    let (left, right) = (alone(views[0]), alone(views[1]));
    println!("exposure: left alone {left}, right alone {right}, both {shared}");
    assert!(
        left.min(right) < shared && shared < left.max(right),
        "one exposure over both eyes lies between each eye's own: {left}, {right}, {shared}"
    );
    assert!(
        (left / right).log2().abs() > 0.5,
        "the eyes see different brightness (the test's premise): {left} vs {right}"
    );
    for view in 0..2 {
        let mut hdr = Vec::new();
        stereo.read_view_hdr(f, view, &mut hdr).unwrap();
        let expected = fovea_tools::output::tonemap_preview(&hdr, shared, ToneCurve::Neutral);
        let shown = ldr(&stereo, f, view);
        let worst = expected
            .iter()
            .zip(&shown)
            .map(|(&a, &b)| (a as i32 - b as i32).abs())
            .max()
            .unwrap();
        assert!(
            worst <= 1,
            "eye {view} is displayed at the shared exposure {shared} (largest 8-bit difference {worst})"
        );
    }
    assert_clean(&ctx);
}

/// A manual exposure is its multiplier on every frame, whatever the scene shows.
#[test]
fn manual_exposure_is_its_multiplier() {
    let ctx = gpu();
    let (scene, camera) = cornell();
    let mut r = renderer(&ctx, &scene, 1, Exposure::stops(1.0));
    let views = mono(camera, SCREEN.as_vec2() * 0.5);
    for i in 0..2 {
        let f = frame(&mut r, &views, i, 0.05, true);
        assert_eq!(r.frame_exposure(f).unwrap(), 2.0);
        let mut hdr = Vec::new();
        r.read_view_hdr(f, 0, &mut hdr).unwrap();
        let expected = fovea_tools::output::tonemap_preview(&hdr, 2.0, ToneCurve::Neutral);
        let shown = ldr(&r, f, 0);
        assert!(
            expected
                .iter()
                .zip(&shown)
                .all(|(&a, &b)| (a as i32 - b as i32).abs() <= 1),
            "frame {i} is displayed at ×2"
        );
    }
    assert_clean(&ctx);
}
