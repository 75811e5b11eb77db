//! The real-time engine: stereo views over one scene upload in one submit, frames in flight on a
//! ring of slots (same images as waiting, no drain in the steady state, deferred release), and
//! how the two eyes' noise relates. Synchronisation validation is on in the ring tests.

use fovea_renderer::frame::{CameraPose, FrameInput, RenderSettings, StereoNoise, ViewInput};
use fovea_renderer::gpu_scene::GpuScene;
use fovea_renderer::passes::denoise::svgf::SvgfSettings;
use fovea_renderer::passes::denoise::DenoiserSettings;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::{Cartesian, SamplingSpace, VisualPolar, VisualPolarParams};
use fovea_renderer::vk::{Context, ContextOptions, EngineCounters};
use fovea_tests::{assert_clean, assert_pictures_equal, gpu, Picture};
use glam::{Mat4, UVec2, Vec2, Vec3};
use std::sync::Arc;

const SCREEN: UVec2 = UVec2::new(64, 72);
/// Half the FOVE 0's eye distance (metres, the glTF unit).
const HALF_IPD: f32 = 0.0315;

fn sync_gpu() -> Arc<Context> {
    Context::new(&ContextOptions {
        validation: true,
        sync_validation: true,
        ..Default::default()
    })
    .expect("Vulkan device with validation layers")
}

fn vp() -> Box<dyn SamplingSpace> {
    Box::new(
        VisualPolar::new(SCREEN, SCREEN.as_vec2() * 0.5, VisualPolarParams::default()).unwrap(),
    )
}

fn svgf() -> RenderSettings {
    RenderSettings {
        denoiser: DenoiserSettings::Svgf(SvgfSettings::default()),
        ..Default::default()
    }
}

fn eye(head: &CameraPose, dx: f32) -> CameraPose {
    CameraPose {
        world_from_view: head.world_from_view * Mat4::from_translation(Vec3::new(dx, 0.0, 0.0)),
        fov_tan: head.fov_tan,
    }
}

fn cornell() -> (fovea_renderer::scene::Scene, CameraPose) {
    let scene = fovea_tests::owned_scene("cornell-box");
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], SCREEN.x, SCREEN.y);
    (scene, camera)
}

fn stereo_input(head: &CameraPose, frame: u32, gazes: [Vec2; 2]) -> FrameInput {
    let views = [
        ViewInput {
            camera: eye(head, -HALF_IPD),
            gaze: Some(gazes[0]),
        },
        ViewInput {
            camera: eye(head, HALF_IPD),
            gaze: Some(gazes[1]),
        },
    ];
    FrameInput::views(&views, frame).unwrap()
}

fn ldr(r: &Renderer, frame: u64, view: usize) -> Vec<u8> {
    let mut out = Vec::new();
    r.read_view_ldr(frame, view, &mut out).unwrap();
    out
}

