//! A-SVGF (Schied, Peters, Dachsbacher 2018) in Cartesian and Visual-Polar space on the
//! Cornell box: gradient samples re-shade last frame's path exactly (δ = 0 on a still scene, the
//! sign and ratio of a light change), a light switched off reaches the output within a few frames
//! where SVGF lags, noise reduction on a still camera comparable to SVGF's, no NaN/Inf/negative
//! output with fireflies or an empty view; run-time emission scaling keeps the light table
//! consistent; a space without temporal filters refuses it, the screen-clipped VP layout runs it.

use fovea_renderer::frame::{CameraPose, FrameInput, RenderSettings};
use fovea_renderer::layouts::{AsvgfGradientSample, ASVGF_NO_LUMINANCE};
use fovea_renderer::passes::denoise::asvgf::{Asvgf, AsvgfSettings};
use fovea_renderer::passes::denoise::svgf::SvgfSettings;
use fovea_renderer::passes::denoise::DenoiserSettings;
use fovea_renderer::passes::resampling::{ResamplingMode, ResamplingSettings};
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::{
    Cartesian, SamplingSpace, VisualPolar, VisualPolarParams, VpLayout,
};
use fovea_renderer::way_back::blur::BlurSettings;
use fovea_tests::{
    assert_clean, assert_pictures, gpu, light_material, mean_rgb, owned_scene, read_image, rmse,
    save_preview, Picture,
};
use glam::{Mat4, UVec2};

const SCREEN: UVec2 = UVec2::new(64, 72);

fn space(name: &str, screen: UVec2) -> Box<dyn SamplingSpace> {
    match name {
        "cartesian" => Box::new(Cartesian::new(screen)),
        _ => Box::new(
            VisualPolar::new(screen, screen.as_vec2() * 0.5, VisualPolarParams::default()).unwrap(),
        ),
    }
}

const SPACES: [&str; 2] = ["cartesian", "vp"];

/// The blur is off: the comparisons measure sampling + denoising only.
fn settings(denoiser: DenoiserSettings) -> RenderSettings {
    RenderSettings {
        blur: BlurSettings {
            sigma_at_30: 0.0,
            ..Default::default()
        },
        denoiser,
        ..Default::default()
    }
}

/// Resampling off and with both passes: with resampling the gradient compares plain path
/// estimates the tracer keeps beside the resampled sample (trace.comp), which must repeat last
/// frame's path as exactly as the plain kernel's gradient samples do.
const RESAMPLING: [ResamplingMode; 2] = [ResamplingMode::Off, ResamplingMode::DiGi];

fn with_resampling(settings: RenderSettings, mode: ResamplingMode) -> RenderSettings {
    RenderSettings {
        resampling: ResamplingSettings::default().with_mode(mode),
        ..settings
    }
}

fn asvgf() -> DenoiserSettings {
    DenoiserSettings::Asvgf(AsvgfSettings::default())
}

fn svgf() -> DenoiserSettings {
    DenoiserSettings::Svgf(SvgfSettings::default())
}

fn frame(camera: CameraPose, frame_index: u32) -> FrameInput {
    FrameInput::mono(camera, frame_index, None).with_hdr(true)
}

fn luminance(p: &[f32; 4]) -> f64 {
    0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64
}

fn mean_luminance(pixels: &[[f32; 4]]) -> f64 {
    pixels.iter().map(luminance).sum::<f64>() / pixels.len() as f64
}

/// Gradient samples the tracer re-shaded last frame: (last luminance, this frame's).
fn reshaded(r: &Renderer) -> (Vec<(f32, f32)>, usize) {
    let Some(a) = r.denoiser().and_then(|d| d.downcast_ref::<Asvgf>()) else {
        panic!("A-SVGF expected")
    };
    let samples: Vec<AsvgfGradientSample> = a.read_samples().unwrap();
    let claimed = samples.iter().filter(|s| s.surface.x != 0).count();
    let pairs = samples
        .iter()
        .filter(|s| s.surface.x != 0 && s.shading.w != ASVGF_NO_LUMINANCE)
        .map(|s| (f32::from_bits(s.shading.z), f32::from_bits(s.shading.w)))
        .collect();
    (pairs, claimed)
}

