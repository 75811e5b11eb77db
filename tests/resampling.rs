//! ReSTIR DI and GI (`--resampling di`, `di+gi`; docs/design/resampling.md) against answers
//! known in advance: the environment furnace, a 64-light scene's converged reference, the
//! furnace's geometric series and the Cornell box's converged reference (the mean of many
//! real-time frames of a still camera), a lower error than next-event estimation alone at one
//! sample per texel around the gaze (Cartesian and Visual-Polar), references that resampling
//! leaves untouched, and each eye's reservoirs its own. The conformance suite
//! (`tests/conformance.rs`) runs it on every space that supports it and checks the refusals.

use fovea_renderer::frame::{CameraPose, FrameInput, RenderSettings, ViewInput};
use fovea_renderer::passes::denoise::DenoiserSettings;
use fovea_renderer::passes::resampling::{ResamplingMode, ResamplingSettings};
use fovea_renderer::passes::tonemap::ToneCurve;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::{Cartesian, SamplingSpace, VisualPolar, VisualPolarParams};
use fovea_renderer::vk::Context;
use fovea_scene::{Camera, Material, Scene, Sky};
use fovea_tests::scenes::{add_floor, add_quad, furnace, lambert, white_sphere};
use fovea_tests::{assert_clean, gpu, mean_over_frames, mean_rgb, owned_scene, rmse};
use glam::{UVec2, Vec2, Vec3};
use std::sync::Arc;

const SIZE: UVec2 = UVec2::new(64, 72);

fn settings(mode: ResamplingMode) -> RenderSettings {
    RenderSettings {
        tone_curve: ToneCurve::Clamp,
        resampling: ResamplingSettings::default().with_mode(mode),
        ..Default::default()
    }
}

fn renderer(
    ctx: &Arc<Context>,
    scene: &Scene,
    space: Box<dyn SamplingSpace>,
    mode: ResamplingMode,
) -> Renderer {
    Renderer::new(ctx, scene, space, settings(mode)).unwrap()
}

/// A renderer resampling with `brdf_candidates` BRDF candidates (the default's other parameters).
fn renderer_with_brdf(
    ctx: &Arc<Context>,
    scene: &Scene,
    space: Box<dyn SamplingSpace>,
    (mode, brdf_candidates): (ResamplingMode, u32),
) -> Renderer {
    let mut s = settings(mode);
    s.resampling.brdf_candidates = brdf_candidates;
    Renderer::new(ctx, scene, space, s).unwrap()
}

/// The cases a convergence test runs: each mode, and with resampling both without BRDF
/// candidates (the environment's BRDF share left to the path) and with the default's.
const MODES_AND_BRDF: [(ResamplingMode, u32); 5] = [
    (ResamplingMode::Off, 0),
    (ResamplingMode::Di, 0),
    (ResamplingMode::Di, 1),
    (ResamplingMode::DiGi, 0),
    (ResamplingMode::DiGi, 1),
];

fn case_name((mode, brdf_candidates): (ResamplingMode, u32)) -> String {
    match mode {
        ResamplingMode::Off => mode.name().to_string(),
        _ => format!("{} ({brdf_candidates} BRDF candidates)", mode.name()),
    }
}

fn cornell() -> (Scene, CameraPose) {
    let scene = owned_scene("cornell-box");
    let pose = CameraPose::from_scene_camera(&scene.cameras[0], SIZE.x, SIZE.y);
    (scene, pose)
}

/// The mean of `frames` real-time frames per pixel, still camera, gaze at the centre.
fn mean_image(r: &mut Renderer, pose: CameraPose, frames: u32) -> Vec<[f32; 4]> {
    let mut mean = vec![[0.0f32; 4]; (SIZE.x * SIZE.y) as usize];
    let mut hdr = Vec::new();
    for f in 0..frames {
        r.render_frame(&FrameInput::mono(pose, f, Some(SIZE.as_vec2() * 0.5)).with_hdr(true))
            .unwrap();
        r.read_hdr(&mut hdr).unwrap();
        for (m, p) in mean.iter_mut().zip(&hdr) {
            (0..4).for_each(|c| m[c] += p[c] / frames as f32);
        }
    }
    mean
}