#[test]
fn stereo_renders_both_eyes_from_one_scene_upload_in_one_submit() {
    let ctx = gpu();
    let (scene, head) = cornell();
    let before = ctx.allocated_bytes();
    let gpu_scene = GpuScene::upload(&ctx, &scene).unwrap();
    let scene_bytes = ctx.allocated_bytes() - before;
    let mono = Renderer::with_views(&ctx, gpu_scene, vec![vp()], svgf(), 2).unwrap();
    let mono_bytes = ctx.allocated_bytes() - before;
    drop(mono);
    let gpu_scene = GpuScene::upload(&ctx, &scene).unwrap();
    let mut stereo = Renderer::with_views(&ctx, gpu_scene, vec![vp(), vp()], svgf(), 2).unwrap();
    let stereo_bytes = ctx.allocated_bytes() - before;
    // One scene: stereo = scene + 2 × (one view's state), not 2 × (scene + view).
    let view_bytes = mono_bytes - scene_bytes;
    assert!(scene_bytes > 0 && view_bytes > 0);
    assert!(
        (stereo_bytes - scene_bytes - 2 * view_bytes).abs() <= view_bytes / 50,
        "stereo {stereo_bytes} B, scene {scene_bytes} B, one view {view_bytes} B"
    );

    let submits = EngineCounters::get(&ctx.counters.submits);
    let centre = SCREEN.as_vec2() * 0.5;
    let frame = stereo
        .submit(&stereo_input(&head, 0, [centre, centre]), None)
        .unwrap();
    assert_eq!(
        EngineCounters::get(&ctx.counters.submits) - submits,
        1,
        "both eyes in one submission"
    );
    stereo.wait_frame(frame).unwrap();
    let (left, right) = (ldr(&stereo, frame, 0), ldr(&stereo, frame, 1));
    assert_ne!(
        left, right,
        "the eyes see the scene from different positions"
    );
    for view in 0..2 {
        let stats = stereo.frame_stats(frame, view).unwrap();
        assert_eq!(
            stats.samples_traced + stats.samples_culled,
            stereo.view(view).space.sample_count()
        );
    }
    // Timings name each eye's passes.
    let traces: Vec<u32> = stereo
        .timings()
        .iter()
        .filter(|t| t.name == "trace")
        .map(|t| t.view)
        .collect();
    assert_eq!(traces, [0, 1]);
    drop(stereo);
    assert_clean(&ctx);
}

#[test]
fn moving_one_eyes_gaze_changes_only_that_eyes_image_and_history() {
    let ctx = gpu();
    let (scene, head) = cornell();
    let centre = SCREEN.as_vec2() * 0.5;
    let moved = Vec2::new(12.0, 14.0);
    let run = |right_gaze_from_frame_2: Vec2| {
        let mut r = Renderer::with_views(
            &ctx,
            GpuScene::upload(&ctx, &scene).unwrap(),
            vec![vp(), vp()],
            svgf(),
            2,
        )
        .unwrap();
        let mut last = 0;
        for f in 0..4 {
            let right = if f >= 2 {
                right_gaze_from_frame_2
            } else {
                centre
            };
            last = r
                .submit(&stereo_input(&head, f, [centre, right]), None)
                .unwrap();
        }
        r.finish().unwrap();
        (ldr(&r, last, 0), ldr(&r, last, 1))
    };
    let (left_a, right_a) = run(centre);
    let (left_b, right_b) = run(moved);
    // Frame 3 carries frame 2's SVGF history: the left eye's image and history are untouched.
    assert_eq!(
        left_a, left_b,
        "the left eye changed when only the right eye's gaze moved"
    );
    assert_ne!(right_a, right_b, "the right eye ignored its gaze");
    assert_clean(&ctx);
}

#[test]
fn a_mono_frame_equals_the_same_view_of_a_stereo_frame() {
    let ctx = gpu();
    let (scene, head) = cornell();
    let gaze = Vec2::new(20.0, 30.0);
    let left = eye(&head, -HALF_IPD);
    let mut mono = Renderer::with_views(
        &ctx,
        GpuScene::upload(&ctx, &scene).unwrap(),
        vec![vp()],
        svgf(),
        2,
    )
    .unwrap();
    let mut stereo = Renderer::with_views(
        &ctx,
        GpuScene::upload(&ctx, &scene).unwrap(),
        vec![vp(), vp()],
        svgf(),
        2,
    )
    .unwrap();
    for f in 0..3 {
        let m = mono
            .submit(&FrameInput::mono(left, f, Some(gaze)), None)
            .unwrap();
        let s = stereo
            .submit(&stereo_input(&head, f, [gaze, gaze]), None)
            .unwrap();
        mono.wait_frame(m).unwrap();
        stereo.wait_frame(s).unwrap();
        assert_eq!(ldr(&mono, m, 0), ldr(&stereo, s, 0), "frame {f}");
    }
    assert_clean(&ctx);
}

