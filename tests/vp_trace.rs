//! The tracer fed by the Visual-Polar sampling space (pipeline step 1): one traced sample
//! per kept VP texel, nothing traced in the clipped fovea triangle, off-screen samples traced and
//! counted (`FrameStats::samples_offscreen`, ray counter slot 3) when they are traced as in the
//! paper (`OffscreenSamples::Trace`); culled by default, with the picture unchanged. The screen-clipped layout traces
//! the same number of samples and keeps them on the screen: only jittered samples of texels whose
//! cell reaches past the border (the cell spans a column's width in radius, its arcs are those of
//! the centre radius) may leave it.
//!
//! The off-screen count is checked two ways:
//! - exactly, against a CPU replay of the kernel's jitter (the same PCG hash seeded the same way
//!   as `rng_seed(texel, frame, seed, 0)` in `trace.comp`; the jitter is the first `rng_next2`)
//!   mapped by the Rust twin `VisualPolar::vp_to_screen`, allowing for the texels whose CPU
//!   position lies within 2e-3 px of the screen border (Rust and GLSL agree to < 1e-3 px,
//!   `tests/vp_mapping.rs`);
//! - jitter-independently: between the texels whose whole cell is off-screen and the texels
//!   with any part off-screen (each cell probed on a 9×9 lattice).

use fovea_renderer::frame::{CameraPose, FrameInput, FrameStats, OffscreenSamples, RenderSettings};
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::random::{pcg_hash, rng_seed};
use fovea_renderer::sampling::{
    Cartesian, Eccentricity, FovTangents, SamplingSpace, VisualPolar, VisualPolarParams, VpLayout,
};
use fovea_renderer::vk::Context;
use fovea_scene::Scene;
use fovea_tests::{assert_clean, gpu, read_image};
use glam::{IVec2, UVec2, Vec2};
use std::sync::Arc;

const SCREEN: UVec2 = UVec2::new(160, 180);
const FRAME_INDEX: u32 = 3;

/// `rng_seed` + the first `rng_next2` of `shaders/common/random.glsl`.
fn kernel_jitter(texel: UVec2, frame: u32, seed: u32, sample_index: u32) -> Vec2 {
    let mut state = rng_seed(texel.to_array(), frame, seed, sample_index);
    let mut next = || {
        state = pcg_hash(state);
        (state >> 8) as f32 * (1.0 / 16_777_216.0)
    };
    let x = next();
    let y = next();
    Vec2::new(x, y)
}

fn offscreen(p: Vec2) -> bool {
    let s = SCREEN.as_vec2();
    p.x < 0.0 || p.y < 0.0 || p.x >= s.x || p.y >= s.y
}

/// Distance from p to the screen border (positive both inside and outside).
fn border_distance(p: Vec2) -> f32 {
    let s = SCREEN.as_vec2();
    if offscreen(p) {
        let dx = (-p.x).max(p.x - s.x).max(0.0);
        let dy = (-p.y).max(p.y - s.y).max(0.0);
        dx.max(dy).max(1e-9)
    } else {
        p.x.min(p.y).min(s.x - p.x).min(s.y - p.y)
    }
}

struct CpuCounts {
    /// Replay of the kernel's jitter: off-screen samples, and those within 2e-3 px of the border.
    replay: u64,
    replay_ambiguous: u64,
    /// At texel centres (for the report).
    centres: u64,
    /// Cells entirely off-screen / with any probe off-screen.
    cell_all: u64,
    cell_any: u64,
}