/// In a closed box whose walls all emit 1 and reflect ½, every direction sees 1 + ½ + ¼ with the
/// real-time path (emission, direct light, one bounce's direct light): the mean of the frames
/// with resampling must be that, as next-event estimation's is. Every light point lies on a wall,
/// so a neighbour's sample off the shading point's own wall re-evaluates there with the same
/// support: the 1/M normalisation is unbiased here.
#[test]
fn furnace_converges_with_resampling() {
    let ctx = gpu();
    let scene = furnace(0.5, 1.0);
    // Large enough that the neighbours' disc covers a small part of the view: the reservoirs of
    // a tiny view share a handful of samples, and its mean over frames wanders.
    let size = 64;
    let pose = CameraPose::from_scene_camera(&scene.cameras[0], size, size);
    let expected = 1.75;
    for mode in [
        ResamplingMode::Off,
        ResamplingMode::Di,
        ResamplingMode::DiGi,
    ] {
        let space = Box::new(Cartesian::new(UVec2::splat(size)));
        let mut r = renderer(&ctx, &scene, space, mode);
        let mean = mean_over_frames(&mut r, pose, None, 64, |_, _| {});
        println!(
            "furnace, resampling {}: mean {mean:?} vs {expected}",
            mode.name()
        );
        for c in mean {
            assert!(
                (c - expected).abs() < 0.01 * expected,
                "resampling {}: mean {c} vs analytic {expected}",
                mode.name()
            );
        }
    }
    assert_clean(&ctx);
}

/// A white Lambertian sphere in a uniform environment of radiance L is L everywhere: every bounce
/// escapes, so ReSTIR GI's samples are all the environment's (weighed against next-event
/// estimation at the point that uses them) and DI's light samples all environment directions.
/// The mean of 64 real-time frames over the middle of the sphere must be L with each mode.
#[test]
fn environment_furnace_converges_with_resampling() {
    let ctx = gpu();
    let l = 0.7f32;
    let mut scene = white_sphere();
    scene.sky = Sky::uniform(Vec3::splat(l));
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 3.5), Vec3::ZERO, 0.7, "test");
    let pose = CameraPose::from_scene_camera(&camera, SIZE.x, SIZE.y);
    // The sphere's image is a disc about 29 pixels in radius around the centre.
    let centre = SIZE.as_vec2() * 0.5;
    let inside: Vec<usize> = (0..SIZE.x * SIZE.y)
        .filter(|i| {
            let p = Vec2::new((i % SIZE.x) as f32 + 0.5, (i / SIZE.x) as f32 + 0.5);
            p.distance(centre) < 20.0
        })
        .map(|i| i as usize)
        .collect();
    for case in MODES_AND_BRDF {
        let mut r = renderer_with_brdf(&ctx, &scene, Box::new(Cartesian::new(SIZE)), case);
        let image = mean_image(&mut r, pose, 64);
        let mean = mean_rgb(&inside.iter().map(|&i| image[i]).collect::<Vec<_>>());
        let name = case_name(case);
        println!("environment furnace, resampling {name}: mean {mean:?} vs {l}");
        for c in mean {
            assert!(
                (c / l as f64 - 1.0).abs() < 0.01,
                "resampling {name}: mean {c} vs L {l}"
            );
        }
    }
    assert_clean(&ctx);
}

