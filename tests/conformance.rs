//! One conformance suite for every filter × every sampling space (it catches, for example, a trace
//! kernel variant that was never built): each space that supports the temporal filters (its
//! `SpaceCapabilities`) runs SVGF, A-SVGF, BMFR and both TAA
//! modes without validation messages, with finite non-negative output, reducing the noise against
//! the space's own converged image, and rejecting its history when the camera jumps
//! (disocclusion), keeping its output finite when the light blows up to Inf and exactly black on an
//! empty view, and (polar spaces) filtering across the φ seam like any other angle; each space that
//! does not refuses every filter by name. Adding a space means adding it to `spaces()`, not
//! copying these tests.

use fovea_renderer::frame::{CameraPose, FrameInput, RenderSettings};
use fovea_renderer::graph::FrameRecorder;
use fovea_renderer::passes::denoise::{Denoiser, DenoiserSettings};
use fovea_renderer::passes::grid::{GBuffer, GridFrame};
use fovea_renderer::passes::taa::Taa;
use fovea_renderer::passes::taa::{TaaMode, TaaSettings};
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::{
    BlockShape, Cartesian, CompositeMode, Eccentricity, FalloffShape, FixedFoveation,
    LinearFalloff, LogPolarParams, PixelBlocks, RadialLaw, RandomAcuity, SamplingSpace,
    UniformBudget, VisualPolar, VisualPolarParams, VpLayout, VrsTiles, FALLOFF_BUDGET_OF_VP,
};
use fovea_renderer::vk::{Context, Image};
use fovea_renderer::way_back::blur::BlurSettings;
use fovea_tests::denoise::{
    assert_finite_non_negative, plain_materials, rmse_where, seam_texels, seam_truth, upload,
    upload_gbuffer, SeamErrors,
};
use fovea_tests::{
    assert_clean, failure_message, gpu, light_material, owned_scene, read_image, Picture,
    SpaceBuffers,
};
use glam::{Mat4, UVec2};
use std::sync::Arc;

const SIZE: UVec2 = UVec2::new(96, 108);
const CONVERGED_FRAMES: u32 = 96;
const FILTERED_FRAMES: u32 = 12;

/// Makes a fresh space (a renderer owns the one it gets).
type MakeSpace = Box<dyn Fn() -> Box<dyn SamplingSpace>>;

/// Every space of the product at `size`, gaze at the centre.
fn spaces(size: UVec2) -> Vec<(&'static str, MakeSpace)> {
    let gaze = size.as_vec2() * 0.5;
    let vp = VisualPolarParams::default();
    let fove0 = fovea_tools::commands::bench_vp::fove0_fov().unwrap();
    let polar = move |radial| {
        VisualPolar::new(
            size,
            gaze,
            VisualPolarParams {
                radial,
                ..Default::default()
            },
        )
        .unwrap()
    };
    vec![
        (
            "cartesian",
            Box::new(move || Box::new(Cartesian::new(size))),
        ),
        (
            "vp",
            Box::new(move || Box::new(VisualPolar::new(size, gaze, vp).unwrap())),
        ),
        (
            "log-polar",
            Box::new(move || Box::new(polar(RadialLaw::LogPolar(LogPolarParams::default())))),
        ),
        (
            "composite",
            Box::new(move || {
                Box::new(polar(RadialLaw::Composite(
                    CompositeMode::Composite.params(size.x as f32 / 2.0),
                )))
            }),
        ),
        (
            "vp-headset",
            Box::new(move || {
                Box::new(
                    VisualPolar::new(
                        size,
                        gaze,
                        VisualPolarParams {
                            eccentricity: Eccentricity::Headset(fove0),
                            ..vp
                        },
                    )
                    .unwrap(),
                )
            }),
        ),
        (
            "vp-screen-clipped",
            Box::new(move || {
                Box::new(
                    VisualPolar::new(
                        size,
                        gaze,
                        VisualPolarParams {
                            layout: VpLayout::ScreenClipped,
                            ..vp
                        },
                    )
                    .unwrap(),
                )
            }),
        ),
        (
            "vp-screen-aware",
            Box::new(move || {
                Box::new(
                    VisualPolar::new(
                        size,
                        gaze,
                        VisualPolarParams {
                            layout: VpLayout::ScreenAware,
                            ..vp
                        },
                    )
                    .unwrap(),
                )
            }),
        ),
        (
            "uniform-budget",
            Box::new(move || Box::new(UniformBudget::with_samples(size, 4000).unwrap())),
        ),
        (
            "linear-falloff",
            Box::new(move || {
                Box::new(
                    LinearFalloff::new(size, vp, FalloffShape::default(), FALLOFF_BUDGET_OF_VP)
                        .unwrap(),
                )
            }),
        ),
        (
            "random-acuity",
            Box::new(move || Box::new(RandomAcuity::new(size, gaze, vp).unwrap())),
        ),
        (
            "pixel-blocks",
            Box::new(move || Box::new(PixelBlocks::new(size, vp, BlockShape::default()).unwrap())),
        ),
        (
            "vrs-tiles",
            Box::new(move || Box::new(VrsTiles::new(size, gaze, vp).unwrap())),
        ),
        // The lens centre a quarter of the way in: the filters run on a grid centred off the gaze.
        (
            "fixed-foveation",
            Box::new(move || {
                Box::new(FixedFoveation::new(size, size.as_vec2() * 0.25, vp).unwrap())
            }),
        ),
    ]
}