/// Still camera: a gradient sample shades last frame's surface with last frame's random state, so
/// an unchanged scene gives the same path and δ = 0; the light at half its emission gives exactly
/// half the radiance (δ < 0), and back at full twice that (δ > 0) — all light in the box is the
/// ceiling light's, and every path is the same one; the reconstructed λ = |δ̂| / max f̂ follows (0,
/// ½, ½). Then the same with the camera moving; all of it without and with resampling.
#[test]
fn gradient_samples_reshade_last_frames_path() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let light = light_material(&scene);
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], SCREEN.x, SCREEN.y);
    for (space_name, mode) in SPACES.into_iter().flat_map(|s| RESAMPLING.map(|m| (s, m))) {
        let name = format!("{space_name}, resampling {}", mode.name());
        let name = name.as_str();
        let mut r = Renderer::new(
            &ctx,
            &scene,
            space(space_name, SCREEN),
            with_resampling(settings(asvgf()), mode),
        )
        .unwrap();
        let Some(a) = r.denoiser().and_then(|d| d.downcast_ref::<Asvgf>()) else {
            panic!()
        };
        let strata = a.strata();
        r.render_frame(&frame(camera, 0)).unwrap();
        assert_eq!(
            reshaded(&r).1,
            0,
            "{name}: no gradient samples without a previous frame"
        );

        let check_ratio = |r: &Renderer, f: u32, expected: f32| {
            let (pairs, claimed) = reshaded(r);
            let lit: Vec<(f32, f32)> = pairs
                .iter()
                .copied()
                .filter(|(prev, _)| *prev > 1e-3)
                .collect();
            let off = lit
                .iter()
                .filter(|(prev, cur)| (cur / prev - expected).abs() > 1e-3 * expected)
                .count();
            let worst = lit
                .iter()
                .map(|(prev, cur)| (cur / prev - expected).abs())
                .fold(0f32, f32::max);
            println!(
                "{name} frame {f}: {claimed} of {} strata claimed, {} re-shaded ({} lit); f_i/f_(i-1) = {expected} ± {worst:.2e}, {off} beyond 1e-3",
                strata.x * strata.y,
                pairs.len(),
                lit.len()
            );
            // Most strata of the box (the grid is all box but VP's texels beyond the screen).
            assert!(
                lit.len() * 2 > (strata.x * strata.y) as usize,
                "{name} frame {f}: only {} lit gradient samples",
                lit.len()
            );
            // Rounding in the re-derived view ray may send a rare continuation elsewhere.
            assert!(
                off * 100 <= lit.len(),
                "{name} frame {f}: {off} of {} gradient samples off the ratio {expected}",
                lit.len()
            );
            let sign = lit
                .iter()
                .filter(|(prev, cur)| {
                    (cur - prev).signum() == (expected - 1.0).signum() || expected == 1.0
                })
                .count();
            assert!(
                sign * 100 >= lit.len() * 99,
                "{name} frame {f}: δ has the wrong sign in {} samples",
                lit.len() - sign
            );
            // The reconstruction averages δ and max f alike: λ = |δ̂| / max f̂ is the ratio's.
            let Some(a) = r.denoiser().and_then(|d| d.downcast_ref::<Asvgf>()) else {
                panic!()
            };
            let gradient: Vec<[f32; 4]> = read_image(&ctx, a.gradient());
            let lambda = (expected - 1.0).abs() / expected.max(1.0);
            let confident: Vec<f32> = gradient
                .iter()
                .filter(|g| g[2] > 0.0 && g[1] > 1e-3)
                .map(|g| g[0].abs() / g[1])
                .collect();
            let off = confident
                .iter()
                .filter(|l| (*l - lambda).abs() > 1e-3)
                .count();
            println!("{name} frame {f}: λ = {lambda} expected, {off} of {} reconstructed strata off by > 1e-3", confident.len());
            assert!(
                confident.len() * 2 > (strata.x * strata.y) as usize
                    && off * 100 <= confident.len(),
                "{name} frame {f}: λ off in {off} strata"
            );
        };
        r.render_frame(&frame(camera, 1)).unwrap();
        check_ratio(&r, 1, 1.0);
        r.set_emission_scale(&scene, light, 0.5).unwrap();
        r.render_frame(&frame(camera, 2)).unwrap();
        check_ratio(&r, 2, 0.5);
        r.set_emission_scale(&scene, light, 1.0).unwrap();
        r.render_frame(&frame(camera, 3)).unwrap();
        check_ratio(&r, 3, 2.0);

        // A moving camera: the samples land elsewhere in the grid, and the box's walls are
        // Lambertian, so the same path (seen from a slightly different direction) still gives the
        // same radiance.
        for f in 4..7 {
            let shift = Mat4::from_translation(glam::Vec3::new(
                0.01 * (f - 3) as f32,
                0.005 * (f - 3) as f32,
                0.0,
            ));
            r.render_frame(&frame(
                CameraPose {
                    world_from_view: shift * camera.world_from_view,
                    ..camera
                },
                f,
            ))
            .unwrap();
        }
        check_ratio(&r, 6, 1.0);
        assert_clean(&ctx);
    }
}