fn cpu_counts(vp: &VisualPolar, seed: u32) -> CpuCounts {
    let g = vp.grid_size();
    let mut c = CpuCounts {
        replay: 0,
        replay_ambiguous: 0,
        centres: 0,
        cell_all: 0,
        cell_any: 0,
    };
    for x in 0..g.x {
        for y in 0..vp.rows_in_column(x) {
            assert!(vp.is_valid_texel(IVec2::new(x as i32, y as i32)));
            let t = Vec2::new(x as f32, y as f32);
            let p = vp.vp_to_screen(t + kernel_jitter(UVec2::new(x, y), FRAME_INDEX, seed, 0));
            c.replay += offscreen(p) as u64;
            c.replay_ambiguous += (border_distance(p) < 2e-3) as u64;
            c.centres += offscreen(vp.vp_to_screen(t + 0.5)) as u64;
            let (mut all, mut any) = (true, false);
            for i in 0..9 {
                for j in 0..9 {
                    let o = offscreen(
                        vp.vp_to_screen(t + Vec2::new(i as f32, j as f32) * (0.9999 / 8.0)),
                    );
                    all &= o;
                    any |= o;
                }
            }
            c.cell_all += all as u64;
            c.cell_any += any as u64;
        }
    }
    c
}

fn cornell() -> Scene {
    fovea_tests::owned_scene("cornell-box")
}

fn render(
    ctx: &Arc<Context>,
    scene: &Scene,
    space: Box<dyn SamplingSpace>,
) -> (Renderer, FrameStats) {
    let settings = RenderSettings {
        offscreen_samples: OffscreenSamples::Trace,
        ..Default::default()
    };
    let mut r = Renderer::new(ctx, scene, space, settings).unwrap();
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], SCREEN.x, SCREEN.y);
    let stats = r
        .render_frame(&FrameInput::mono(camera, FRAME_INDEX, None))
        .unwrap();
    (r, stats)
}

/// Renders one VP frame and checks counts and the G-buffer; returns the off-screen share and the
/// CPU counts.
fn check_vp_frame(
    ctx: &Arc<Context>,
    scene: &Scene,
    gaze_name: &str,
    gaze: Vec2,
    layout: VpLayout,
) -> (f64, CpuCounts, u64) {
    check_vp_frame_with(
        ctx,
        scene,
        gaze_name,
        gaze,
        VisualPolarParams {
            layout,
            ..Default::default()
        },
    )
}