/// How the eyes' 1-spp noise relates (docs/guide/view.md, "Stereo noise"): a still Cartesian frame
/// of both eyes, no denoiser. With both eyes at one position the images differ only by noise:
/// shared seeds make them identical, independent ones do not. At the FOVE 0's eye distance the
/// inter-eye difference is printed for both choices beside the converged pair's (parallax alone).
#[test]
fn stereo_noise_independent_vs_shared() {
    let ctx = gpu();
    let (scene, head) = cornell();
    let pair = |noise: StereoNoise, half_ipd: f32, frame: u32| -> (Vec<u8>, Vec<u8>) {
        let settings = RenderSettings {
            stereo_noise: noise,
            ..Default::default()
        };
        let spaces: Vec<Box<dyn SamplingSpace>> = vec![
            Box::new(Cartesian::new(SCREEN)),
            Box::new(Cartesian::new(SCREEN)),
        ];
        let mut r = Renderer::with_views(
            &ctx,
            GpuScene::upload(&ctx, &scene).unwrap(),
            spaces,
            settings,
            1,
        )
        .unwrap();
        let views = [
            ViewInput {
                camera: eye(&head, -half_ipd),
                gaze: None,
            },
            ViewInput {
                camera: eye(&head, half_ipd),
                gaze: None,
            },
        ];
        let f = r
            .submit(&FrameInput::views(&views, frame).unwrap(), None)
            .unwrap();
        r.wait_frame(f).unwrap();
        (ldr(&r, f, 0), ldr(&r, f, 1))
    };
    let (left, right) = pair(StereoNoise::Screen, 0.0, 0);
    assert_pictures_equal(
        "shared seeds at one position give one image (right eye against left)",
        &Picture::rgba8(SCREEN.x, SCREEN.y, &right),
        &Picture::rgba8(SCREEN.x, SCREEN.y, &left),
    );
    let pair = |noise, half_ipd, frame| {
        let (left, right) = pair(noise, half_ipd, frame);
        byte_rmse(&left, &right)
    };
    let independent_same_position = pair(StereoNoise::Independent, 0.0, 0);
    assert!(
        independent_same_position > 5.0,
        "independent noise differs between the eyes: RMSE {independent_same_position}"
    );
    let mean = |noise| (0..4).map(|f| pair(noise, HALF_IPD, f)).sum::<f64>() / 4.0;
    let (independent, shared) = (mean(StereoNoise::Independent), mean(StereoNoise::Screen));
    // The converged pair: the parallax part of the difference.
    let reference = |dx| {
        let mut r = Renderer::new(
            &ctx,
            &scene,
            Box::new(Cartesian::new(SCREEN)),
            RenderSettings::default(),
        )
        .unwrap();
        let hdr = r.render_reference(&eye(&head, dx), 64, 3, |_| {}).unwrap();
        fovea_tools::output::tonemap_preview(
            &hdr,
            1.0,
            fovea_renderer::passes::tonemap::ToneCurve::Aces,
        )
    };
    let parallax = byte_rmse(&reference(-HALF_IPD), &reference(HALF_IPD));
    println!("inter-eye RMSE (8-bit) at 63 mm: independent {independent:.2}, shared {shared:.2}, converged {parallax:.2}; same position: independent {independent_same_position:.2}, shared 0");
    assert!(
        shared < independent,
        "shared seeds correlate the eyes' noise: {shared} vs {independent}"
    );
    assert_clean(&ctx);
}

fn byte_rmse(a: &[u8], b: &[u8]) -> f64 {
    let sum: f64 = a
        .iter()
        .zip(b)
        .enumerate()
        .filter(|(i, _)| i % 4 != 3)
        .map(|(_, (&x, &y))| (x as f64 - y as f64).powi(2))
        .sum();
    (sum / (a.len() as f64 * 0.75)).sqrt()
}