/// Frames after the switch (the first frame rendered without the light is 1) until the mean
/// luminance has covered 90 % of the step to its new level; `None` if it never does.
fn lag(after: &[f64], before: f64, level: f64) -> Option<usize> {
    after
        .iter()
        .position(|l| (l - level).abs() <= 0.1 * (before - level).abs())
        .map(|i| i + 1)
}

/// Still camera, the ceiling light switched off after 10 frames: the mean screen luminance of
/// A-SVGF's output reaches its new level (0: nothing else lights the box) within a few frames,
/// where SVGF's history (α = 0.2) decays over about ten; without and with resampling (whose
/// reservoirs start afresh when the lights change, while SVGF's history does not).
#[test]
fn a_light_switched_off_reaches_the_asvgf_output_faster_than_svgf() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let light = light_material(&scene);
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], SCREEN.x, SCREEN.y);
    let (on, off) = (10u32, 14u32);
    for (space_name, mode) in SPACES.into_iter().flat_map(|s| RESAMPLING.map(|m| (s, m))) {
        let name = format!("{space_name}, resampling {}", mode.name());
        let mut lags = Vec::new();
        for (label, denoiser) in [("svgf", svgf()), ("asvgf", asvgf())] {
            let settings = with_resampling(settings(denoiser), mode);
            let mut r = Renderer::new(&ctx, &scene, space(space_name, SCREEN), settings).unwrap();
            let mut hdr = Vec::new();
            let mut levels = Vec::new();
            for f in 0..on + off {
                if f == on {
                    r.set_emission_scale(&scene, light, 0.0).unwrap();
                }
                r.render_frame(&frame(camera, f)).unwrap();
                r.read_hdr(&mut hdr).unwrap();
                levels.push(mean_luminance(&hdr));
            }
            let before = levels[on as usize - 1];
            let after = &levels[on as usize..];
            let frames = lag(after, before, 0.0);
            let trace: Vec<String> = after
                .iter()
                .take(12)
                .map(|l| format!("{:.3}", l / before))
                .collect();
            println!(
                "{name} {label}: lag {frames:?} frames (10 % of the step); level / before: {}",
                trace.join(" ")
            );
            lags.push(frames.unwrap_or(off as usize + 1));
        }
        let (svgf_lag, asvgf_lag) = (lags[0], lags[1]);
        assert!(asvgf_lag <= 3, "{name}: A-SVGF needs {asvgf_lag} frames");
        assert!(
            svgf_lag >= asvgf_lag + 4,
            "{name}: SVGF lags {svgf_lag} frames, A-SVGF {asvgf_lag}: not clearly faster"
        );
    }
    assert_clean(&ctx);
}

/// Screen pixels away from edges in the reference: no pixel of the 5×5 around brighter than the
/// walls ever get (the light and its rim) and the 3×3 neighbours within 30 % of the centre's
/// luminance. Without TAA an edge pixel shows one surface per frame where the reference averages
/// several (aliasing, not noise), and the light's rim (17× the walls) would outweigh the rest.
fn smooth_pixels(reference: &[[f32; 4]], size: UVec2) -> Vec<bool> {
    let (w, h) = (size.x as i32, size.y as i32);
    let lum = |x: i32, y: i32| {
        luminance(&reference[(y.clamp(0, h - 1) * w + x.clamp(0, w - 1)) as usize])
    };
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let c = lum(x, y);
            let near = |r: i32, keep: &dyn Fn(f64) -> bool| {
                (-r..=r).all(|dy| (-r..=r).all(|dx| keep(lum(x + dx, y + dy))))
            };
            c > 0.0 && near(2, &|l| l < 1.5) && near(1, &|l| (l - c).abs() <= 0.3 * c)
        })
        .collect()
}

