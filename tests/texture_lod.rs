//! Texture level of detail by ray cones: a fine checkerboard plane seen at a grazing angle. The
//! reference (point-sampled level 0, jittered over each pixel: the box-filtered pixel) is what
//! both modes converge to; with ray cones a 1-spp frame varies far less from frame to frame
//! (no aliasing to average away), and in Visual-Polar space the periphery gains most.

use fovea_renderer::frame::{CameraPose, FrameInput, RenderSettings, TextureLod};
use fovea_renderer::passes::tonemap::ToneCurve;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::{Cartesian, SamplingSpace, VisualPolar, VisualPolarParams};
use fovea_scene::{Camera, Scene, Texture};
use fovea_tests::scenes::{add_quad, lambert};
use fovea_tests::{assert_clean, gpu, rmse, save_preview};
use glam::{UVec2, Vec2, Vec3};
use std::sync::Arc;

const SIZE: UVec2 = UVec2::new(64, 72);
const FRAMES: u32 = 16;

/// A 100 × 100 plane under the camera, emitting a checkerboard of one-texel squares (64 × 64
/// texels, repeated 32 times per side; a square is 5 cm). Emission only (depth 1): every bit of
/// frame-to-frame change is the pixel jitter meeting the texture.
fn checker_plane() -> (Scene, Camera) {
    let size = 64;
    let mut rgba8 = Vec::with_capacity(size * size * 4);
    for y in 0..size {
        for x in 0..size {
            let v = if (x + y) % 2 == 0 { 255 } else { 0 };
            rgba8.extend([v, v, v, 255]);
        }
    }
    let material = fovea_scene::Material {
        emissive: Vec3::ONE,
        emissive_texture: Some(0),
        ..lambert(0.0, 0.0)
    };
    let mut scene = Scene {
        materials: vec![material],
        textures: vec![Texture {
            width: size as u32,
            height: size as u32,
            rgba8,
        }],
        mesh_names: vec!["plane".into()],
        ..Default::default()
    };
    let p = |x: f32, z: f32| Vec3::new(x, 0.0, z);
    add_quad(
        &mut scene,
        [
            p(-50.0, 0.0),
            p(50.0, 0.0),
            p(50.0, -100.0),
            p(-50.0, -100.0),
        ],
        0,
    );
    scene.vertices.iter_mut().for_each(|v| v.uv *= 32.0);
    let camera = Camera::look_at(
        Vec3::new(0.0, 1.0, -1.0),
        Vec3::new(0.0, 0.0, -12.0),
        0.9,
        "grazing",
    );
    (scene, camera)
}

fn settings(lod: TextureLod) -> RenderSettings {
    RenderSettings {
        max_depth: 1,
        tone_curve: ToneCurve::Clamp,
        texture_lod: lod,
        ..Default::default()
    }
}

fn frames(
    ctx: &Arc<fovea_renderer::vk::Context>,
    scene: &Scene,
    camera: &CameraPose,
    space: Box<dyn SamplingSpace>,
    lod: TextureLod,
) -> Vec<Vec<[f32; 4]>> {
    let gaze = space.gaze();
    let mut r = Renderer::new(ctx, scene, space, settings(lod)).unwrap();
    (0..FRAMES)
        .map(|i| {
            r.render_frame(&FrameInput::mono(*camera, i, Some(gaze)).with_hdr(true))
                .unwrap();
            let mut hdr = Vec::new();
            r.read_hdr(&mut hdr).unwrap();
            hdr
        })
        .collect()
}

fn mean(frames: &[Vec<[f32; 4]>]) -> Vec<[f32; 4]> {
    let n = frames.len() as f32;
    (0..frames[0].len())
        .map(|i| std::array::from_fn(|c| frames.iter().map(|f| f[i][c]).sum::<f32>() / n))
        .collect()
}

/// Mean over the pixels `keep` of each pixel's variance across the frames (red channel).
fn temporal_variance(frames: &[Vec<[f32; 4]>], keep: impl Fn(usize) -> bool) -> f64 {
    let avg = mean(frames);
    let (mut sum, mut count) = (0.0, 0usize);
    for (i, m) in avg.iter().enumerate().filter(|(i, _)| keep(*i)) {
        sum += frames
            .iter()
            .map(|f| (f[i][0] as f64 - m[0] as f64).powi(2))
            .sum::<f64>()
            / (frames.len() - 1) as f64;
        count += 1;
    }
    sum / count.max(1) as f64
}

