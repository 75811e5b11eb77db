//! The sparse comparators of comparators.md that trace samples scattered over the screen and fill
//! the rest: linear falloff (§B) and random acuity samples. Each traces exactly the samples its
//! host-side rule names (the rule is the GPU's: Rust = GLSL), its way back leaves no hole and
//! keeps the traced pixels, it converges to the image one sample per pixel gives, it refuses the
//! filters it cannot run, and `fovea render --method NAME` reports it end to end.

use fovea_renderer::frame::{CameraPose, FrameInput, OffscreenSamples, RenderSettings};
use fovea_renderer::graph::FrameRecorder;
use fovea_renderer::passes::denoise::DenoiserSettings;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::{
    FalloffShape, LinearFalloff, RandomAcuity, SamplingSpace, VisualPolar, VisualPolarParams,
    FALLOFF_BUDGET_OF_VP,
};
use fovea_renderer::vk::Image;
use fovea_renderer::way_back::fill::FillPass;
use fovea_renderer::way_back::splat::{SplatInputs, SplatPass};
use fovea_tests::{assert_clean, gpu, owned_scene, probe};
use glam::{UVec2, Vec2};

const SCREEN: UVec2 = UVec2::new(64, 72);

fn falloff() -> LinearFalloff {
    LinearFalloff::new(
        SCREEN,
        VisualPolarParams::default(),
        FalloffShape::default(),
        FALLOFF_BUDGET_OF_VP,
    )
    .unwrap()
}

/// No frame may hold a hole or a non-finite pixel.
fn no_holes(f: u32, hdr: &[[f32; 4]]) {
    assert_eq!(hdr.len(), (SCREEN.x * SCREEN.y) as usize);
    assert!(
        hdr.iter()
            .all(|p| p.iter().all(|c| c.is_finite()) && p[3] > 0.0),
        "frame {f}: a hole or a non-finite pixel"
    );
}

#[test]
fn linear_falloff_traces_the_pixels_its_rule_keeps_and_converges_like_one_sample_per_pixel() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let camera = CameraPose::from_scene_camera(scene.default_camera().unwrap(), SCREEN.x, SCREEN.y);
    let settings = RenderSettings::default();
    let gaze = Vec2::new(20.0, 50.0);
    let mut host = falloff();
    host.set_gaze(gaze).unwrap();
    let mut r = Renderer::new(&ctx, &scene, Box::new(falloff()), settings).unwrap();
    for f in 0..3 {
        let stats = r
            .render_frame(&FrameInput::mono(camera, f, Some(gaze)))
            .unwrap();
        assert_eq!(
            stats.samples_traced,
            host.traced_count(f, settings.seed),
            "frame {f}"
        );
        assert_eq!(stats.samples_offscreen, 0);
    }
    let expected = host.sample_count() as f64;
    assert!(
        expected < (SCREEN.x * SCREEN.y) as f64 * 0.9,
        "{expected}: the periphery is thinned"
    );
    fovea_tests::assert_mean_like_cartesian(&ctx, &scene, &mut r, camera, gaze, 16, no_holes);
    assert_clean(&ctx);
}

/// A smooth ramp sampled at one pixel in five: the filled image keeps every sample exactly and
/// puts the ramp's value everywhere else (within 12 % of its range at worst, 2 % on average).
#[test]
fn push_pull_keeps_the_samples_and_fills_the_holes_smoothly() {
    let ctx = gpu();
    let size = UVec2::new(61, 47);
    let truth = |x: u32, y: u32| [x as f32 / 60.0, y as f32 / 46.0, 0.5, 1.0];
    let keep = |x: u32, y: u32| fovea_tests::unit_hash(x * 7919 + y * 104_729) < 0.2;
    let sparse: Vec<[f32; 4]> = (0..size.y)
        .flat_map(|y| (0..size.x).map(move |x| (x, y)))
        .map(|(x, y)| if keep(x, y) { truth(x, y) } else { [0.0; 4] })
        .collect();
    let input = Image::new(
        &ctx,
        "sparse",
        size.x,
        size.y,
        ash::vk::Format::R32G32B32A32_SFLOAT,
    )
    .unwrap();
    fovea_tests::write_image(&ctx, &input, &sparse);
    let fill = FillPass::new(&ctx, size).unwrap();
    let out = {
        let mut rec = fovea_renderer::graph::FrameRecorder::new(&ctx, fill.passes() + 1).unwrap();
        rec.begin().unwrap();
        let filled = fill.record(&mut rec, &input).unwrap();
        rec.submit_and_wait().unwrap();
        fovea_tests::read_image::<[f32; 4]>(&ctx, filled)
    };
    let (mut worst, mut sum): (f32, f64) = (0.0, 0.0);
    for y in 0..size.y {
        for x in 0..size.x {
            let (got, want) = (out[(y * size.x + x) as usize], truth(x, y));
            if keep(x, y) {
                assert_eq!(got, want, "sample ({x}, {y}) kept as traced");
            }
            assert_eq!(got[3], 1.0);
            let error = (0..3).map(|c| (got[c] - want[c]).abs()).fold(0.0, f32::max);
            worst = worst.max(error);
            sum += error as f64;
        }
    }
    let mean = sum / (size.x * size.y) as f64;
    println!("push-pull error: worst {worst}, mean {mean}");
    // Measured: worst 0.088 (a hole next to the border, filled from a coarse level), mean 0.012.
    assert!(worst < 0.12 && mean < 0.02, "worst {worst}, mean {mean}");
    assert_clean(&ctx);
}