/// Renders `frames` frames, writing each one out when its slot comes round (the loop
/// `fovea render` runs), and returns every frame's pixels.
fn render_ring(ctx: &Arc<Context>, in_flight: usize, frames: u32) -> (Vec<Vec<u8>>, Renderer) {
    let (scene, head) = cornell();
    let mut r = Renderer::with_views(
        ctx,
        GpuScene::upload(ctx, &scene).unwrap(),
        vec![vp()],
        svgf(),
        in_flight,
    )
    .unwrap();
    let mut images = Vec::new();
    for f in 0..frames {
        if let Some(done) = r.retire_next().unwrap() {
            images.push(ldr(&r, done, 0));
        }
        let gaze = Vec2::new(20.0 + 4.0 * f as f32, 30.0);
        r.submit(
            &FrameInput::mono(
                fovea_stage::camera_path::orbit(&head, Vec3::ZERO, f, frames),
                f,
                Some(gaze),
            ),
            None,
        )
        .unwrap();
    }
    r.finish().unwrap();
    for done in frames.saturating_sub(in_flight as u32) as u64..frames as u64 {
        images.push(ldr(&r, done, 0));
    }
    (images, r)
}

#[test]
fn a_ring_of_two_gives_the_images_of_waiting_frame_by_frame_without_draining() {
    let ctx = sync_gpu();
    let (waited, _) = render_ring(&ctx, 1, 6);
    let idle = |c: &Context| {
        EngineCounters::get(&c.counters.queue_idle_waits)
            + EngineCounters::get(&c.counters.device_idle_waits)
    };
    let idle_before = idle(&ctx);
    let (scene, head) = cornell();
    let mut r = Renderer::with_views(
        &ctx,
        GpuScene::upload(&ctx, &scene).unwrap(),
        vec![vp()],
        svgf(),
        2,
    )
    .unwrap();
    let setup_idle = idle(&ctx) - idle_before;
    for f in 0..8 {
        r.retire_next().unwrap();
        r.submit(
            &FrameInput::mono(head, f, Some(Vec2::new(30.0, 30.0))),
            None,
        )
        .unwrap();
    }
    // Steady state: the CPU never waited for the frame it had just submitted, nor for the queue
    // or the device; each frame waited only for the one two frames before it.
    assert_eq!(
        r.ring().drain_waits(),
        0,
        "a frame waited for the newest submission"
    );
    assert_eq!(
        idle(&ctx) - idle_before,
        setup_idle,
        "the loop waited for the queue or the device"
    );
    r.finish().unwrap();
    assert_eq!(r.ring().drain_waits(), 1, "finish drains once");
    drop(r);
    let (ringed, _) = render_ring(&ctx, 2, 6);
    assert_eq!(waited.len(), 6);
    assert_eq!(waited, ringed, "frames in flight changed the images");
    assert_clean(&ctx);
}

#[test]
fn views_replaced_mid_run_are_freed_only_after_their_frames_completed() {
    let ctx = sync_gpu();
    let (scene, head) = cornell();
    let mut r = Renderer::with_views(
        &ctx,
        GpuScene::upload(&ctx, &scene).unwrap(),
        vec![vp()],
        svgf(),
        2,
    )
    .unwrap();
    let input = |f| FrameInput::mono(head, f, None);
    r.submit(&input(0), None).unwrap();
    r.submit(&input(1), None).unwrap();
    let live = ctx.live_allocations();
    // A smaller view without a denoiser, swapped in while frames 0 and 1 may be running.
    r.replace_views(
        vec![Box::new(Cartesian::new(UVec2::new(32, 36)))],
        RenderSettings::default(),
    )
    .unwrap();
    assert_eq!(
        r.ring().deferred_count(),
        1,
        "the old views wait for their frames"
    );
    assert!(
        ctx.live_allocations() > live,
        "the old views were freed at once, under frames in flight"
    );
    r.submit(&input(2), None).unwrap(); // waits for frame 0 only: frame 1 may still use them
    assert_eq!(r.ring().deferred_count(), 1);
    r.submit(&input(3), None).unwrap(); // frame 1 done: the old views go
    assert_eq!(r.ring().deferred_count(), 0);
    assert!(
        ctx.live_allocations() < live,
        "the old views were not freed"
    );
    r.finish().unwrap();
    assert_eq!(ldr(&r, 3, 0).len(), 32 * 36 * 4);
    assert_clean(&ctx);
}