#[test]
fn ray_cones_converge_to_the_box_filtered_pixel_with_less_one_spp_variance() {
    let ctx = gpu();
    let (scene, camera) = checker_plane();
    let pose = CameraPose::from_scene_camera(&camera, SIZE.x, SIZE.y);
    let mut r = Renderer::new(
        &ctx,
        &scene,
        Box::new(Cartesian::new(SIZE)),
        settings(TextureLod::RayCones),
    )
    .unwrap();
    let reference = r.render_reference(&pose, 256, 1, |_| {}).unwrap();
    drop(r);
    let point = frames(
        &ctx,
        &scene,
        &pose,
        Box::new(Cartesian::new(SIZE)),
        TextureLod::Off,
    );
    let cones = frames(
        &ctx,
        &scene,
        &pose,
        Box::new(Cartesian::new(SIZE)),
        TextureLod::RayCones,
    );
    save_preview("texture_lod_reference.png", SIZE.x, SIZE.y, &reference);
    save_preview("texture_lod_point_1spp.png", SIZE.x, SIZE.y, &point[0]);
    save_preview("texture_lod_cones_1spp.png", SIZE.x, SIZE.y, &cones[0]);
    let (var_point, var_cones) = (
        temporal_variance(&point, |_| true),
        temporal_variance(&cones, |_| true),
    );
    let (bias_point, bias_cones) = (
        rmse(&mean(&point), &reference),
        rmse(&mean(&cones), &reference),
    );
    let (frame_point, frame_cones) = (rmse(&point[0], &reference), rmse(&cones[0], &reference));
    eprintln!("variance point {var_point:.5} cones {var_cones:.5}; {FRAMES}-frame mean vs reference point {bias_point:.4} cones {bias_cones:.4}; one frame point {frame_point:.4} cones {frame_cones:.4}");
    assert!(
        var_cones < var_point / 4.0,
        "1-spp variance with ray cones {var_cones} vs point sampling {var_point}"
    );
    // Converges to the box-filtered pixel: the cone's mean is as close to the reference as
    // point sampling's 16-frame mean (which is unbiased), and one cone frame is much closer than
    // one point-sampled frame.
    assert!(
        bias_cones < 1.5 * bias_point.max(0.02),
        "16-frame mean vs reference: cones {bias_cones}, point {bias_point}"
    );
    assert!(
        frame_cones < frame_point / 2.0,
        "one frame vs reference: cones {frame_cones}, point {frame_point}"
    );
    assert_clean(&ctx);
}

#[test]
fn visual_polar_periphery_samples_read_coarser_levels() {
    let ctx = gpu();
    let (scene, camera) = checker_plane();
    let pose = CameraPose::from_scene_camera(&camera, SIZE.x, SIZE.y);
    let vp = || -> Box<dyn SamplingSpace> {
        Box::new(
            VisualPolar::new(SIZE, SIZE.as_vec2() * 0.5, VisualPolarParams::default()).unwrap(),
        )
    };
    let point = frames(&ctx, &scene, &pose, vp(), TextureLod::Off);
    let cones = frames(&ctx, &scene, &pose, vp(), TextureLod::RayCones);
    // The outer ring (beyond 60 % of the half-diagonal from the gaze): sparse samples, each
    // standing for many pixels, alias most without a footprint.
    let centre = SIZE.as_vec2() * 0.5;
    let outer = |i: usize| {
        let p = Vec2::new(
            (i as u32 % SIZE.x) as f32 + 0.5,
            (i as u32 / SIZE.x) as f32 + 0.5,
        );
        (p - centre).length() > 0.6 * centre.length()
    };
    let (var_point, var_cones) = (
        temporal_variance(&point, outer),
        temporal_variance(&cones, outer),
    );
    eprintln!("VP periphery variance point {var_point:.5} cones {var_cones:.5}");
    assert!(
        var_cones < var_point / 3.0,
        "VP periphery 1-spp variance with ray cones {var_cones} vs point sampling {var_point}"
    );
    assert_clean(&ctx);
}