/// RMSE over the pixels `keep` marks.
fn rmse_where(a: &[[f32; 4]], b: &[[f32; 4]], keep: &[bool]) -> f64 {
    let pick = |v: &[[f32; 4]]| {
        v.iter()
            .zip(keep)
            .filter(|(_, k)| **k)
            .map(|(p, _)| *p)
            .collect::<Vec<_>>()
    };
    rmse(&pick(a), &pick(b))
}

/// Still camera, 16 frames at 96×108: RMSE against a 128-spp Cartesian reference (VP after the
/// remap, blur off) on `smooth_pixels`, whole frame and around the gaze, raw 1 spp vs SVGF vs A-SVGF. On a still scene δ = 0 and
/// λ = 0: A-SVGF is SVGF (its gradient paths are traced apart from the image's samples), so it
/// must reach SVGF's factor within 3 % (measured equal; a fresh sample taken at last frame's
/// brightest point instead of the texel's own jitter gave 0.67× against SVGF's 0.94× over the VP
/// frame).
#[test]
fn asvgf_noise_reduction_is_comparable_to_svgf() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let size = UVec2::new(96, 108);
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], size.x, size.y);
    let mut reference_renderer = Renderer::new(
        &ctx,
        &scene,
        Box::new(Cartesian::new(size)),
        settings(DenoiserSettings::None),
    )
    .unwrap();
    let reference = reference_renderer
        .render_reference(&camera, 128, 3, |_| {})
        .unwrap();
    drop(reference_renderer);
    let smooth = smooth_pixels(&reference, size);
    // Around the gaze (3 fovea radii; the fovea alone holds too few pixels at this size for a
    // stable figure): VP's density is highest there, while further out VP has fewer samples
    // than pixels and its error is mostly resolution, not noise.
    let gaze = size.as_vec2() * 0.5;
    let r_centre = 3.0 * space("vp", size).visual_polar().unwrap().r_fovea();
    let centre: Vec<bool> = (0..size.x * size.y)
        .map(|i| {
            smooth[i as usize]
                && (glam::Vec2::new((i % size.x) as f32 + 0.5, (i / size.x) as f32 + 0.5) - gaze)
                    .length()
                    < r_centre
        })
        .collect();
    let count = |m: &[bool]| m.iter().filter(|k| **k).count();
    println!(
        "{} of {} pixels away from edges, {} of them within {r_centre:.1} px of the gaze",
        count(&smooth),
        smooth.len(),
        count(&centre)
    );
    for name in SPACES {
        let mut errors = Vec::new();
        let mut last = Vec::new();
        for (label, denoiser, frames) in [
            ("raw", DenoiserSettings::None, 1),
            ("svgf", svgf(), 16),
            ("asvgf", asvgf(), 16),
        ] {
            let mut r = Renderer::new(&ctx, &scene, space(name, size), settings(denoiser)).unwrap();
            let mut hdr = Vec::new();
            for f in 0..frames {
                r.render_frame(&frame(camera, f)).unwrap();
            }
            r.read_hdr(&mut hdr).unwrap();
            save_preview(&format!("asvgf_{name}_{label}.png"), size.x, size.y, &hdr);
            errors.push([
                rmse_where(&hdr, &reference, &smooth),
                rmse_where(&hdr, &reference, &centre),
            ]);
            last = hdr;
        }
        // A-SVGF's picture (the last rendered) against the reference.
        let (actual, expected) = (
            Picture::hdr(size.x, size.y, &last),
            Picture::hdr(size.x, size.y, &reference),
        );
        for (region, k) in [("whole frame", 0), ("centre", 1)] {
            let (svgf_factor, asvgf_factor) =
                (errors[0][k] / errors[1][k], errors[0][k] / errors[2][k]);
            println!(
                "{name} {region}: RMSE raw {:.4}, SVGF {:.4} ({svgf_factor:.2}×), A-SVGF {:.4} ({asvgf_factor:.2}×) after 16 frames",
                errors[0][k], errors[1][k], errors[2][k]
            );
            assert_pictures(
                asvgf_factor >= 0.97 * svgf_factor,
                name,
                &actual,
                &expected,
                format_args!(
                    "{name} {region}: A-SVGF {asvgf_factor:.2}× vs SVGF {svgf_factor:.2}×"
                ),
            );
            if name == "cartesian" || region == "centre" {
                assert_pictures(
                    asvgf_factor >= 3.0,
                    name,
                    &actual,
                    &expected,
                    format_args!(
                        "{name} {region}: A-SVGF reduces the RMSE only {asvgf_factor:.2}×"
                    ),
                );
            }
        }
    }
    assert_clean(&ctx);
}