/// Per-channel relative difference of the image means, and the largest of the 4×4 blocks'
/// relative luminance differences (blocks darker than 2 % of the mean left out).
fn mean_differences(image: &[[f32; 4]], reference: &[[f32; 4]]) -> ([f64; 3], f64) {
    let (a, b) = (mean_rgb(image), mean_rgb(reference));
    let whole = [0, 1, 2].map(|c| a[c] / b[c] - 1.0);
    let luma = |m: [f64; 3]| 0.2126 * m[0] + 0.7152 * m[1] + 0.0722 * m[2];
    let overall = luma(b);
    let (bw, bh) = (SIZE.x / 4, SIZE.y / 4);
    let mut worst = 0.0f64;
    for by in 0..4 {
        for bx in 0..4 {
            let block = |img: &[[f32; 4]]| -> Vec<[f32; 4]> {
                (0..bh)
                    .flat_map(|y| (0..bw).map(move |x| (x, y)))
                    .map(|(x, y)| img[((by * bh + y) * SIZE.x + bx * bw + x) as usize])
                    .collect()
            };
            let (la, lb) = (
                luma(mean_rgb(&block(image))),
                luma(mean_rgb(&block(reference))),
            );
            if lb > 0.02 * overall {
                worst = worst.max((la / lb - 1.0).abs());
            }
        }
    }
    (whole, worst)
}

/// The mean of 256 still frames against a 512-spp reference, next-event estimation alone and with
/// resampling (the unbiased 1/Z normalisation): the whole image and every 4×4 block of it. The
/// reservoirs carry samples over many frames and texels, so the mean of resampled frames
/// converges more slowly than independent frames' where the light is hardest to find (the
/// penumbra beside the tall box: its block is the worst, a few per cent after 256 frames); the
/// figures are printed (docs/design/resampling.md records them).
#[test]
fn cornell_box_converges_to_the_reference() {
    let ctx = gpu();
    let (scene, pose) = cornell();
    let label = format!("Cornell box {}×{}", SIZE.x, SIZE.y);
    assert_converges(
        &ctx,
        (&scene, pose, &label),
        256,
        &[
            ((ResamplingMode::Off, 0), 0.01, 0.03),
            ((ResamplingMode::Di, 1), 0.01, 0.06),
            ((ResamplingMode::DiGi, 1), 0.01, 0.06),
        ],
    );
    assert_clean(&ctx);
}

/// The mean of `frames` still frames with each case (mode, BRDF candidates) against a 512-spp
/// reference, printed: the whole image's per-channel difference under its case's first bound,
/// every 4×4 block's under the second.
fn assert_converges(
    ctx: &Arc<Context>,
    (scene, pose, label): (&Scene, CameraPose, &str),
    frames: u32,
    cases: &[((ResamplingMode, u32), f64, f64)],
) {
    let reference = renderer(
        ctx,
        scene,
        Box::new(Cartesian::new(SIZE)),
        ResamplingMode::Off,
    )
    .render_reference(&pose, 512, 3, |_| {})
    .unwrap();
    for &(case, whole_bound, block_bound) in cases {
        let mut r = renderer_with_brdf(ctx, scene, Box::new(Cartesian::new(SIZE)), case);
        let mean = mean_image(&mut r, pose, frames);
        let (whole, worst) = mean_differences(&mean, &reference);
        let name = case_name(case);
        println!(
            "{label}, resampling {name}: mean of {frames} frames vs 512 spp: {:+.4} {:+.4} {:+.4} per channel, worst 4×4 block {:.4}",
            whole[0], whole[1], whole[2], worst
        );
        assert!(
            whole.iter().all(|d| d.abs() < whole_bound),
            "{label}, resampling {name}: mean off by {whole:?} (bound {whole_bound})"
        );
        assert!(
            worst < block_bound,
            "{label}, resampling {name}: a 4×4 block's mean off by {worst:.4} (bound {block_bound})"
        );
    }
}