#[test]
fn linear_falloff_refuses_the_filters_and_the_cli_reports_it() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    fovea_tests::assert_refuses_svgf(&ctx, &scene, Box::new(falloff()));
    assert_clean(&ctx);

    let report = fovea_tests::render_report("linear-falloff", fovea_tests::profile_with_blur());
    assert_eq!(report["method"], "linear-falloff");
    assert!(
        report["passes"]["fill_push"].as_f64().is_some()
            && report["passes"]["blur_v"].as_f64().is_some(),
        "{}",
        report["passes"]
    );
    let traced = report["samples_traced"].as_u64().unwrap();
    assert!(traced > 0 && traced < 64 * 72, "{report}");
}

fn random_acuity(screen: UVec2, gaze: Vec2) -> RandomAcuity {
    RandomAcuity::new(screen, gaze, VisualPolarParams::default()).unwrap()
}

/// Rust = GLSL on every texel of two screens, three gazes and two frames: the same texels draw,
/// and their samples land within 2e-3 px of each other (the mapping's float order; the draws
/// themselves are the same bits).
#[test]
fn random_acuity_draws_agree_between_rust_and_glsl() {
    let ctx = gpu();
    for screen in [UVec2::new(64, 72), UVec2::new(320, 360)] {
        let s = screen.as_vec2();
        for gaze in [s * 0.5, Vec2::new(0.1, 0.2) * s, Vec2::new(0.97, 0.9) * s] {
            let space = random_acuity(screen, gaze);
            for frame in [0, 7] {
                let gpu: Vec<Option<Vec2>> = probe(&ctx, &space, frame, 11)
                    .iter()
                    .map(|p| p.position)
                    .collect();
                let g = space.grid_size();
                let mut worst: f32 = 0.0;
                for (i, got) in gpu.iter().enumerate() {
                    let t = UVec2::new(i as u32 % g.x, i as u32 / g.x);
                    let want = space.screen_position(t, frame, 11);
                    assert_eq!(
                        got.is_some(),
                        want.is_some(),
                        "{screen} gaze {gaze} frame {frame} texel {t}"
                    );
                    if let (Some(a), Some(b)) = (got, want) {
                        worst = worst.max((*a - b).length() / (1.0 + (b - gaze).length() * 1e-3));
                    }
                }
                assert!(
                    worst < 2e-3,
                    "{screen} gaze {gaze} frame {frame}: worst {worst} px"
                );
            }
        }
    }
    assert_clean(&ctx);
}