fn filters() -> Vec<(&'static str, DenoiserSettings, TaaMode)> {
    let taa = TaaSettings::default();
    vec![
        (
            "svgf",
            DenoiserSettings::parse("svgf").unwrap(),
            TaaMode::Off,
        ),
        (
            "asvgf",
            DenoiserSettings::parse("asvgf").unwrap(),
            TaaMode::Off,
        ),
        (
            "bmfr",
            DenoiserSettings::parse("bmfr").unwrap(),
            TaaMode::Off,
        ),
        ("taa-vp", DenoiserSettings::None, TaaMode::SamplingGrid(taa)),
        ("taa-screen", DenoiserSettings::None, TaaMode::Screen(taa)),
    ]
}

/// The blur is off: the suite measures sampling and filtering only.
fn settings(denoiser: DenoiserSettings, taa: TaaMode) -> RenderSettings {
    RenderSettings {
        blur: BlurSettings {
            sigma_at_30: 0.0,
            ..Default::default()
        },
        denoiser,
        taa,
        ..Default::default()
    }
}

/// The mean of `frames` raw frames of a space at `camera` (after its way back), and the last.
fn converged(
    renderer: &mut Renderer,
    camera: CameraPose,
    frames: u32,
) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let (mut raw, mut mean) = (Vec::new(), vec![[0.0f32; 4]; (SIZE.x * SIZE.y) as usize]);
    for f in (0..frames).rev() {
        renderer
            .render_frame(&FrameInput::mono(camera, f, Some(SIZE.as_vec2() * 0.5)).with_hdr(true))
            .unwrap();
        renderer.read_hdr(&mut raw).unwrap();
        for (m, p) in mean.iter_mut().zip(&raw) {
            (0..4).for_each(|c| m[c] += p[c] / frames as f32);
        }
    }
    (mean, raw)
}

/// Screen pixels inside a surface of a converged image, the same for every filter: not an
/// emitter, and every 8-neighbour's luminance within 10 % (edges, where a coarse grid's remap and
/// a filter may legitimately differ from the mean of raw frames, are left out).
fn smooth_interior(converged: &[[f32; 4]]) -> Vec<bool> {
    let luma = |p: &[f32; 4]| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    let (w, h) = (SIZE.x as i32, SIZE.y as i32);
    (0..h * w)
        .map(|i| {
            let (x, y, l) = (i % w, i / w, luma(&converged[i as usize]));
            let inside = x > 0 && y > 0 && x + 1 < w && y + 1 < h && l < 1.0;
            inside
                && (-1..=1).all(|dy| {
                    (-1..=1).all(|dx| {
                        (luma(&converged[((y + dy) * w + x + dx) as usize]) - l).abs()
                            <= 0.1 * l.max(0.05)
                    })
                })
        })
        .collect()
}

