//! The `uniform-budget` comparator: Visual-Polar's sample count on a regular grid, bilinearly
//! upscaled. It traces the budget it claims, converges to the same image as one sample per pixel,
//! refuses the filters its grid cannot run, and `fovea render --method uniform-budget` reports it.

use fovea_renderer::frame::{CameraPose, FrameInput, RenderSettings};
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::{
    Cartesian, SamplingSpace, UniformBudget, VisualPolar, VisualPolarParams,
};
use fovea_tests::{assert_clean, gpu, owned_scene};
use glam::UVec2;

const SCREEN: UVec2 = UVec2::new(64, 72);

/// Mean linear colour over `frames` frames; the upscaled image must be screen-sized.
fn mean_over_frames(renderer: &mut Renderer, camera: CameraPose, frames: u32) -> [f64; 3] {
    fovea_tests::mean_over_frames(renderer, camera, None, frames, |_, hdr| {
        assert_eq!(
            hdr.len(),
            (SCREEN.x * SCREEN.y) as usize,
            "the upscaled image is screen-sized"
        );
    })
}

#[test]
fn uniform_budget_traces_vp_s_count_and_converges_like_one_sample_per_pixel() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let camera = CameraPose::from_scene_camera(scene.default_camera().unwrap(), SCREEN.x, SCREEN.y);
    let vp =
        VisualPolar::new(SCREEN, SCREEN.as_vec2() * 0.5, VisualPolarParams::default()).unwrap();
    let budget = UniformBudget::with_samples(SCREEN, vp.sample_count()).unwrap();
    assert!(
        (budget.sample_count() as f64 / vp.sample_count() as f64 - 1.0).abs() < 0.03,
        "{} vs {}",
        budget.sample_count(),
        vp.sample_count()
    );
    assert!(budget.grid.x < SCREEN.x && budget.grid.y < SCREEN.y);

    let mut uniform =
        Renderer::new(&ctx, &scene, Box::new(budget), RenderSettings::default()).unwrap();
    let stats = uniform
        .render_frame(&FrameInput::mono(camera, 0, None))
        .unwrap();
    assert_eq!(
        stats.samples_traced,
        budget.sample_count(),
        "every texel traced once"
    );
    let a = mean_over_frames(&mut uniform, camera, 16);
    let mut cartesian = Renderer::new(
        &ctx,
        &scene,
        Box::new(Cartesian::new(SCREEN)),
        RenderSettings::default(),
    )
    .unwrap();
    let b = mean_over_frames(&mut cartesian, camera, 16);
    for c in 0..3 {
        assert!(
            (a[c] / b[c] - 1.0).abs() < 0.08,
            "channel {c}: uniform budget {} vs one per pixel {}",
            a[c],
            b[c]
        );
    }
    assert_clean(&ctx);
}

#[test]
fn uniform_budget_refuses_the_denoisers_and_the_cli_reports_it() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let budget = UniformBudget::with_samples(SCREEN, 2000).unwrap();
    fovea_tests::assert_refuses_svgf(&ctx, &scene, Box::new(budget));
    assert_clean(&ctx);

    let report = fovea_tests::render_report("uniform-budget", Default::default());
    assert_eq!(report["method"], "uniform-budget");
    assert!(
        report["passes"]["upscale"].as_f64().is_some(),
        "{}",
        report["passes"]
    );
    let (grid, screen) = (
        report["vp_width"].as_u64().unwrap() * report["vp_height"].as_u64().unwrap(),
        64 * 72,
    );
    assert!(
        grid < screen && report["samples_traced"].as_u64().unwrap() == grid,
        "{report}"
    );
}