/// A floor lit by 64 small area lights of four strengths, a wall casting their shadows: the light
/// table's many entries are what light resampling chooses between. The mean of 128 still frames
/// against a 512-spp reference, with each mode, as the Cornell box's.
#[test]
fn many_lights_converge_to_the_reference() {
    let ctx = gpu();
    let mut scene = Scene {
        materials: vec![lambert(0.6, 0.0)],
        mesh_names: vec!["room".into()],
        ..Default::default()
    };
    let strengths = [2.0, 5.0, 9.0, 14.0];
    // Emitting downward only: the camera above sees their dark backs, the image is the light
    // they cast.
    scene.materials.extend(strengths.map(|e| lambert(0.0, e)));
    add_floor(&mut scene, 1.5, 0);
    // A wall across the middle: half the lights reach each side of it only past its edge.
    add_quad(
        &mut scene,
        [
            Vec3::new(0.0, 0.0, -0.8),
            Vec3::new(0.0, 0.7, -0.8),
            Vec3::new(0.0, 0.7, 0.8),
            Vec3::new(0.0, 0.0, 0.8),
        ],
        0,
    );
    let a = 0.04;
    for i in 0..64u32 {
        let (x, z) = (-1.05 + 0.3 * (i % 8) as f32, -1.05 + 0.3 * (i / 8) as f32);
        let h = 0.9 + 0.1 * (i % 3) as f32;
        add_quad(
            &mut scene,
            [
                Vec3::new(x - a, h, z - a),
                Vec3::new(x + a, h, z - a),
                Vec3::new(x + a, h, z + a),
                Vec3::new(x - a, h, z + a),
            ],
            1 + (i * 7 % 4),
        );
    }
    let camera = Camera::look_at(
        Vec3::new(0.4, 2.0, 2.4),
        Vec3::new(0.0, 0.2, 0.0),
        0.9,
        "test",
    );
    let pose = CameraPose::from_scene_camera(&camera, SIZE.x, SIZE.y);
    assert_converges(
        &ctx,
        (&scene, pose, "64 lights"),
        128,
        &MODES_AND_BRDF.map(|case| (case, 0.01, 0.06)),
    );
    assert_clean(&ctx);
}

/// A glossy metal floor (roughness 0.3) under one large area light and a uniform sky, seen at
/// a grazing angle so that the light's reflection fills much of the view: light sampling draws
/// points all over the light, few of which the narrow lobe reflects; BRDF candidates find them
/// through the lobe (the sky's BRDF share stays the path's). The mean of 128 still frames
/// converges to the 512-spp reference with and without them, and at one sample per texel
/// (frames 4–11, no denoiser) the error with them is lower.
#[test]
fn brdf_candidates_converge_and_lower_the_error_on_glossy_surfaces() {
    let ctx = gpu();
    let mut scene = Scene {
        materials: vec![
            Material {
                base_color: glam::Vec4::new(0.9, 0.9, 0.9, 1.0),
                metallic: 1.0,
                roughness: 0.3,
                ..Default::default()
            },
            lambert(0.0, 4.0),
        ],
        mesh_names: vec!["room".into()],
        sky: Sky::uniform(Vec3::splat(0.3)),
        ..Default::default()
    };
    add_floor(&mut scene, 2.0, 0);
    // Emitting downward.
    let (a, h) = (0.6, 1.0);
    add_quad(
        &mut scene,
        [
            Vec3::new(-a, h, -1.2 - a),
            Vec3::new(a, h, -1.2 - a),
            Vec3::new(a, h, -1.2 + a),
            Vec3::new(-a, h, -1.2 + a),
        ],
        1,
    );
    let camera = Camera::look_at(
        Vec3::new(0.0, 0.6, 1.8),
        Vec3::new(0.0, 0.0, -0.6),
        0.9,
        "test",
    );
    let pose = CameraPose::from_scene_camera(&camera, SIZE.x, SIZE.y);
    assert_converges(
        &ctx,
        (&scene, pose, "glossy floor"),
        128,
        &[
            ((ResamplingMode::Di, 0), 0.01, 0.06),
            ((ResamplingMode::Di, 1), 0.01, 0.06),
            ((ResamplingMode::DiGi, 1), 0.01, 0.06),
        ],
    );
    let reference = renderer(
        &ctx,
        &scene,
        Box::new(Cartesian::new(SIZE)),
        ResamplingMode::Off,
    )
    .render_reference(&pose, 512, 3, |_| {})
    .unwrap();
    let centre = SIZE.as_vec2() * 0.5;
    let mut errors = Vec::new();
    for brdf_candidates in [0, 1] {
        let case = (ResamplingMode::Di, brdf_candidates);
        let mut r = renderer_with_brdf(&ctx, &scene, Box::new(Cartesian::new(SIZE)), case);
        let (rmse_sum, flip_sum) =
            error_over_frames(&mut r, pose, &reference, (centre, SIZE.x as f32));
        println!(
            "glossy floor, resampling {}: RMSE {rmse_sum:.4}, FLIP {flip_sum:.4} over the view (frames 4–11)",
            case_name(case)
        );
        errors.push((rmse_sum, flip_sum));
    }
    assert!(
        errors[1].0 < errors[0].0 && errors[1].1 < errors[0].1,
        "BRDF candidates: RMSE {:.4} / FLIP {:.4} vs without {:.4} / {:.4}",
        errors[1].0,
        errors[1].1,
        errors[0].0,
        errors[0].1
    );
    assert_clean(&ctx);
}