fn check_vp_frame_with(
    ctx: &Arc<Context>,
    scene: &Scene,
    gaze_name: &str,
    gaze: Vec2,
    params: VisualPolarParams,
) -> (f64, CpuCounts, u64) {
    let (layout, eccentricity) = (params.layout, params.eccentricity);
    let vp = VisualPolar::new(SCREEN, gaze, params).unwrap();
    let (r, stats) = render(ctx, scene, Box::new(vp));
    let g = vp.grid_size();
    let samples = vp.sample_count();
    let cpu = cpu_counts(&vp, r.settings.seed);
    let share = stats.samples_offscreen as f64 / samples as f64;
    println!(
        "{layout:?} {eccentricity:?} gaze {gaze_name} {gaze}: grid {}x{}, {} samples ({:.1} % of {} screen pixels), traced {}, off-screen {} = {:.1} % \
         (CPU replay {} ± {}, at texel centres {}, cell bounds [{}, {}])",
        g.x,
        g.y,
        samples,
        100.0 * samples as f64 / (SCREEN.x * SCREEN.y) as f64,
        SCREEN.x * SCREEN.y,
        stats.samples_traced,
        stats.samples_offscreen,
        100.0 * share,
        cpu.replay,
        cpu.replay_ambiguous,
        cpu.centres,
        cpu.cell_all,
        cpu.cell_any,
    );
    assert_eq!(
        stats.samples_traced, samples,
        "one traced sample per kept texel"
    );
    assert_eq!(stats.primary_rays, samples);
    assert!(
        cpu.cell_all <= stats.samples_offscreen && stats.samples_offscreen <= cpu.cell_any,
        "off-screen count {} outside the jitter-independent bounds [{}, {}]",
        stats.samples_offscreen,
        cpu.cell_all,
        cpu.cell_any
    );
    assert!(
        stats.samples_offscreen.abs_diff(cpu.replay) <= cpu.replay_ambiguous,
        "off-screen count {} vs CPU replay of the kernel's jitter {} (± {} border cases)",
        stats.samples_offscreen,
        cpu.replay,
        cpu.replay_ambiguous
    );

    // G-buffer: clipped texels are written as "nothing" (zeros, motion −1); kept on-screen
    // texels of the closed Cornell box hit geometry.
    let color: Vec<[f32; 4]> = read_image(ctx, &r.view(0).gbuffer.color);
    let normal_depth: Vec<[f32; 4]> = read_image(ctx, &r.view(0).gbuffer.normal_depth);
    let ids: Vec<[u32; 2]> = read_image(ctx, &r.view(0).gbuffer.ids);
    let motion: Vec<[f32; 2]> = read_image(ctx, &r.view(0).gbuffer.motion);
    let (mut clipped, mut kept_on_screen, mut hits_on_screen) = (0u64, 0u64, 0u64);
    for y in 0..g.y {
        for x in 0..g.x {
            let i = (y * g.x + x) as usize;
            if vp.is_valid_texel(IVec2::new(x as i32, y as i32)) {
                if !offscreen(vp.vp_to_screen(Vec2::new(x as f32, y as f32) + 0.5)) {
                    kept_on_screen += 1;
                    hits_on_screen += (ids[i][0] != 0) as u64;
                }
                continue;
            }
            clipped += 1;
            assert_eq!(color[i], [0.0; 4], "colour at clipped texel ({x}, {y})");
            assert_eq!(
                normal_depth[i], [0.0; 4],
                "normal/depth at clipped texel ({x}, {y})"
            );
            assert_eq!(ids[i], [0, 0], "ids at clipped texel ({x}, {y})");
            assert_eq!(
                motion[i],
                [-1.0, -1.0],
                "motion at clipped texel ({x}, {y})"
            );
        }
    }
    assert_eq!(clipped, g.x as u64 * g.y as u64 - samples);
    assert!(clipped > 0, "the default 12 % clip removes texels");
    assert!(
        hits_on_screen as f64 > 0.9 * kept_on_screen as f64,
        "on-screen samples should see the Cornell box: {hits_on_screen} of {kept_on_screen} hit"
    );
    (share, cpu, stats.samples_traced)
}

#[test]
fn visual_polar_tracing_counts_samples_and_offscreen() {
    let ctx = gpu();
    let scene = cornell();
    let (centre, _, _) = check_vp_frame(
        &ctx,
        &scene,
        "centre",
        SCREEN.as_vec2() * 0.5,
        VpLayout::Paper,
    );
    let (corner, _, _) =
        check_vp_frame(&ctx, &scene, "corner", Vec2::new(2.0, 2.0), VpLayout::Paper);
    assert!(
        centre < 0.3 && 0.3 < corner,
        "off-screen share: centre {centre:.3}, corner {corner:.3}"
    );
    assert_clean(&ctx);
}

/// The screen-clipped layout and the screen-aware axis: the paper's sample count, and off the
/// screen only samples whose texel cell reaches past the border (no cell lies wholly off it), a
/// small share.
#[test]
fn screen_clipped_layout_keeps_samples_on_screen() {
    let ctx = gpu();
    let scene = cornell();
    let gazes = [
        ("centre", SCREEN.as_vec2() * 0.5),
        ("edge", Vec2::new(3.0, 90.0)),
        ("corner", Vec2::new(2.0, 2.0)),
    ];
    for (name, gaze) in gazes {
        let (paper_share, _, paper_traced) =
            check_vp_frame(&ctx, &scene, name, gaze, VpLayout::Paper);
        for layout in [VpLayout::ScreenClipped, VpLayout::ScreenAware] {
            let (share, cpu, traced) = check_vp_frame(&ctx, &scene, name, gaze, layout);
            println!(
                "gaze {name}: off-screen share paper {:.1} % → {layout:?} {:.2} %",
                100.0 * paper_share,
                100.0 * share
            );
            assert_eq!(
                traced, paper_traced,
                "gaze {name} {layout:?}: the same budget"
            );
            assert_eq!(
                cpu.centres, 0,
                "gaze {name} {layout:?}: texel centres lie on their arcs, on the screen"
            );
            assert_eq!(
                cpu.cell_all, 0,
                "gaze {name} {layout:?}: a texel cell wholly off the screen"
            );
            assert!(
                share < 0.03,
                "gaze {name} {layout:?}: {:.2} % off the screen",
                100.0 * share
            );
        }
    }
    assert_clean(&ctx);
}