fn assert_finite_non_negative(what: &str, pixels: &[[f32; 4]]) {
    for (i, p) in pixels.iter().enumerate() {
        assert!(
            p.iter().all(|v| v.is_finite() && *v >= 0.0),
            "{what}: texel {i} = {p:?}"
        );
    }
}

/// Fireflies: the light scaled by 1e30 for two frames (radiance that overflows to Inf in the tracer
/// or saturates the moments) between normal frames, so gradients see the jump both ways; and an
/// empty view (the camera turned out of the box's open side): every output finite and
/// non-negative, the empty view exactly black.
#[test]
fn asvgf_output_is_finite_and_non_negative_with_fireflies_and_an_empty_view() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let light = light_material(&scene);
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], SCREEN.x, SCREEN.y);
    let away = CameraPose {
        world_from_view: camera.world_from_view * Mat4::from_rotation_y(std::f32::consts::PI),
        ..camera
    };
    for name in SPACES {
        let mut r = Renderer::new(&ctx, &scene, space(name, SCREEN), settings(asvgf())).unwrap();
        let mut hdr = Vec::new();
        for f in 0..6 {
            r.set_emission_scale(&scene, light, if f == 2 || f == 3 { 1e30 } else { 1.0 })
                .unwrap();
            r.render_frame(&frame(camera, f)).unwrap();
            r.read_hdr(&mut hdr).unwrap();
            assert_finite_non_negative(&format!("{name} frame {f}"), &hdr);
        }
        for f in 6..9 {
            r.render_frame(&frame(away, f)).unwrap();
            r.read_hdr(&mut hdr).unwrap();
            assert!(
                hdr.iter().all(|p| p[..3] == [0.0; 3]),
                "{name}: the empty view is not black (frame {f})"
            );
        }
        assert_clean(&ctx);
    }
}

/// `Renderer::set_emission_scale`: the light off leaves the box black, back on gives the very
/// same frame as before (materials and light table restored), dimmed to a quarter a quarter of
/// it; a missing material and a negative or non-finite scale are errors.
#[test]
fn emission_scale_switches_a_light_consistently() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let light = light_material(&scene);
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], SCREEN.x, SCREEN.y);
    let mut r = Renderer::new(
        &ctx,
        &scene,
        space("cartesian", SCREEN),
        settings(DenoiserSettings::None),
    )
    .unwrap();
    let render = |r: &mut Renderer| {
        let mut hdr = Vec::new();
        r.render_frame(&frame(camera, 5)).unwrap();
        r.read_hdr(&mut hdr).unwrap();
        hdr
    };
    let lit = render(&mut r);
    let lit_light_count = r.scene.light_count;
    r.set_emission_scale(&scene, light, 0.0).unwrap();
    assert_eq!(r.scene.light_count, 0);
    assert_eq!(mean_rgb(&render(&mut r)), [0.0; 3]);
    r.set_emission_scale(&scene, light, 0.25).unwrap();
    let dimmed = render(&mut r);
    let ratio = mean_luminance(&dimmed) / mean_luminance(&lit);
    assert!(
        (ratio - 0.25).abs() < 1e-4,
        "a quarter of the emission gives {ratio} of the light"
    );
    r.set_emission_scale(&scene, light, 1.0).unwrap();
    assert_eq!(r.scene.light_count, lit_light_count);
    assert_eq!(render(&mut r), lit, "back on, the frame differs");
    for (material, scale) in [
        (scene.materials.len(), 1.0),
        (light, -1.0),
        (light, f32::NAN),
    ] {
        let err = r
            .set_emission_scale(&scene, material, scale)
            .unwrap_err()
            .to_string();
        assert!(err.contains("emission scale"), "{err}");
    }
    assert_clean(&ctx);
}