/// `error_around` (within `radius` pixels of `gaze`) of frames 4–11 of a still camera looking
/// at `gaze`, averaged: the reservoirs have gathered a few frames' candidates by then.
fn error_over_frames(
    r: &mut Renderer,
    pose: CameraPose,
    reference: &[[f32; 4]],
    (gaze, radius): (Vec2, f32),
) -> (f64, f64) {
    let (mut rmse_sum, mut flip_sum) = (0.0, 0.0);
    let mut hdr = Vec::new();
    let measured = 4..12;
    for f in 0..measured.end {
        r.render_frame(&FrameInput::mono(pose, f, Some(gaze)).with_hdr(true))
            .unwrap();
        if measured.contains(&f) {
            r.read_hdr(&mut hdr).unwrap();
            let (e, flip) = error_around(&hdr, reference, gaze, radius);
            rmse_sum += e / measured.len() as f64;
            flip_sum += flip / measured.len() as f64;
        }
    }
    (rmse_sum, flip_sum)
}

/// RMSE and mean FLIP of one frame against the reference over the screen pixels within `radius`
/// pixels of the gaze (the fovea, where Visual-Polar does not blur).
fn error_around(frame: &[[f32; 4]], reference: &[[f32; 4]], gaze: Vec2, radius: f32) -> (f64, f64) {
    let keep: Vec<bool> = (0..SIZE.x * SIZE.y)
        .map(|i| {
            let p = Vec2::new((i % SIZE.x) as f32 + 0.5, (i / SIZE.x) as f32 + 0.5);
            p.distance(gaze) <= radius
        })
        .collect();
    let pick = |img: &[[f32; 4]]| -> Vec<[f32; 4]> {
        img.iter()
            .zip(&keep)
            .filter(|(_, k)| **k)
            .map(|(p, _)| *p)
            .collect()
    };
    let (a, b) = (pick(frame), pick(reference));
    let ldr = |img: &[[f32; 4]]| fovea_tools::output::tonemap_preview(img, 1.0, ToneCurve::Aces);
    let flip =
        fovea_tools::eval::flip::flip_map(&ldr(reference), &ldr(frame), SIZE.x, SIZE.y, 20.0);
    let mean_flip = flip
        .iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(f, _)| f)
        .sum::<f64>()
        / a.len() as f64;
    (rmse(&a, &b), mean_flip)
}