/// Fireflies through the whole frame: the light scaled by 1e30 for two frames (radiance that
/// overflows to Inf in the tracer and saturates moments, fits and histories) between normal
/// frames, so the filter sees the jump both ways — every output pixel finite and non-negative;
/// then the camera turned out of the box: two frames exactly black (no history ghosts into
/// an empty view).
fn blow_up_the_light_and_look_away(
    r: &mut Renderer,
    scene: &fovea_scene::Scene,
    (camera, away): (CameraPose, CameraPose),
    first: u32,
    what: &str,
) {
    let light = light_material(scene);
    let mut out = Vec::new();
    for (k, scale) in [1e30, 1e30, 1.0, 1.0].into_iter().enumerate() {
        r.set_emission_scale(scene, light, scale).unwrap();
        r.render_frame(
            &FrameInput::mono(camera, first + k as u32, Some(SIZE.as_vec2() * 0.5)).with_hdr(true),
        )
        .unwrap();
        r.read_hdr(&mut out).unwrap();
        assert_finite_non_negative(&format!("{what}, light ×{scale:e}, frame {k}"), &out);
    }
    for k in 4..6 {
        r.render_frame(
            &FrameInput::mono(away, first + k, Some(SIZE.as_vec2() * 0.5)).with_hdr(true),
        )
        .unwrap();
        r.read_hdr(&mut out).unwrap();
        assert!(
            out.iter().all(|p| p[..3] == [0.0; 3]),
            "{what}: the empty view is not black (frame {k})"
        );
    }
}