/// The draws follow Visual-Polar's sample density: per ring of distance from the gaze, the
/// samples of eight frames against the probability that a position uniform over VP's kept texels
/// (the density VP's grid stands for) lies in the ring — exact: a ring is a span of the ρ axis,
/// so its probability is the kept texels' area over that span — held by Pearson's χ² at 1 %.
#[test]
fn random_acuity_samples_follow_visual_polars_density_per_ring() {
    let screen = UVec2::new(320, 360);
    let gaze = Vec2::new(140.0, 200.0);
    let space = random_acuity(screen, gaze);
    let vp = VisualPolar::new(screen, gaze, VisualPolarParams::default()).unwrap();
    let r_max = vp.r_max();
    let rings = 8;
    let ring = |p: Vec2| {
        (((p - gaze).length() / r_max).sqrt() * rings as f32).min(rings as f32 - 1.0) as usize
    };
    let g = vp.grid_size();
    // Ring k spans r ∈ [(k/8)², ((k+1)/8)²]·r_max, i.e. the grid's x from x(r_lo) to x(r_hi).
    let x_of_r = |r: f32| {
        if r <= 0.0 {
            0.0
        } else if r >= r_max {
            g.x as f64
        } else {
            vp.screen_to_vp(gaze + Vec2::new(r, 0.0)).x as f64
        }
    };
    let kept = vp.sample_count() as f64;
    let probability: Vec<f64> = (0..rings)
        .map(|k| {
            let edge = |k: usize| (k as f32 / rings as f32).powi(2) * r_max;
            let (a, b) = (x_of_r(edge(k)), x_of_r(edge(k + 1)));
            (0..g.x)
                .map(|c| {
                    let overlap = (b.min(c as f64 + 1.0) - a.max(c as f64)).max(0.0);
                    overlap * vp.rows_in_column(c) as f64
                })
                .sum::<f64>()
                / kept
        })
        .collect();
    let mut drawn = vec![0f64; rings];
    for y in 0..g.y {
        for x in 0..g.x {
            for frame in 0..8 {
                if let Some(p) = space.screen_position(UVec2::new(x, y), frame, 1) {
                    drawn[ring(p)] += 1.0;
                }
            }
        }
    }
    let total: f64 = drawn.iter().sum();
    assert_eq!(total as u64, 8 * vp.sample_count());
    let expected: Vec<f64> = probability.iter().map(|p| p * total).collect();
    let fit = fovea_test_kit::chi2::chi2_test(&drawn, &expected, 0.01);
    println!("per ring drawn {drawn:?} vs VP's density {expected:.0?}: {fit:?}");
    assert!(fit.is_ok(), "{}", fit.unwrap_err());
}

/// A constant grid splats to exactly that constant wherever a sample landed (the pixels the host
/// computes) and leaves alpha 0 everywhere else.
#[test]
fn the_splat_puts_every_sample_in_its_pixel() {
    let ctx = gpu();
    let (screen, gaze) = (UVec2::new(64, 72), Vec2::new(20.0, 30.0));
    let space = random_acuity(screen, gaze);
    let grid = space.grid_size();
    let value = [0.25, 0.5, 2.0, 1.0];
    let color = Image::new(
        &ctx,
        "grid_color",
        grid.x,
        grid.y,
        ash::vk::Format::R32G32B32A32_SFLOAT,
    )
    .unwrap();
    fovea_tests::write_image(&ctx, &color, &vec![value; (grid.x * grid.y) as usize]);
    let buffers = fovea_tests::SpaceBuffers::new(&ctx, &space, 5, 2);
    let splat = SplatPass::new(&ctx, space.trace_variant(), screen).unwrap();
    let mut rec = FrameRecorder::new(&ctx, splat.passes() + 1).unwrap();
    rec.begin().unwrap();
    let inputs = SplatInputs {
        frame_data: &buffers.frame,
        sampling: &buffers.sampling,
        sampling_table: &buffers.table,
    };
    let sparse = splat.record(&mut rec, &inputs, &color).unwrap();
    rec.submit_and_wait().unwrap();
    let out: Vec<[f32; 4]> = fovea_tests::read_image(&ctx, sparse);
    let mut hit = vec![false; (screen.x * screen.y) as usize];
    for y in 0..grid.y {
        for x in 0..grid.x {
            let Some(p) = space.screen_position(UVec2::new(x, y), 5, 2) else {
                continue;
            };
            if p.cmpge(Vec2::ZERO).all() && p.cmplt(screen.as_vec2()).all() {
                hit[(p.y as u32 * screen.x + p.x as u32) as usize] = true;
            }
        }
    }
    let covered = hit.iter().filter(|&&h| h).count();
    assert!(
        covered > 500 && covered < hit.len(),
        "{covered}: the fovea is dense, the periphery holes"
    );
    for (i, (px, &h)) in out.iter().zip(&hit).enumerate() {
        // Within a pixel's width of a sample, the host and the GPU may put it on either side.
        let want = if h { value } else { [0.0; 4] };
        let near = |dx: i32, dy: i32| {
            let (x, y) = (
                (i as u32 % screen.x) as i32 + dx,
                (i as u32 / screen.x) as i32 + dy,
            );
            x >= 0
                && y >= 0
                && x < screen.x as i32
                && y < screen.y as i32
                && hit[(y as u32 * screen.x + x as u32) as usize] != h
        };
        if *px != want {
            assert!(
                (-1..=1).any(|dx| (-1..=1).any(|dy| near(dx, dy))),
                "pixel {i}: {px:?}, want {want:?}"
            );
        }
        assert!(*px == value || *px == [0.0; 4], "pixel {i}: {px:?}");
    }
    assert_clean(&ctx);
}