/// The headset eccentricity axis (FOVE 0): the trace kernel places the samples where the Rust
/// mapping does (the off-screen count matches the CPU replay of the kernel's jitter), centre and
/// corner gaze.
#[test]
fn headset_axis_tracing_counts_samples_and_offscreen() {
    let ctx = gpu();
    let scene = cornell();
    let params = VisualPolarParams {
        eccentricity: Eccentricity::Headset(FovTangents::from_angles_deg(-45.0, 45.0, -48.4, 48.4)),
        ..Default::default()
    };
    let (centre, _, _) =
        check_vp_frame_with(&ctx, &scene, "centre", SCREEN.as_vec2() * 0.5, params);
    let (corner, _, _) = check_vp_frame_with(&ctx, &scene, "corner", Vec2::new(2.0, 2.0), params);
    assert!(
        centre < 0.3 && 0.3 < corner,
        "off-screen share: centre {centre:.3}, corner {corner:.3}"
    );
    assert_clean(&ctx);
}

/// Cartesian samples are the screen: nothing off-screen.
#[test]
fn cartesian_has_no_offscreen_samples() {
    let ctx = gpu();
    let scene = cornell();
    let (_r, stats) = render(&ctx, &scene, Box::new(Cartesian::new(SCREEN)));
    assert_eq!(stats.samples_traced, (SCREEN.x * SCREEN.y) as u64);
    assert_eq!(stats.samples_offscreen, 0);
    assert_clean(&ctx);
}