/// One sample per texel, no denoiser, a still camera: after a few frames the reservoirs have
/// gathered the previous frames' and the neighbours' candidates, and the error around the gaze
/// against the converged image (frames 4–11, each measured, averaged) falls below next-event
/// estimation's, in Cartesian and in Visual-Polar space: for the direct light alone (max depth
/// 2, the light it resamples) to under half, and with the real-time path's bounce (depth 3,
/// whose indirect light `di` leaves as it is) clearly, and with `di+gi` again below `di`.
#[test]
fn resampling_lowers_the_error_at_one_sample() {
    const GI_RMSE_BOUND: f64 = 0.8;
    let ctx = gpu();
    let (scene, pose) = cornell();
    // Off the centre, on the back wall and the tall box.
    let gaze = SIZE.as_vec2() * Vec2::new(0.4, 0.55);
    let radius = SIZE.x as f32 / 5.0;
    type MakeSpace = fn(Vec2) -> Box<dyn SamplingSpace>;
    let spaces: [(&str, MakeSpace); 2] = [
        ("cartesian", |_| Box::new(Cartesian::new(SIZE))),
        ("vp", |gaze| {
            Box::new(VisualPolar::new(SIZE, gaze, VisualPolarParams::default()).unwrap())
        }),
    ];
    for (max_depth, rmse_bound) in [(2, 0.5), (3, 0.9)] {
        let reference = renderer(
            &ctx,
            &scene,
            Box::new(Cartesian::new(SIZE)),
            ResamplingMode::Off,
        )
        .render_reference(&pose, 512, max_depth, |_| {})
        .unwrap();
        for (name, make) in spaces {
            let mut errors = Vec::new();
            let modes: &[ResamplingMode] = match max_depth {
                2 => &[ResamplingMode::Off, ResamplingMode::Di],
                _ => &[
                    ResamplingMode::Off,
                    ResamplingMode::Di,
                    ResamplingMode::DiGi,
                ],
            };
            for &mode in modes {
                let settings = RenderSettings {
                    max_depth,
                    ..settings(mode)
                };
                let mut r = Renderer::new(&ctx, &scene, make(gaze), settings).unwrap();
                let (rmse_sum, flip_sum) =
                    error_over_frames(&mut r, pose, &reference, (gaze, radius));
                println!(
                    "{name}, max depth {max_depth}, resampling {}: RMSE {rmse_sum:.4}, FLIP {flip_sum:.4} within {radius} px of the gaze (frames 4–11)",
                    mode.name()
                );
                errors.push((rmse_sum, flip_sum));
            }
            let (off, di) = (errors[0], errors[1]);
            assert!(
                di.0 < rmse_bound * off.0 && di.1 < off.1,
                "{name}, max depth {max_depth}: resampling di RMSE {:.4} / FLIP {:.4} vs off {:.4} / {:.4}",
                di.0,
                di.1,
                off.0,
                off.1
            );
            // The bounce resampled too: the rest of the real-time path's noise falls.
            if let Some(gi) = errors.get(2) {
                assert!(
                    gi.0 < GI_RMSE_BOUND * di.0 && gi.1 < di.1,
                    "{name}, max depth {max_depth}: resampling di+gi RMSE {:.4} / FLIP {:.4} vs di {:.4} / {:.4}",
                    gi.0,
                    gi.1,
                    di.0,
                    di.1
                );
            }
        }
    }
    assert_clean(&ctx);
}