#[test]
fn random_acuity_traces_visual_polars_count_and_converges_like_one_sample_per_pixel() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let camera = CameraPose::from_scene_camera(scene.default_camera().unwrap(), SCREEN.x, SCREEN.y);
    let settings = RenderSettings {
        offscreen_samples: OffscreenSamples::Trace,
        ..Default::default()
    };
    let gaze = Vec2::new(40.0, 30.0);
    let host = random_acuity(SCREEN, gaze);
    let mut r = Renderer::new(
        &ctx,
        &scene,
        Box::new(random_acuity(SCREEN, SCREEN.as_vec2() * 0.5)),
        settings,
    )
    .unwrap();
    for f in 0..3 {
        let stats = r
            .render_frame(&FrameInput::mono(camera, f, Some(gaze)))
            .unwrap();
        assert_eq!(
            stats.samples_traced,
            host.traced_count(f, settings.seed),
            "frame {f}"
        );
        assert_eq!(
            stats.samples_traced,
            host.sample_count(),
            "frame {f}: every kept texel drew"
        );
    }
    fovea_tests::assert_mean_like_cartesian(&ctx, &scene, &mut r, camera, gaze, 16, no_holes);
    fovea_tests::assert_refuses_svgf(&ctx, &scene, Box::new(host));
    assert_clean(&ctx);

    let report = fovea_tests::render_report("random-acuity", fovea_tests::profile_with_blur());
    assert_eq!(report["method"], "random-acuity");
    for pass in ["splat_scatter", "splat_resolve", "fill_push", "blur_v"] {
        assert!(
            report["passes"][pass].as_f64().is_some(),
            "{pass}: {}",
            report["passes"]
        );
    }
}