/// Off-screen culling (`OffscreenSamples::Cull`, the default): the spaces that place samples off
/// the screen (the paper's VP layout, log-polar with L from the diagonal, composite, random
/// acuity) trace only those the way back reads, so without a filter the picture is byte for byte
/// the one with every sample traced, gaze centred and in a corner; the skipped samples are
/// counted, none on a layout that keeps its samples on the screen. With SVGF the filter sees
/// culled texels as misses (no weight): the picture moves by well under one LDR level on average.
#[test]
fn offscreen_culling_keeps_the_picture_and_counts_what_it_skips() {
    use fovea_renderer::passes::denoise::DenoiserSettings;
    use fovea_renderer::sampling::{
        CompositeMode, LogPolarExtent, LogPolarParams, RadialLaw, RandomAcuity,
    };
    let ctx = gpu();
    let scene = cornell();
    let camera = fovea_tests::cornell_box_far_camera(SCREEN);
    let frames = |space: Box<dyn SamplingSpace>, gaze: Vec2, settings: RenderSettings| {
        let mut r = Renderer::new(&ctx, &scene, space, settings).unwrap();
        let (mut pictures, mut stats) = (Vec::new(), Vec::new());
        for f in 0..2 {
            stats.push(
                r.render_frame(&FrameInput::mono(camera, f, Some(gaze)))
                    .unwrap(),
            );
            let mut ldr = Vec::new();
            r.read_ldr(&mut ldr).unwrap();
            pictures.push(ldr);
        }
        (pictures, stats)
    };
    let cull = RenderSettings::default();
    let trace = RenderSettings {
        offscreen_samples: OffscreenSamples::Trace,
        ..cull
    };
    assert_eq!(cull.offscreen_samples, OffscreenSamples::Cull);
    let corner = Vec2::new(2.0, 2.0);
    for gaze in [SCREEN.as_vec2() * 0.5, corner] {
        let polar = move |radial| {
            VisualPolar::new(
                SCREEN,
                gaze,
                VisualPolarParams {
                    radial,
                    ..Default::default()
                },
            )
            .unwrap()
        };
        type Make = Box<dyn Fn() -> Box<dyn SamplingSpace>>;
        let spaces: [(&str, Make, bool); 6] = [
            (
                "vp",
                Box::new(move || Box::new(polar(RadialLaw::Acuity))),
                true,
            ),
            (
                "log-polar diagonal",
                Box::new(move || {
                    Box::new(polar(RadialLaw::LogPolar(LogPolarParams {
                        extent: LogPolarExtent::Diagonal,
                        ..Default::default()
                    })))
                }),
                true,
            ),
            (
                "composite",
                Box::new(move || {
                    Box::new(polar(RadialLaw::Composite(
                        CompositeMode::Composite.params(SCREEN.x as f32 / 2.0),
                    )))
                }),
                true,
            ),
            (
                "random-acuity",
                Box::new(move || {
                    Box::new(RandomAcuity::new(SCREEN, gaze, VisualPolarParams::default()).unwrap())
                }),
                true,
            ),
            (
                "vp-screen-clipped",
                Box::new(move || {
                    Box::new(
                        VisualPolar::new(
                            SCREEN,
                            gaze,
                            VisualPolarParams {
                                layout: VpLayout::ScreenClipped,
                                ..Default::default()
                            },
                        )
                        .unwrap(),
                    )
                }),
                false,
            ),
            (
                "cartesian",
                Box::new(|| Box::new(Cartesian::new(SCREEN))),
                false,
            ),
        ];
        for (name, make, places_offscreen) in spaces {
            let samples = make().sample_count();
            let (all, all_stats) = frames(make(), gaze, trace);
            let (culled, culled_stats) = frames(make(), gaze, cull);
            for (f, (a, c)) in all_stats.iter().zip(&culled_stats).enumerate() {
                println!("{name} gaze {gaze} frame {f}: traced {} of {samples} ({} off the screen); culled {} ({} traced off the screen)", a.samples_traced, a.samples_offscreen, c.samples_culled, c.samples_offscreen);
                assert_eq!(a.samples_culled, 0, "{name}: trace culls nothing");
                assert_eq!(
                    c.samples_traced + c.samples_culled,
                    a.samples_traced,
                    "{name} frame {f}: every sample traced or culled"
                );
                assert!(
                    c.samples_culled <= a.samples_offscreen,
                    "{name} frame {f}: only off-screen samples are culled"
                );
                if places_offscreen && gaze == corner {
                    assert!(
                        c.samples_culled > a.samples_traced / 2,
                        "{name} frame {f}: a corner gaze culls most of the circle"
                    );
                }
                if !places_offscreen {
                    assert_eq!(c.samples_culled, 0, "{name}: its samples are on the screen");
                }
            }
            assert!(
                all == culled,
                "{name} gaze {gaze}: culling changed the picture"
            );
        }
    }
    // A filter: culled texels are misses to it.
    let vp = VisualPolar::new(SCREEN, corner, VisualPolarParams::default()).unwrap();
    let svgf = DenoiserSettings::parse("svgf").unwrap();
    let (all, _) = frames(
        Box::new(vp),
        corner,
        RenderSettings {
            denoiser: svgf,
            ..trace
        },
    );
    let (culled, _) = frames(
        Box::new(vp),
        corner,
        RenderSettings {
            denoiser: svgf,
            ..cull
        },
    );
    let mean_diff = all[1]
        .iter()
        .zip(&culled[1])
        .map(|(a, b)| a.abs_diff(*b) as f64)
        .sum::<f64>()
        / all[1].len() as f64;
    println!(
        "SVGF, corner gaze: culling moves the picture by {mean_diff:.4} LDR levels on average"
    );
    assert!(
        mean_diff < 0.05,
        "SVGF: culling moved the picture by {mean_diff} levels on average"
    );
    assert_clean(&ctx);
}