/// Noise: 12 filtered frames against the raw one-sample frame, both against the space's own
/// converged image on its smooth interiors; bound 1.15× (measured 2026-12-02: Cartesian
/// 3.5–5.5×; the polar spaces' SVGF, A-SVGF and BMFR 1.19–1.9×, A-SVGF the least (its gradients
/// reset the history where the 1-sample noise looks like change) — at 96×108 their grids are
/// coarse and the spatial filters' smoothing of the periphery is a bias the mean of raw frames
/// lacks — and their TAA 3.0–3.8×; a filter that does nothing measures 1.0×). Disocclusion: after those
/// frames the camera jumps 20° around the box's centre; the first frame there must be no worse than
/// 1.5× the raw frame against that view's converged image (history carried over would ghost
/// the old view into it).
#[test]
fn every_filter_on_every_space_that_supports_it() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let start = CameraPose::from_scene_camera(&scene.cameras[0], SIZE.x, SIZE.y);
    let centre = scene.bounds().center();
    let turn = Mat4::from_translation(centre)
        * Mat4::from_rotation_y(20f32.to_radians())
        * Mat4::from_translation(-centre);
    let jumped = CameraPose {
        world_from_view: turn * start.world_from_view,
        fov_tan: start.fov_tan,
    };
    // Turned around, the camera looks out of the box's open side into nothing.
    let away = CameraPose {
        world_from_view: start.world_from_view * Mat4::from_rotation_y(std::f32::consts::PI),
        ..start
    };
    let gaze = Some(SIZE.as_vec2() * 0.5);
    let mut failures = Vec::new();
    for (space_name, make) in spaces(SIZE) {
        if !make().capabilities().temporal_filters {
            for (filter, denoiser, taa) in filters() {
                let err = Renderer::new(&ctx, &scene, make(), settings(denoiser, taa))
                    .err()
                    .map(|e| e.to_string())
                    .unwrap_or_default();
                assert!(
                    err.contains(space_name) && err.contains("supports no denoiser"),
                    "{space_name} + {filter}: {err}"
                );
            }
            continue;
        }
        let mut raw_renderer = Renderer::new(
            &ctx,
            &scene,
            make(),
            settings(DenoiserSettings::None, TaaMode::Off),
        )
        .unwrap();
        let (reference, raw) = converged(&mut raw_renderer, start, CONVERGED_FRAMES);
        let (jumped_reference, jumped_raw) =
            converged(&mut raw_renderer, jumped, CONVERGED_FRAMES / 2);
        drop(raw_renderer);
        let (interior, jumped_interior) = (
            smooth_interior(&reference),
            smooth_interior(&jumped_reference),
        );
        for (filter, denoiser, taa) in filters() {
            let mut r = Renderer::new(&ctx, &scene, make(), settings(denoiser, taa)).unwrap();
            let mut out = Vec::new();
            for f in 0..FILTERED_FRAMES {
                r.render_frame(&FrameInput::mono(start, f, gaze).with_hdr(true))
                    .unwrap();
            }
            r.read_hdr(&mut out).unwrap();
            assert_finite_non_negative(&format!("{space_name} + {filter}"), &out);
            let (before, after) = (
                rmse_where(&raw, &reference, |i| interior[i]),
                rmse_where(&out, &reference, |i| interior[i]),
            );
            let filtered = out.clone();
            r.render_frame(&FrameInput::mono(jumped, FILTERED_FRAMES, gaze).with_hdr(true))
                .unwrap();
            r.read_hdr(&mut out).unwrap();
            assert_finite_non_negative(&format!("{space_name} + {filter} after the jump"), &out);
            let (raw_jump, filtered_jump) = (
                rmse_where(&jumped_raw, &jumped_reference, |i| jumped_interior[i]),
                rmse_where(&out, &jumped_reference, |i| jumped_interior[i]),
            );
            println!(
                "{space_name} + {filter}: noise {before:.4} → {after:.4} ({:.2}×); after the jump {filtered_jump:.4} vs raw {raw_jump:.4}",
                before / after
            );
            let picture = |texels| Picture::hdr(SIZE.x, SIZE.y, texels);
            if before / after < 1.15 {
                failures.push(failure_message(
                    &format!("{space_name} + {filter}"),
                    &picture(&filtered),
                    &picture(&reference),
                    format_args!(
                        "{space_name} + {filter}: RMSE fell only {:.2}× ({before:.4} → {after:.4})",
                        before / after
                    ),
                ));
            }
            if filtered_jump > 1.5 * raw_jump {
                failures.push(failure_message(
                    &format!("{space_name} + {filter} after the jump"),
                    &picture(&out),
                    &picture(&jumped_reference),
                    format_args!("{space_name} + {filter}: the first frame after the jump {filtered_jump:.4} vs raw {raw_jump:.4}"),
                ));
            }
            blow_up_the_light_and_look_away(
                &mut r,
                &scene,
                (jumped, away),
                FILTERED_FRAMES + 1,
                &format!("{space_name} + {filter}"),
            );
            assert_clean(&ctx);
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// One grid filter run on its own over a synthetic G-buffer (the seam test's), as the renderer
/// records it: a denoiser (A-SVGF's forward projection first) or TAA in the grid.
enum GridFilter {
    Denoiser(Box<dyn Denoiser>),
    Taa(Box<Taa>),
}

impl GridFilter {
    fn new(
        ctx: &Arc<Context>,
        denoiser: &DenoiserSettings,
        taa: TaaMode,
        space: &dyn SamplingSpace,
    ) -> GridFilter {
        let (grid, variant) = (space.grid_size(), space.shader_variant());
        match (denoiser.build(ctx, grid, variant).unwrap(), taa) {
            (Some(d), _) => GridFilter::Denoiser(d),
            (None, TaaMode::SamplingGrid(s)) => {
                GridFilter::Taa(Box::new(Taa::new(ctx, grid, variant, s).unwrap()))
            }
            (None, other) => panic!("no grid filter for TAA {other:?}"),
        }
    }

    fn run(&mut self, ctx: &Arc<Context>, frame: &GridFrame) -> Vec<[f32; 4]> {
        let mut rec = FrameRecorder::new(ctx, 32).unwrap();
        rec.begin().unwrap();
        let out: &Image = match self {
            GridFilter::Denoiser(d) => {
                d.record_before_trace(&mut rec, frame).unwrap();
                d.record(&mut rec, frame).unwrap()
            }
            GridFilter::Taa(t) => {
                let color = &frame.gbuffer.color;
                t.record(&mut rec, color, frame, glam::Vec2::splat(0.5))
                    .unwrap()
            }
        };
        rec.submit_and_wait().unwrap();
        read_image(ctx, out)
    }
}

/// The φ seam, every grid filter on every polar space that runs them: radiance 0.5 + 0.3·sin φ
/// plus noise on one face-on plane (`seam_texels`, 128×144). Rows at the seam (φ ≈ 0, rows 0 and
/// n − 1) sit on a zero crossing exactly like the rows at φ ≈ π; a filter (or a TAA neighbourhood
/// clamp, or a BMFR block) that did not wrap would see one side of the slope only there. After 8
/// frames the seam's error must be like the other angles' (`SeamErrors::like_elsewhere`).
/// Screen-space TAA runs after the remap, where there is no seam.
#[test]
fn every_grid_filter_filters_the_phi_seam_like_any_other_angle() {
    const SEAM_SIZE: UVec2 = UVec2::new(128, 144);
    let ctx = gpu();
    let materials = plain_materials(&ctx);
    let mut failures = Vec::new();
    for (space_name, make) in spaces(SEAM_SIZE) {
        let space = make();
        // The polar spaces that run the filters have a seam.
        let Some(&vp) = space
            .visual_polar()
            .filter(|_| space.capabilities().temporal_filters)
        else {
            continue;
        };
        let grid = space.grid_size();
        // A-SVGF projects its gradient samples from last frame's visibility: none here (zero),
        // so it filters like SVGF with the adaptive α.
        let g = GBuffer::with_visibility(&ctx, grid).unwrap();
        upload(
            &ctx,
            g.visibility.as_ref().unwrap(),
            &vec![[0u32; 4]; (grid.x * grid.y) as usize],
        );
        let buffers = SpaceBuffers::new(&ctx, space.as_ref(), 0, 1);
        let params = space.params();
        for (filter, denoiser, taa) in filters()
            .into_iter()
            .filter(|(_, _, taa)| !matches!(taa, TaaMode::Screen(_)))
        {
            let mut f = GridFilter::new(&ctx, &denoiser, taa, space.as_ref());
            let mut out = Vec::new();
            for frame in 0..8u32 {
                upload_gbuffer(&ctx, &g, &seam_texels(&vp, frame));
                let previous = (frame > 0).then_some(params);
                out = f.run(
                    &ctx,
                    &buffers.grid_frame(&g, (params, previous), &materials),
                );
            }
            assert_finite_non_negative(&format!("{space_name} + {filter} at the seam"), &out);
            let e = SeamErrors::of(&vp, &out);
            println!("{space_name} + {filter}: seam rows RMSE {:.4}, at φ ≈ π {:.4}, median row bin {:.4}; per bin {:.4?}", e.seam, e.opposite, e.median, e.bins);
            if !e.like_elsewhere() {
                let truth: Vec<[f32; 4]> = (0..grid.x * grid.y)
                    .map(|i| {
                        let t = seam_truth(&vp, i % grid.x, i / grid.x);
                        [t, t, t, 1.0]
                    })
                    .collect();
                failures.push(failure_message(
                    &format!("{space_name} + {filter} at the seam"),
                    &Picture::hdr(grid.x, grid.y, &out),
                    &Picture::hdr(grid.x, grid.y, &truth),
                    format_args!(
                        "{space_name} + {filter}: seam {:.4} vs {:.4} at φ ≈ π, median {:.4}",
                        e.seam, e.opposite, e.median
                    ),
                ));
            }
            assert_clean(&ctx);
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The screen-clipped layout and the screen-aware axis under a moving gaze, every grid filter:
/// each frame the gaze moves (edge → corner → centre), so every column's on-screen arcs (and the
/// screen-aware axis' knots) change and the history must be found through the previous frame's
/// (the second half of `DenoiseFrame::sampling_table`).
/// One face-on plane, static camera, radiance a smooth screen pattern plus noise. Each filter must
/// reduce the noise (≥ 1.15×), stay below a run whose previous-frame half repeats this frame's
/// arcs — which reprojects the history to the wrong texels wherever a column is clipped (< 0.9×;
/// measured SVGF / A-SVGF 0.17, TAA 0.22, BMFR 0.79: its per-frame fit leans least on history) —
/// and be no worse than the paper layout's under the same gaze path (≤ 1.15×; same grid and
/// filter, full circles).
#[test]
fn every_grid_filter_follows_a_moving_gaze_through_the_previous_frames_arcs() {
    const CLIP_SIZE: UVec2 = UVec2::new(128, 144);
    const FRAMES: u32 = 8;
    let ctx = gpu();
    let materials = plain_materials(&ctx);
    let gaze = |f: u32| {
        let path = [
            glam::Vec2::new(12.0, 70.0),
            glam::Vec2::new(110.0, 130.0),
            glam::Vec2::new(64.0, 72.0),
        ];
        let t = f as f32 / (FRAMES - 1) as f32 * 2.0;
        let (i, u) = ((t.floor() as usize).min(1), t - t.floor().min(1.0));
        path[i].lerp(path[i + 1], u)
    };
    let space = |layout: VpLayout, f: u32| {
        VisualPolar::new(
            CLIP_SIZE,
            gaze(f),
            VisualPolarParams {
                layout,
                ..Default::default()
            },
        )
        .unwrap()
    };
    // About one period across the screen: BMFR's per-block fit of position features follows it
    // (a pattern of a few pixels' period is fitted worse than the noise in either layout).
    let truth = |s: glam::Vec2| 0.5 + 0.3 * (s.x / 27.0).sin() * (s.y / 33.0).cos();
    let texels = |vp: &VisualPolar, f: u32| -> Vec<Option<fovea_tests::denoise::Texel>> {
        let centre = CLIP_SIZE.as_vec2() * 0.5;
        fovea_tests::denoise::texel_screens(vp)
            .iter()
            .enumerate()
            .map(|(i, s)| {
                s.map(|s| {
                    let p = (s - centre) / 64.0 * 5.0;
                    let v =
                        truth(s) + 0.2 * (fovea_tests::unit_hash(i as u32 * 31 + f * 7919) - 0.5);
                    fovea_tests::denoise::Texel {
                        radiance: [v; 3],
                        normal: [0.0, 0.0, 1.0],
                        position: [p.x, p.y, -5.0],
                        mesh: 1,
                        motion: s,
                    }
                })
            })
            .collect()
    };
    let error = |vp: &VisualPolar, values: &dyn Fn(usize) -> f32| {
        let screens = fovea_tests::denoise::texel_screens(vp);
        let e: Vec<f64> = screens
            .iter()
            .enumerate()
            .filter_map(|(i, s)| s.map(|s| (values(i) - truth(s)) as f64))
            .collect();
        (e.iter().map(|v| v * v).sum::<f64>() / e.len() as f64).sqrt()
    };
    let grid = space(VpLayout::ScreenClipped, 0).grid_size();
    assert_eq!(grid, space(VpLayout::Paper, 0).grid_size());
    assert_eq!(grid, space(VpLayout::ScreenAware, 0).grid_size());
    let g = GBuffer::with_visibility(&ctx, grid).unwrap();
    upload(
        &ctx,
        g.visibility.as_ref().unwrap(),
        &vec![[0u32; 4]; (grid.x * grid.y) as usize],
    );
    let mut failures = Vec::new();
    // (layout, the previous frame's own arcs in the table's second half); the paper layout last.
    let runs = [
        (VpLayout::ScreenClipped, true),
        (VpLayout::ScreenClipped, false),
        (VpLayout::ScreenAware, true),
        (VpLayout::ScreenAware, false),
        (VpLayout::Paper, true),
    ];
    for (filter, denoiser, taa) in filters()
        .into_iter()
        .filter(|(_, _, taa)| !matches!(taa, TaaMode::Screen(_)))
    {
        let mut errors = [0.0; 5];
        let mut noise = [0.0; 5];
        for (run, &(layout, previous_arcs)) in runs.iter().enumerate() {
            let mut f = GridFilter::new(&ctx, &denoiser, taa, &space(layout, 0));
            for frame in 0..FRAMES {
                let (vp, prev) = (space(layout, frame), space(layout, frame.saturating_sub(1)));
                let input = texels(&vp, frame);
                upload_gbuffer(&ctx, &g, &input);
                let buffers = SpaceBuffers::new(&ctx, &vp, frame, 1);
                let table = fovea_tests::grid_table(
                    &ctx,
                    &vp,
                    previous_arcs.then_some(&prev as &dyn SamplingSpace),
                );
                let sequence = (
                    vp.sampling_params(),
                    (frame > 0).then(|| prev.sampling_params()),
                );
                let frame_in = GridFrame {
                    sampling_table: &table,
                    ..buffers.grid_frame(&g, sequence, &materials)
                };
                let out = f.run(&ctx, &frame_in);
                if frame == FRAMES - 1 {
                    assert_finite_non_negative(&format!("{layout:?} + {filter}"), &out);
                    errors[run] = error(&vp, &|i| out[i][1]);
                    noise[run] = error(&vp, &|i| input[i].as_ref().map_or(0.0, |t| t.radiance[1]));
                }
            }
            assert_clean(&ctx);
        }
        let paper = errors[4];
        for (k, name) in [(0, "screen-clipped"), (2, "screen-aware")] {
            let (noise, right, wrong) = (noise[k], errors[k], errors[k + 1]);
            println!("{name} + {filter}, moving gaze: noise {noise:.4} → {right:.4}; with this frame's arcs as the previous frame's {wrong:.4}; paper layout {paper:.4}");
            if right > noise / 1.15 || right > 0.9 * wrong || right > 1.15 * paper {
                failures.push(format!("{name} + {filter}: {noise:.4} → {right:.4} (previous arcs ignored: {wrong:.4}, paper layout: {paper:.4})"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// ReSTIR DI and GI (`--resampling di`, `di+gi`) on every space whose grid runs the temporal
/// filters (their reuse addresses the grid as they do: φ wraps, clipped texels hold nothing, the
/// previous gaze's grid for the temporal step): no validation message, every pixel finite and
/// non-negative, the mean over frames like next-event estimation's, and BMFR and A-SVGF after
/// it; every other space refuses them by name.
#[test]
fn resampling_on_every_space_that_supports_it() {
    use fovea_renderer::passes::resampling::{ResamplingMode, ResamplingSettings};
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let start = CameraPose::from_scene_camera(&scene.cameras[0], SIZE.x, SIZE.y);
    let gaze = SIZE.as_vec2() * 0.5;
    let with = |mode: ResamplingMode, settings: RenderSettings| RenderSettings {
        resampling: ResamplingSettings::default().with_mode(mode),
        ..settings
    };
    let modes = [ResamplingMode::Di, ResamplingMode::DiGi];
    let plain = settings(DenoiserSettings::None, TaaMode::Off);
    let refusal = |make: &MakeSpace, settings: RenderSettings| {
        Renderer::new(&ctx, &scene, make(), settings)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    };
    for (space_name, make) in spaces(SIZE) {
        if !make().capabilities().temporal_filters {
            for mode in modes {
                let err = refusal(&make, with(mode, plain));
                assert!(
                    err.contains(space_name) && err.contains("resampling"),
                    "{space_name} + resampling {}: {err}",
                    mode.name()
                );
            }
            continue;
        }
        let check = |what: &str| {
            let what = what.to_string();
            move |f: u32, hdr: &[[f32; 4]]| {
                assert_finite_non_negative(&format!("{space_name} + {what}, frame {f}"), hdr)
            }
        };
        let frames = 24;
        let mut r = Renderer::new(&ctx, &scene, make(), plain).unwrap();
        let off = fovea_tests::mean_over_frames(&mut r, start, Some(gaze), frames, check("nee"));
        for mode in modes {
            let name = mode.name();
            let mut r = Renderer::new(&ctx, &scene, make(), with(mode, plain)).unwrap();
            let mean =
                fovea_tests::mean_over_frames(&mut r, start, Some(gaze), frames, check(name));
            println!(
                "{space_name}: mean of {frames} frames, resampling {name} {mean:?} vs off {off:?}"
            );
            for c in 0..3 {
                assert!(
                    (mean[c] / off[c] - 1.0).abs() < 0.02,
                    "{space_name}: channel {c}, resampling {name} {} vs off {}",
                    mean[c],
                    off[c]
                );
            }
        }
        let bmfr = settings(DenoiserSettings::parse("bmfr").unwrap(), TaaMode::Off);
        let mut r = Renderer::new(&ctx, &scene, make(), with(ResamplingMode::DiGi, bmfr)).unwrap();
        fovea_tests::mean_over_frames(&mut r, start, Some(gaze), 4, check("di+gi + bmfr"));
        let asvgf = settings(DenoiserSettings::parse("asvgf").unwrap(), TaaMode::Off);
        for mode in modes {
            let what = format!("{} + asvgf", mode.name());
            let mut r = Renderer::new(&ctx, &scene, make(), with(mode, asvgf)).unwrap();
            fovea_tests::mean_over_frames(&mut r, start, Some(gaze), 4, check(&what));
        }
        assert_clean(&ctx);
    }
}

/// Cross-eye reuse (`--cross-eye-reuse on`) on every space whose grid runs the temporal filters
/// (it finds the other eye's sample through the other eye's grid as they address it): both eyes
/// 63 mm apart with independent noise, no validation message, every pixel finite and
/// non-negative, each eye's mean over frames like each eye's own without it (the Cornell box is
/// diffuse: both eyes' samples of a surface estimate one radiance) and each pixel's variance over
/// the frames lower (the other eye's sample was found and taken), and with SVGF and BMFR after
/// it, and A-SVGF (its gradients compare the tracer's own estimates, which the merge leaves
/// alone); every other space refuses it by name.
#[test]
fn cross_eye_reuse_on_every_space_that_supports_it() {
    use fovea_renderer::frame::{CrossEyeReuse, ViewInput};
    use glam::Vec3;
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let head = CameraPose::from_scene_camera(&scene.cameras[0], SIZE.x, SIZE.y);
    let eyes = [-0.0315, 0.0315].map(|dx| ViewInput {
        camera: CameraPose {
            world_from_view: head.world_from_view * Mat4::from_translation(Vec3::new(dx, 0.0, 0.0)),
            fov_tan: head.fov_tan,
        },
        gaze: Some(SIZE.as_vec2() * 0.5),
    });
    let stereo = |make: &MakeSpace, settings: RenderSettings| {
        let gpu_scene = fovea_renderer::gpu_scene::GpuScene::upload(&ctx, &scene).unwrap();
        Renderer::with_views(&ctx, gpu_scene, vec![make(), make()], settings, 1)
    };
    let with = |reuse, settings: RenderSettings| RenderSettings {
        cross_eye_reuse: reuse,
        ..settings
    };
    let with_reuse = |settings| with(CrossEyeReuse::On, settings);
    let plain = RenderSettings {
        stereo_noise: fovea_renderer::frame::StereoNoise::Independent,
        ..settings(DenoiserSettings::None, TaaMode::Off)
    };
    let frames = 12;
    // Each eye's mean colour over `frames` frames and the median over its pixels of the variance
    // of their luminance over the frames (the median: the light's rim, where a pixel's jitter
    // crosses from the emitter to the ceiling, varies by orders of magnitude more than noise),
    // every frame checked.
    let means = |r: &mut Renderer, what: &str| {
        let mut sum = [[0.0f64; 3]; 2];
        let n = (SIZE.x * SIZE.y) as usize;
        let mut moments = [vec![(0.0f64, 0.0f64); n], vec![(0.0f64, 0.0f64); n]];
        let mut hdr = Vec::new();
        for f in 0..frames {
            let input = FrameInput::views(&eyes, f).unwrap().with_hdr(true);
            let frame = r.submit(&input, None).unwrap();
            r.wait_frame(frame).unwrap();
            for (eye, eye_sum) in sum.iter_mut().enumerate() {
                r.read_view_hdr(frame, eye, &mut hdr).unwrap();
                assert_finite_non_negative(&format!("{what}, eye {eye}, frame {f}"), &hdr);
                let m = fovea_tests::mean_rgb(&hdr);
                (0..3).for_each(|c| eye_sum[c] += m[c] / frames as f64);
                for (p, px) in moments[eye].iter_mut().zip(&hdr) {
                    let l = (0.2126 * px[0] + 0.7152 * px[1] + 0.0722 * px[2]) as f64;
                    *p = (p.0 + l, p.1 + l * l);
                }
            }
        }
        let k = frames as f64;
        let variance = moments.map(|eye| {
            let mut v: Vec<f64> = eye
                .iter()
                .map(|(s, s2)| (s2 / k - (s / k).powi(2)).max(0.0))
                .collect();
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        });
        (sum, variance)
    };
    for (space_name, make) in spaces(SIZE) {
        if !make().capabilities().temporal_filters {
            let err = stereo(&make, with_reuse(plain))
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default();
            assert!(
                err.contains(space_name) && err.contains("cross-eye"),
                "{space_name} + cross-eye reuse: {err}"
            );
            let auto = stereo(&make, with(CrossEyeReuse::Auto, plain)).unwrap();
            assert!(!auto.reuses_across_eyes(), "{space_name} + auto");
            continue;
        }
        let asvgf = settings(DenoiserSettings::parse("asvgf").unwrap(), TaaMode::Off);
        let auto = |settings| stereo(&make, with(CrossEyeReuse::Auto, settings)).unwrap();
        assert!(auto(asvgf).reuses_across_eyes(), "{space_name} + asvgf");
        assert!(auto(plain).reuses_across_eyes(), "{space_name}");
        let (off, off_variance) = means(&mut stereo(&make, plain).unwrap(), space_name);
        let (on, on_variance) = means(
            &mut stereo(&make, with_reuse(plain)).unwrap(),
            &format!("{space_name} + cross-eye"),
        );
        println!("{space_name}: mean of {frames} frames per eye, cross-eye reuse {on:?} vs off {off:?}; pixel variance {on_variance:?} vs {off_variance:?}");
        for eye in 0..2 {
            // Where both eyes see a surface each pixel averages two independent samples: about
            // half the variance.
            assert!(
                on_variance[eye] < 0.7 * off_variance[eye],
                "{space_name}: eye {eye}, pixel variance with cross-eye reuse {} vs off {}",
                on_variance[eye],
                off_variance[eye]
            );
            for c in 0..3 {
                assert!(
                    (on[eye][c] / off[eye][c] - 1.0).abs() < 0.02,
                    "{space_name}: eye {eye}, channel {c}, cross-eye {} vs off {}",
                    on[eye][c],
                    off[eye][c]
                );
            }
        }
        for denoiser in ["svgf", "asvgf", "bmfr"] {
            let filtered = settings(DenoiserSettings::parse(denoiser).unwrap(), TaaMode::Off);
            let mut r = stereo(&make, with_reuse(filtered)).unwrap();
            means(&mut r, &format!("{space_name} + cross-eye + {denoiser}"));
        }
        assert_clean(&ctx);
    }
}