/// Composite foveation (Andersson & Hansson 2020) is a radial law of the polar space: every
/// filter runs on it without validation messages, and `fovea render --method composite
/// --composite-mode M` reports it end to end.
#[test]
fn composite_runs_the_filters_and_the_cli_reports_it() {
    use fovea_renderer::passes::taa::TaaMode;
    use fovea_renderer::sampling::{CompositeMode, RadialLaw};
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let camera = CameraPose::from_scene_camera(scene.default_camera().unwrap(), SCREEN.x, SCREEN.y);
    let radial = RadialLaw::Composite(CompositeMode::Composite.params(SCREEN.x as f32 / 2.0));
    let space = VisualPolar::new(
        SCREEN,
        SCREEN.as_vec2() * 0.5,
        VisualPolarParams {
            radial,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(space.u_fovea() > 0.0, "the gaze disc");
    for denoiser in ["svgf", "asvgf", "bmfr"] {
        let settings = RenderSettings {
            denoiser: DenoiserSettings::parse(denoiser).unwrap(),
            taa: TaaMode::parse("vp").unwrap(),
            ..Default::default()
        };
        let mut r = Renderer::new(&ctx, &scene, Box::new(space), settings).unwrap();
        fovea_tests::mean_over_frames(&mut r, camera, Some(Vec2::new(25.0, 40.0)), 3, |f, hdr| {
            assert!(
                hdr.iter().all(|p| p.iter().all(|c| c.is_finite())),
                "{denoiser} frame {f}"
            );
        });
    }
    assert_clean(&ctx);

    let profile = fovea_tools::render_profile::RenderProfile {
        composite_mode: CompositeMode::Kernel,
        ..Default::default()
    };
    let report = fovea_tests::render_report("composite", profile);
    assert_eq!(report["method"], "composite");
    assert_eq!(report["composite_mode"], "kernel");
    assert!(
        report["passes"]["remap"].as_f64().is_some(),
        "{}",
        report["passes"]
    );
}

/// Fixed foveation: with the eye near a corner it renders byte for byte what Visual-Polar renders
/// with the eye on the lens centre, SVGF included (its filters run in the lens-centred grid), and
/// `fovea render --method fixed-foveation` records where the eye looked.
#[test]
fn fixed_foveation_keeps_the_fovea_on_the_lens_wherever_the_eye_looks() {
    use fovea_renderer::sampling::FixedFoveation;
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let camera = CameraPose::from_scene_camera(scene.default_camera().unwrap(), SCREEN.x, SCREEN.y);
    let lens = SCREEN.as_vec2() * 0.5;
    for denoiser in ["none", "svgf"] {
        let settings = RenderSettings {
            denoiser: DenoiserSettings::parse(denoiser).unwrap(),
            ..Default::default()
        };
        let fixed = FixedFoveation::new(SCREEN, lens, VisualPolarParams::default()).unwrap();
        let mut fixed = Renderer::new(&ctx, &scene, Box::new(fixed), settings).unwrap();
        let mut vp = Renderer::new(
            &ctx,
            &scene,
            Box::new(VisualPolar::new(SCREEN, lens, VisualPolarParams::default()).unwrap()),
            settings,
        )
        .unwrap();
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for f in 0..3 {
            let eye = Vec2::new(6.0 + 3.0 * f as f32, 8.0);
            fixed
                .render_frame(&FrameInput::mono(camera, f, Some(eye)))
                .unwrap();
            vp.render_frame(&FrameInput::mono(camera, f, Some(lens)))
                .unwrap();
            assert_eq!(fixed.space().gaze(), eye);
            fixed.read_ldr(&mut a).unwrap();
            vp.read_ldr(&mut b).unwrap();
            assert!(
                a == b,
                "{denoiser} frame {f}: fixed foveation moved with the eye"
            );
        }
    }
    assert_clean(&ctx);

    let report = fovea_tests::render_report("fixed-foveation", Default::default());
    assert_eq!(report["method"], "fixed-foveation");
    assert!(
        report["visual_polar"].is_object() && report["passes"]["remap"].as_f64().is_some(),
        "{report}"
    );
    // The simulated eye is off the lens centre (32, 36): its gaze, not the samples' centre.
    let gaze = &report["gaze"][0];
    assert!(
        gaze.is_array() && *gaze != serde_json::json!([32.0, 36.0]),
        "{gaze}"
    );
}

/// Variable-rate tiles: every packed texel's pixel on the GPU is the Rust rule's (Rust = GLSL, two
/// screens × four gazes), a frame traces exactly that many samples, the splat and fill leave no
/// hole and converge to one sample per pixel's image, the filters are refused, and
/// `fovea render --method vrs-tiles` reports it end to end.
#[test]
fn vrs_tiles_trace_the_rust_rules_pixels_and_converge_like_one_sample_per_pixel() {
    use fovea_renderer::sampling::VrsTiles;
    let ctx = gpu();
    for screen in [SCREEN, UVec2::new(320, 360)] {
        let s = screen.as_vec2();
        for gaze in [
            s * 0.5,
            Vec2::new(3.3, s.y - 2.1),
            Vec2::new(0.74, 0.22) * s,
            Vec2::new(-20.0, 10.0),
        ] {
            let space = VrsTiles::new(screen, gaze, VisualPolarParams::default()).unwrap();
            let g = space.grid_size();
            for (i, got) in probe(&ctx, &space, 0, 1).iter().enumerate() {
                let t = glam::IVec2::new((i as u32 % g.x) as i32, (i as u32 / g.x) as i32);
                let want = space.pixel(t).map(|p| p.as_vec2() + 0.5);
                assert_eq!(got.position, want, "{screen} gaze {gaze} texel {t}");
            }
        }
    }
    let scene = owned_scene("cornell-box");
    let camera = CameraPose::from_scene_camera(scene.default_camera().unwrap(), SCREEN.x, SCREEN.y);
    let tiles = |gaze| VrsTiles::new(SCREEN, gaze, VisualPolarParams::default()).unwrap();
    let mut r = Renderer::new(
        &ctx,
        &scene,
        Box::new(tiles(SCREEN.as_vec2() * 0.5)),
        RenderSettings::default(),
    )
    .unwrap();
    for (f, gaze) in [Vec2::new(20.0, 50.0), Vec2::new(60.0, 5.0)]
        .into_iter()
        .enumerate()
    {
        let stats = r
            .render_frame(&FrameInput::mono(camera, f as u32, Some(gaze)))
            .unwrap();
        assert_eq!(
            stats.samples_traced,
            tiles(gaze).sample_count(),
            "gaze {gaze}"
        );
    }
    fovea_tests::assert_mean_like_cartesian(
        &ctx,
        &scene,
        &mut r,
        camera,
        Vec2::new(20.0, 50.0),
        16,
        no_holes,
    );
    fovea_tests::assert_refuses_svgf(&ctx, &scene, Box::new(tiles(SCREEN.as_vec2() * 0.5)));
    assert_clean(&ctx);

    let report = fovea_tests::render_report("vrs-tiles", fovea_tests::profile_with_blur());
    assert_eq!(report["method"], "vrs-tiles");
    assert!(
        report["passes"]["splat_scatter"].as_f64().is_some()
            && report["passes"]["blur_v"].as_f64().is_some(),
        "{}",
        report["passes"]
    );
}