/// A light switched off (`Renderer::set_emission_scale`) leaves no light behind with resampling:
/// the reservoirs' history (DI's light-table entries, GI's radiance gathered at secondary hits)
/// is dropped when the light table is rebuilt, so the very next frame of the Cornell box, whose
/// only light it is, is black; switched on again, the next frame is lit as the first frame was.
#[test]
fn a_light_switched_off_leaves_no_light_behind() {
    let ctx = gpu();
    let (scene, pose) = cornell();
    let light = fovea_tests::light_material(&scene);
    for mode in [ResamplingMode::Di, ResamplingMode::DiGi] {
        let mut r = renderer(&ctx, &scene, Box::new(Cartesian::new(SIZE)), mode);
        let mut hdr = Vec::new();
        let mut render = |r: &mut Renderer, f: u32| {
            r.render_frame(&FrameInput::mono(pose, f, Some(SIZE.as_vec2() * 0.5)).with_hdr(true))
                .unwrap();
            r.read_hdr(&mut hdr).unwrap();
            mean_rgb(&hdr)
        };
        let lit: Vec<[f64; 3]> = (0..6).map(|f| render(&mut r, f)).collect();
        r.set_emission_scale(&scene, light, 0.0).unwrap();
        let off = render(&mut r, 6);
        assert_eq!(
            off,
            [0.0; 3],
            "resampling {}: light left behind after switching off",
            mode.name()
        );
        r.set_emission_scale(&scene, light, 1.0).unwrap();
        let on = render(&mut r, 7);
        let ratio = on[1] / lit[0][1];
        println!(
            "resampling {}: first frame {:.4}, after switching off {:?}, back on {:.4} ({ratio:.3}×)",
            mode.name(),
            lit[0][1],
            off,
            on[1]
        );
        assert!(
            (ratio - 1.0).abs() < 0.05,
            "resampling {}: back on, the frame's mean is {ratio}× the first frame's",
            mode.name()
        );
    }
    assert_clean(&ctx);
}

/// References trace every sample with next-event estimation at every hit: the resampling
/// setting changes none of their bytes.
#[test]
fn references_ignore_resampling() {
    let ctx = gpu();
    let (scene, pose) = cornell();
    let images: Vec<Vec<[f32; 4]>> = [
        ResamplingMode::Off,
        ResamplingMode::Di,
        ResamplingMode::DiGi,
    ]
    .into_iter()
    .map(|mode| {
        renderer(&ctx, &scene, Box::new(Cartesian::new(SIZE)), mode)
            .render_reference(&pose, 4, 3, |_| {})
            .unwrap()
    })
    .collect();
    assert!(
        images[0] == images[1] && images[0] == images[2],
        "a reference changed with resampling"
    );
    assert_clean(&ctx);
}

/// Each eye keeps its own reservoirs (DI's and GI's): the left eye of a stereo renderer draws exactly the frames
/// of a mono renderer (its seed is the mono one's), whatever the right eye sees, also with a
/// denoiser after the resampling.
#[test]
fn each_eye_resamples_on_its_own() {
    let ctx = gpu();
    let (scene, pose) = cornell();
    let settings = RenderSettings {
        denoiser: DenoiserSettings::parse("svgf").unwrap(),
        ..settings(ResamplingMode::DiGi)
    };
    let vp = |gaze: Vec2| -> Box<dyn SamplingSpace> {
        Box::new(VisualPolar::new(SIZE, gaze, VisualPolarParams::default()).unwrap())
    };
    let (left_gaze, right_gaze) = (SIZE.as_vec2() * 0.5, SIZE.as_vec2() * Vec2::new(0.3, 0.6));
    let scene_gpu = || fovea_renderer::gpu_scene::GpuScene::upload(&ctx, &scene).unwrap();
    let mut mono =
        Renderer::with_views(&ctx, scene_gpu(), vec![vp(left_gaze)], settings, 1).unwrap();
    let mut stereo = Renderer::with_views(
        &ctx,
        scene_gpu(),
        vec![vp(left_gaze), vp(right_gaze)],
        settings,
        1,
    )
    .unwrap();
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for f in 0..4 {
        let left = ViewInput {
            camera: pose,
            gaze: Some(left_gaze),
        };
        let right = ViewInput {
            camera: pose,
            gaze: Some(right_gaze),
        };
        mono.render_frame(&FrameInput::views(&[left], f).unwrap())
            .unwrap();
        let frame = stereo
            .submit(&FrameInput::views(&[left, right], f).unwrap(), None)
            .unwrap();
        stereo.wait_frame(frame).unwrap();
        mono.read_ldr(&mut a).unwrap();
        stereo.read_view_ldr(frame, 0, &mut b).unwrap();
        assert!(
            a == b,
            "frame {f}: the stereo left eye differs from the mono render"
        );
    }
    assert_clean(&ctx);
}