/// The renderer itself (not only the CLI) refuses every denoiser and TAA mode on a space whose
/// capabilities exclude them (linear falloff: its pixels are killed at random), naming the space
/// and why, and accepts the bare space; the screen-clipped VP layout takes every filter.
#[test]
fn the_renderer_refuses_filters_a_space_cannot_run() {
    use fovea_renderer::passes::denoise::bmfr::BmfrSettings;
    use fovea_renderer::passes::taa::{TaaMode, TaaSettings};
    use fovea_renderer::sampling::{FalloffShape, LinearFalloff, FALLOFF_BUDGET_OF_VP};
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let falloff = || {
        Box::new(
            LinearFalloff::new(
                SCREEN,
                VisualPolarParams::default(),
                FalloffShape::default(),
                FALLOFF_BUDGET_OF_VP,
            )
            .unwrap(),
        )
    };
    let clipped = || {
        let params = VisualPolarParams {
            layout: VpLayout::ScreenClipped,
            ..VisualPolarParams::default()
        };
        Box::new(VisualPolar::new(SCREEN, SCREEN.as_vec2() * 0.5, params).unwrap())
    };
    assert!(!falloff().capabilities().temporal_filters);
    assert!(
        clipped().capabilities().temporal_filters
            && clipped().capabilities().way_back == fovea_renderer::sampling::WayBack::Remap
    );
    let cases = [
        (
            "svgf",
            settings(DenoiserSettings::Svgf(SvgfSettings::default())),
        ),
        ("asvgf", settings(asvgf())),
        (
            "bmfr",
            settings(DenoiserSettings::Bmfr(BmfrSettings::default())),
        ),
        (
            "vp",
            RenderSettings {
                taa: TaaMode::SamplingGrid(TaaSettings::default()),
                ..settings(DenoiserSettings::None)
            },
        ),
        (
            "screen",
            RenderSettings {
                taa: TaaMode::Screen(TaaSettings::default()),
                ..settings(DenoiserSettings::None)
            },
        ),
    ];
    for (name, s) in cases {
        let err = Renderer::new(&ctx, &scene, falloff(), s)
            .err()
            .unwrap_or_else(|| panic!("{name} accepted"))
            .to_string();
        assert!(
            err.contains(name) && err.contains("linear-falloff") && err.contains("killed"),
            "{err}"
        );
        if let Err(e) = Renderer::new(&ctx, &scene, clipped(), s) {
            panic!("{name} refused on the screen-clipped layout: {e}");
        }
    }
    assert!(Renderer::new(&ctx, &scene, falloff(), settings(DenoiserSettings::None)).is_ok());
    assert_clean(&ctx);
}

/// `fovea render --denoiser asvgf` (moving camera, simulated gaze): the report names the
/// denoiser and times its passes in every Visual-Polar layout and Cartesian space.
#[test]
fn render_command_runs_asvgf_and_reports_it() {
    use fovea_tools::commands::render::{run, RenderArgs};
    let out = fovea_tests::artifacts_dir().join(format!("asvgf-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    for method in ["cartesian", "vp", "vp-screen-clipped"] {
        run(&RenderArgs {
            method,
            denoiser: "asvgf",
            frames: 3,
            exr: false,
            ..fovea_tests::small_render_args("cornell-box", &out)
        })
        .unwrap();
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap())
                .unwrap();
        assert_eq!(report["denoiser"], "asvgf");
        for pass in [
            "asvgf_clear",
            "asvgf_forward",
            "asvgf_gradient",
            "svgf_temporal",
            "svgf_atrous",
            "svgf_modulate",
        ] {
            assert!(
                report["passes"].get(pass).is_some(),
                "{method}: pass {pass} missing"
            );
        }
    }
}
