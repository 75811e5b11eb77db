//! Denoisers in the sampling grid: SVGF in Cartesian and Visual-Polar space.
//! Noise reduction against a converged reference on the Cornell box (whole frame, fovea and
//! eccentricity rings, after the remap for VP); no NaN/Inf/negative output with fireflies, NaNs
//! and an empty view; no history across a disocclusion (synthetic G-buffers with a moving
//! occluder); the `--denoiser` flag end to end (the φ seam: tests/conformance.rs, every filter).
//! TAA in the sampling grid (Karis 2014): noise and edge aliasing reduced against the reference,
//! fireflies, disocclusion resets, the tracer's Halton jitter, the `--taa` flag.

use fovea_renderer::frame::{CameraPose, FrameInput, RenderSettings};
use fovea_renderer::graph::FrameRecorder;
use fovea_renderer::passes::denoise::svgf::{Svgf, SvgfSettings};
use fovea_renderer::passes::denoise::DenoiserSettings;
use fovea_renderer::passes::grid::GBuffer;
use fovea_renderer::passes::grid::GridFrame;
use fovea_renderer::passes::taa::{Taa, TaaMode, TaaSettings};
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::{Cartesian, SamplingSpace, VisualPolar, VisualPolarParams};
use fovea_renderer::vk::{Context, Image};
use fovea_renderer::way_back::blur::BlurSettings;
use fovea_tests::denoise::{
    assert_bit_equal, assert_finite_non_negative, denoise_over_culled_tiles, plain_materials,
    rmse_where, surface_interiors, texel_screens, upload,
};
use fovea_tests::{
    assert_clean, assert_pictures, gpu, inject_fireflies, owned_scene, read_image, save_preview,
    unit_hash, write_image, Picture, SpaceBuffers,
};
use glam::{Mat4, UVec2, Vec2};
use std::sync::Arc;

const SCREEN: UVec2 = UVec2::new(64, 72);

fn spaces(screen: UVec2) -> [(&'static str, Box<dyn SamplingSpace>); 2] {
    let vp =
        VisualPolar::new(screen, screen.as_vec2() * 0.5, VisualPolarParams::default()).unwrap();
    [
        ("cartesian", Box::new(Cartesian::new(screen))),
        ("vp", Box::new(vp)),
    ]
}

/// The blur is off: the VP comparison measures sampling + denoising only.
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

fn with_svgf() -> DenoiserSettings {
    DenoiserSettings::Svgf(SvgfSettings::default())
}

fn frame(camera: CameraPose, frame_index: u32) -> FrameInput {
    FrameInput::mono(camera, frame_index, None).with_hdr(true)
}

/// Still camera on the Cornell box at 128×144 (5 à-trous iterations span ±62 px; at much smaller
/// sizes they flatten whole walls' shading): 16 SVGF frames against the raw 1-sample frame, both
/// against a 256-spp Cartesian reference, on the screen (VP after the remap, blur off). Asserted on
/// surface interiors at the grid's resolution (`surface_interiors`), whole frame and fovea; rings
/// around the gaze and the whole frame with edges are printed.
#[test]
fn svgf_reduces_noise_fourfold_in_both_spaces() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let size = UVec2::new(128, 144);
    let camera = fovea_tests::cornell_box_far_camera(size);
    let mut reference_renderer = Renderer::new(
        &ctx,
        &scene,
        Box::new(Cartesian::new(size)),
        settings(DenoiserSettings::None),
    )
    .unwrap();
    let reference = reference_renderer
        .render_reference(&camera, 256, 3, |_| {})
        .unwrap();
    drop(reference_renderer);
    save_preview("denoise_reference.png", size.x, size.y, &reference);

    for (name, space) in spaces(size) {
        let gaze = space.gaze();
        let vp = space.visual_polar().copied();
        let r_fovea = vp.map_or(size.x as f32 * 0.1, |v| v.r_fovea());
        let r_max = (gaze.max(size.as_vec2() - gaze)).length();
        let radius = |i: usize| {
            (Vec2::new(
                (i as u32 % size.x) as f32 + 0.5,
                (i as u32 / size.x) as f32 + 0.5,
            ) - gaze)
                .length()
        };
        let ring_edges = [
            0.0,
            r_fovea,
            r_fovea + (r_max - r_fovea) / 3.0,
            r_fovea + 2.0 * (r_max - r_fovea) / 3.0,
            r_max + 1.0,
        ];

        let mut raw_renderer =
            Renderer::new(&ctx, &scene, space, settings(DenoiserSettings::None)).unwrap();
        let mut raw = Vec::new();
        raw_renderer.render_frame(&frame(camera, 0)).unwrap();
        raw_renderer.read_hdr(&mut raw).unwrap();
        drop(raw_renderer);

        let space: Box<dyn SamplingSpace> = match vp {
            Some(v) => Box::new(v),
            None => Box::new(Cartesian::new(size)),
        };
        let mut r = Renderer::new(&ctx, &scene, space, settings(with_svgf())).unwrap();
        let mut denoised = Vec::new();
        for f in 0..16 {
            r.render_frame(&frame(camera, f)).unwrap();
        }
        r.read_hdr(&mut denoised).unwrap();
        assert_finite_non_negative(name, &denoised);
        let interior = surface_interiors(&ctx, &r.view(0).gbuffer, r.space());
        save_preview(&format!("denoise_{name}_raw.png"), size.x, size.y, &raw);
        save_preview(
            &format!("denoise_{name}_svgf.png"),
            size.x,
            size.y,
            &denoised,
        );

        let factor = |keep: &dyn Fn(usize) -> bool| {
            let (a, b) = (
                rmse_where(&raw, &reference, keep),
                rmse_where(&denoised, &reference, keep),
            );
            (a, b, a / b)
        };
        let (a, b, whole) = factor(&|i| interior[i]);
        let (_, _, fovea) = factor(&|i| interior[i] && radius(i) < r_fovea);
        let (ea, eb, with_edges) = factor(&|_| true);
        let rings: Vec<String> = ring_edges
            .windows(2)
            .map(|e| {
                let (a, b, f) = factor(&|i| interior[i] && radius(i) >= e[0] && radius(i) < e[1]);
                format!(
                    "[{:.0}, {:.0}) px {a:.4} → {b:.4} ({f:.1}×)",
                    e[0],
                    e[1].min(r_max)
                )
            })
            .collect();
        println!(
            "{name}: surface interiors RMSE {a:.4} → {b:.4}: {whole:.2}× whole frame, {fovea:.2}× fovea (r < {r_fovea:.1} px); \
             rings {}; with edges {ea:.4} → {eb:.4} ({with_edges:.2}×)",
            rings.join(", ")
        );
        let (actual, expected) = (
            Picture::hdr(size.x, size.y, &denoised),
            Picture::hdr(size.x, size.y, &reference),
        );
        assert_pictures(
            whole >= 4.0,
            name,
            &actual,
            &expected,
            format_args!("{name}: whole-frame RMSE fell only {whole:.2}×"),
        );
        assert_pictures(
            fovea >= 4.0,
            name,
            &actual,
            &expected,
            format_args!("{name}: fovea RMSE fell only {fovea:.2}×"),
        );
        let names: Vec<&str> = r.timings().iter().map(|t| t.name).collect();
        for pass in [
            "svgf_temporal",
            "svgf_variance",
            "svgf_atrous",
            "svgf_modulate",
        ] {
            assert!(
                names.contains(&pass),
                "{name}: pass {pass} missing from {names:?}"
            );
        }
    }
    assert_clean(&ctx);
}

/// Any plain-old-data texels into an image of the matching format.
/// One sample of a synthetic G-buffer: a grey radiance on a face-on surface.
#[derive(Clone, Copy)]
struct Sample {
    radiance: f32,
    depth: f32,
    mesh: u32,
    /// Previous screen position.
    motion: Vec2,
}

const HALF_ONE: u16 = 0x3c00;

/// Fills the G-buffer like the tracer would: `None` = a texel without a sample.
fn upload_gbuffer(ctx: &Arc<Context>, g: &GBuffer, samples: &[Option<Sample>]) {
    let grey =
        |s: &Option<Sample>| s.map_or([0.0; 4], |s| [s.radiance, s.radiance, s.radiance, 1.0]);
    let colour: Vec<[f32; 4]> = samples.iter().map(grey).collect();
    write_image(ctx, &g.color, &colour);
    write_image(ctx, &g.radiance, &colour);
    upload(
        ctx,
        &g.albedo,
        &samples
            .iter()
            .map(|s| {
                if s.is_some() {
                    [HALF_ONE; 4]
                } else {
                    [0u16; 4]
                }
            })
            .collect::<Vec<_>>(),
    );
    write_image(
        ctx,
        &g.normal_depth,
        &samples
            .iter()
            .map(|s| s.map_or([0.0; 4], |s| [0.0, 0.0, 1.0, s.depth]))
            .collect::<Vec<_>>(),
    );
    write_image(
        ctx,
        &g.position,
        &samples
            .iter()
            .map(|s| s.map_or([0.0; 4], |s| [0.0, 0.0, -s.depth, 0.01]))
            .collect::<Vec<_>>(),
    );
    upload(
        ctx,
        &g.ids,
        &samples
            .iter()
            .map(|s| s.map_or([0u32; 2], |s| [1, s.mesh << 16]))
            .collect::<Vec<_>>(),
    );
    upload(
        ctx,
        &g.motion,
        &samples
            .iter()
            .map(|s| s.map_or([-1.0f32; 2], |s| s.motion.to_array()))
            .collect::<Vec<_>>(),
    );
}

/// Frame `f` of the moving-occluder scene: frames 0–7 the occluder (mesh 2, depth 2) covers
/// x < 32 (VP samples beyond the screen too); frame 8 it covers x in [16, 48), moved by 16 px,
/// over the static background (mesh 1, depth 10). Radiance with per-frame noise.
fn occluder_scene(
    screens: &[Option<Vec2>],
    f: u32,
    background: f32,
    occluder: f32,
) -> Vec<Option<Sample>> {
    let (covered, shift) = if f < 8 {
        (-1e4..32.0, 0.0)
    } else {
        (16.0..48.0, 16.0)
    };
    screens
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let s = (*s)?;
            let noise = 0.5 + unit_hash(i as u32 * 31 + f * 7919);
            Some(if covered.contains(&s.x) {
                Sample {
                    radiance: occluder * noise,
                    depth: 2.0,
                    mesh: 2,
                    motion: s - Vec2::new(shift, 0.0),
                }
            } else {
                Sample {
                    radiance: background * noise,
                    depth: 10.0,
                    mesh: 1,
                    motion: s,
                }
            })
        })
        .collect()
}

/// Runs one SVGF frame; returns its output (re-modulated) and moments (z = history length).
fn denoise(
    ctx: &Arc<Context>,
    svgf: &mut Svgf,
    frame: &GridFrame,
) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let mut rec = FrameRecorder::new(ctx, 16).unwrap();
    rec.begin().unwrap();
    svgf.record(&mut rec, frame).unwrap();
    rec.submit_and_wait().unwrap();
    (
        read_image(ctx, &svgf.output),
        read_image(ctx, svgf.moments()),
    )
}

/// Fireflies (huge, infinite and NaN radiance injected into a traced Cornell frame) and an empty
/// view: every output texel stays finite and non-negative, the empty view exactly black.
#[test]
fn svgf_output_is_finite_and_non_negative_with_fireflies_and_an_empty_view() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], SCREEN.x, SCREEN.y);
    // Turned around, the camera looks out of the box's open side into nothing.
    let away = CameraPose {
        world_from_view: camera.world_from_view * Mat4::from_rotation_y(std::f32::consts::PI),
        ..camera
    };
    for (name, space) in spaces(SCREEN) {
        let grid = space.grid_size();
        let variant = space.shader_variant();
        let mut r = Renderer::new(&ctx, &scene, space, settings(DenoiserSettings::None)).unwrap();
        let mut svgf = Svgf::new(&ctx, grid, variant, SvgfSettings::default()).unwrap();
        let mut previous = None;
        let mut peak = 0f32;
        for f in 0..6 {
            r.render_frame(&frame(camera, f)).unwrap();
            inject_fireflies(&ctx, &r.view(0).gbuffer.radiance, f);
            let current = r.space().params();
            let buffers = SpaceBuffers::new(&ctx, r.space(), f, 1);
            let (out, moments) = denoise(
                &ctx,
                &mut svgf,
                &buffers.grid_frame(&r.view(0).gbuffer, (current, previous), &r.scene.materials),
            );
            previous = Some(current);
            assert_finite_non_negative(&format!("{name} frame {f} output"), &out);
            assert_finite_non_negative(&format!("{name} frame {f} moments"), &moments);
            peak = peak.max(
                out.iter()
                    .flat_map(|p| p[..3].iter().copied())
                    .fold(0.0, f32::max),
            );
        }
        println!("{name}: brightest output with fireflies {peak:.1}");

        let mut r = Renderer::new(
            &ctx,
            &scene,
            r.space().visual_polar().map_or_else(
                || Box::new(Cartesian::new(SCREEN)) as Box<dyn SamplingSpace>,
                |v| Box::new(*v),
            ),
            settings(with_svgf()),
        )
        .unwrap();
        let mut hdr = Vec::new();
        for f in 0..3 {
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

/// A bright occluder in front of a dim background moves 16 px to the right after 8 frames: the
/// background it uncovers must start a new history (length 1, no occluder colour), while the
/// occluder's own history follows its motion and the static background keeps its history.
#[test]
fn svgf_drops_history_where_a_moving_occluder_uncovers_the_background() {
    let ctx = gpu();
    let (background, occluder) = (0.25f32, 4.0f32);
    for (name, space) in spaces(SCREEN) {
        let screens = texel_screens(space.as_ref());
        let g = GBuffer::new(&ctx, space.grid_size()).unwrap();
        let mut svgf = Svgf::new(
            &ctx,
            space.grid_size(),
            space.shader_variant(),
            SvgfSettings::default(),
        )
        .unwrap();
        let params = space.params();
        let buffers = SpaceBuffers::new(&ctx, space.as_ref(), 0, 1);
        let materials = plain_materials(&ctx);
        let mut last = (Vec::new(), Vec::new());
        for f in 0..9u32 {
            let samples = occluder_scene(&screens, f, background, occluder);
            upload_gbuffer(&ctx, &g, &samples);
            let previous = (f > 0).then_some(params);
            last = denoise(
                &ctx,
                &mut svgf,
                &buffers.grid_frame(&g, (params, previous), &materials),
            );
        }
        let (out, moments) = last;
        let (mut uncovered, mut followed, mut stayed) = (0, 0, 0);
        for (i, s) in screens.iter().enumerate() {
            // VP samples beyond the screen edge may have had no sample last frame (outside r_max).
            let Some(s) =
                s.filter(|s| s.cmpge(Vec2::ZERO).all() && s.cmplt(SCREEN.as_vec2()).all())
            else {
                continue;
            };
            // Margins of a few pixels keep the 3×3 fallback's legitimate same-surface
            // neighbours (and coarse peripheral VP texels) out of the checked sets.
            let (len, lum) = (moments[i][2], out[i][1]);
            if s.x < 14.0 {
                uncovered += 1;
                assert_eq!(
                    len, 1.0,
                    "{name}: uncovered texel {i} at {s} kept a history"
                );
                assert!(
                    lum < 1.0,
                    "{name}: uncovered texel {i} at {s} shows {lum} (occluder colour)"
                );
            } else if s.x > 18.0 && s.x < 46.0 {
                followed += 1;
                assert_eq!(
                    len, 9.0,
                    "{name}: the occluder's history at {s} did not follow its motion"
                );
                assert!(lum > 2.0, "{name}: occluder texel {i} at {s} shows {lum}");
            } else if s.x > 50.0 {
                stayed += 1;
                assert_eq!(
                    len, 9.0,
                    "{name}: static background at {s} lost its history"
                );
            }
        }
        println!("{name}: {uncovered} uncovered, {followed} moved-occluder and {stayed} static texels checked");
        assert!(
            uncovered > 20 && followed > 5 && stayed > 20,
            "{name}: too few texels checked"
        );
    }
    assert_clean(&ctx);
}

/// SVGF's kernels run over the trace's live tiles only (lavapipe runs masked-off lanes at nearly
/// full cost) and its idle pass writes the history of the idle ones: the output and every image a
/// later frame reads must be those of the whole grid, bit for bit, while the gaze moves towards a
/// corner (tiles turn idle and live). G-buffers from the renderer with culling on, each denoised by
/// one SVGF with the space's tile list and by another with every tile holding a sample live.
#[test]
fn svgf_over_the_live_tiles_equals_svgf_over_the_whole_grid() {
    let ctx = gpu();
    let mut pair: Option<[Svgf; 2]> = None;
    denoise_over_culled_tiles(&ctx, 6, |f, r, over_tiles, over_grid| {
        let new = || {
            Svgf::new(
                &ctx,
                r.space().grid_size(),
                r.space().shader_variant(),
                SvgfSettings::default(),
            )
            .unwrap()
        };
        let [a, b] = pair.get_or_insert_with(|| [new(), new()]);
        denoise(&ctx, a, over_tiles);
        denoise(&ctx, b, over_grid);
        let cur = (f % 2) as usize;
        assert_bit_equal(
            &ctx,
            &format!("frame {f}"),
            &[
                ("output", &a.output, &b.output),
                ("colour history", &a.history.color, &b.history.color),
                ("moments", &a.history.moments[cur], &b.history.moments[cur]),
                ("surfaces", &a.history.surface[cur], &b.history.surface[cur]),
            ],
        );
    });
    assert_clean(&ctx);
}

/// `fovea render --denoiser svgf`: the report names the denoiser and times its passes.
#[test]
fn render_command_runs_svgf_and_reports_it() {
    use fovea_tools::commands::render::{run, RenderArgs};
    let out = fovea_tests::artifacts_dir().join(format!("denoise-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    for (method, denoiser) in [("cartesian", "svgf"), ("vp", "svgf"), ("vp", "none")] {
        run(&RenderArgs {
            method,
            denoiser,
            exr: false,
            ..fovea_tests::small_render_args("cornell-box", &out)
        })
        .unwrap();
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap())
                .unwrap();
        assert_eq!(report["denoiser"], denoiser);
        for pass in [
            "svgf_temporal",
            "svgf_variance",
            "svgf_atrous",
            "svgf_modulate",
        ] {
            assert_eq!(
                report["passes"].get(pass).is_some(),
                denoiser == "svgf",
                "{method}/{denoiser}: pass {pass}"
            );
        }
    }
    assert!(DenoiserSettings::parse("nlm").is_err());
}

fn with_taa(denoiser: DenoiserSettings) -> RenderSettings {
    RenderSettings {
        taa: TaaMode::SamplingGrid(TaaSettings::default()),
        ..settings(denoiser)
    }
}

/// Runs one TAA frame on `color`; returns its output.
fn resolve(
    ctx: &Arc<Context>,
    taa: &mut Taa,
    color: &Image,
    frame: &GridFrame,
    jitter: Vec2,
) -> Vec<[f32; 4]> {
    let mut rec = FrameRecorder::new(ctx, 4).unwrap();
    rec.begin().unwrap();
    let out = taa.record(&mut rec, color, frame, jitter).unwrap();
    rec.submit_and_wait().unwrap();
    read_image(ctx, out)
}

/// Still camera on the Cornell box at 64×72: 16 frames of TAA on the raw 1-sample colour against
/// one raw frame, both against a 256-spp Cartesian reference (random jitter per sample, so
/// anti-aliased), on the screen (VP after the remap, blur off). TAA must lower the RMSE over the
/// whole frame, and at geometric edges (texels whose grid 3×3 spans several surfaces, the
/// complement of `surface_interiors`), where a fixed-jitter 1-sample frame is aliased.
#[test]
fn taa_reduces_noise_and_edge_aliasing_in_both_spaces() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let size = SCREEN;
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], size.x, size.y);
    let mut reference_renderer = Renderer::new(
        &ctx,
        &scene,
        Box::new(Cartesian::new(size)),
        settings(DenoiserSettings::None),
    )
    .unwrap();
    let reference = reference_renderer
        .render_reference(&camera, 256, 3, |_| {})
        .unwrap();
    drop(reference_renderer);
    for (name, space) in spaces(size) {
        let vp = space.visual_polar().copied();
        let again = || -> Box<dyn SamplingSpace> {
            vp.map_or_else(
                || Box::new(Cartesian::new(size)) as Box<dyn SamplingSpace>,
                |v| Box::new(v),
            )
        };
        let mut raw_renderer =
            Renderer::new(&ctx, &scene, space, settings(DenoiserSettings::None)).unwrap();
        let mut raw = Vec::new();
        raw_renderer.render_frame(&frame(camera, 0)).unwrap();
        raw_renderer.read_hdr(&mut raw).unwrap();
        drop(raw_renderer);

        let mut r = Renderer::new(&ctx, &scene, again(), with_taa(DenoiserSettings::None)).unwrap();
        let mut resolved = Vec::new();
        for f in 0..16 {
            r.render_frame(&frame(camera, f)).unwrap();
        }
        r.read_hdr(&mut resolved).unwrap();
        assert_finite_non_negative(name, &resolved);
        assert!(
            r.timings().iter().any(|t| t.name == "taa"),
            "{name}: no taa pass timed"
        );
        let taa_ms: f64 = r
            .timings()
            .iter()
            .filter(|t| t.name == "taa")
            .map(|t| t.ms)
            .sum();
        let interior = surface_interiors(&ctx, &r.view(0).gbuffer, r.space());
        save_preview(&format!("taa_{name}_raw.png"), size.x, size.y, &raw);
        save_preview(&format!("taa_{name}.png"), size.x, size.y, &resolved);
        // TAA resolves with Karis's 1/(1 + luma) weights, i.e. it averages in a compressed space:
        // where a pixel covers part of the light (17× the walls' radiance) that average lies far
        // below the reference's linear coverage mean, by design (against flicker). Those pixels
        // (reference luminance > 1) are printed apart; geometric edges elsewhere are asserted.
        let luminance = |p: &[f32; 4]| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
        let lit: Vec<bool> = reference.iter().map(|p| luminance(p) > 1.0).collect();
        let factor = |keep: &dyn Fn(usize) -> bool| {
            let (a, b) = (
                rmse_where(&raw, &reference, keep),
                rmse_where(&resolved, &reference, keep),
            );
            (a, b, a / b)
        };
        let edge_count = (0..interior.len())
            .filter(|&i| !interior[i] && !lit[i])
            .count();
        let (wa, wb, whole) = factor(&|i| !lit[i]);
        let (ia, ib, inner) = factor(&|i| interior[i] && !lit[i]);
        let (ea, eb, edges) = factor(&|i| !interior[i] && !lit[i]);
        let (la, lb, light) = factor(&|i| lit[i]);
        let (aa, ab, all) = factor(&|_| true);
        println!(
            "{name} {}×{}, RMSE 1 raw frame → 16 TAA frames: without the light's pixels {wa:.4} → {wb:.4} ({whole:.2}×), \
             surface interiors {ia:.4} → {ib:.4} ({inner:.2}×), geometric edges ({edge_count} px) {ea:.4} → {eb:.4} ({edges:.2}×); \
             light pixels {la:.4} → {lb:.4} ({light:.2}×); everything {aa:.4} → {ab:.4} ({all:.2}×); taa pass {taa_ms:.3} ms",
            size.x, size.y
        );
        let (actual, expected) = (
            Picture::hdr(size.x, size.y, &resolved),
            Picture::hdr(size.x, size.y, &reference),
        );
        for (ok, what) in [
            (whole >= 2.5, format!("RMSE fell only {whole:.2}×")),
            (
                inner >= 2.5,
                format!("surface-interior RMSE fell only {inner:.2}×"),
            ),
            (
                edges >= 2.0,
                format!("geometric-edge RMSE fell only {edges:.2}×"),
            ),
        ] {
            assert_pictures(ok, name, &actual, &expected, format_args!("{name}: {what}"));
        }
        assert!(
            edge_count > 100,
            "{name}: too few edge pixels ({edge_count})"
        );
    }
    assert_clean(&ctx);
}

/// Fireflies (huge, infinite, NaN and negative colour injected into traced Cornell frames) going
/// into TAA: every output texel stays finite and non-negative.
#[test]
fn taa_output_is_finite_and_non_negative_with_fireflies() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], SCREEN.x, SCREEN.y);
    for (name, space) in spaces(SCREEN) {
        let grid = space.grid_size();
        let variant = space.shader_variant();
        let mut r = Renderer::new(&ctx, &scene, space, settings(DenoiserSettings::None)).unwrap();
        let mut taa = Taa::new(&ctx, grid, variant, TaaSettings::default()).unwrap();
        let mut previous = None;
        let mut peak = 0f32;
        for f in 0..6 {
            r.render_frame(&frame(camera, f)).unwrap();
            inject_fireflies(&ctx, &r.view(0).gbuffer.color, f);
            let current = r.space().params();
            let jitter = TaaSettings::default().jitter(f);
            let buffers = SpaceBuffers::new(&ctx, r.space(), f, 1);
            let out = resolve(
                &ctx,
                &mut taa,
                &r.view(0).gbuffer.color,
                &buffers.grid_frame(&r.view(0).gbuffer, (current, previous), &r.scene.materials),
                jitter,
            );
            previous = Some(current);
            assert_finite_non_negative(&format!("{name} frame {f}"), &out);
            peak = peak.max(
                out.iter()
                    .flat_map(|p| p[..3].iter().copied())
                    .fold(0.0, f32::max),
            );
        }
        println!("{name}: brightest TAA output with fireflies {peak:.1}");
    }
    assert_clean(&ctx);
}

/// The occluder scene of the SVGF disocclusion test through TAA: where the moving occluder
/// uncovers the background, the output is exactly this frame's sample (history dropped); the
/// occluder's history follows its motion and the static background keeps its history (blended).
#[test]
fn taa_drops_history_where_a_moving_occluder_uncovers_the_background() {
    let ctx = gpu();
    let (background, occluder) = (0.25f32, 4.0f32);
    for (name, space) in spaces(SCREEN) {
        let screens = texel_screens(space.as_ref());
        let g = GBuffer::new(&ctx, space.grid_size()).unwrap();
        let mut taa = Taa::new(
            &ctx,
            space.grid_size(),
            space.shader_variant(),
            TaaSettings::default(),
        )
        .unwrap();
        let params = space.params();
        let buffers = SpaceBuffers::new(&ctx, space.as_ref(), 0, 1);
        let materials = plain_materials(&ctx);
        let (mut out, mut current) = (Vec::new(), Vec::new());
        for f in 0..9u32 {
            let samples = occluder_scene(&screens, f, background, occluder);
            upload_gbuffer(&ctx, &g, &samples);
            current = samples;
            // Samples at texel centres: the jitter is the centre.
            let previous = (f > 0).then_some(params);
            out = resolve(
                &ctx,
                &mut taa,
                &g.color,
                &buffers.grid_frame(&g, (params, previous), &materials),
                Vec2::splat(0.5),
            );
        }
        let (mut uncovered, mut followed, mut stayed, mut blended) = (0, 0, 0, 0);
        for (i, s) in screens.iter().enumerate() {
            let Some(s) =
                s.filter(|s| s.cmpge(Vec2::ZERO).all() && s.cmplt(SCREEN.as_vec2()).all())
            else {
                continue;
            };
            let (got, now) = (out[i][1], current[i].unwrap().radiance);
            if s.x < 14.0 {
                uncovered += 1;
                assert!(
                    (got - now).abs() <= 1e-5 * now,
                    "{name}: uncovered texel {i} at {s} shows {got}, this frame's sample is {now}"
                );
            } else if s.x > 18.0 && s.x < 46.0 {
                followed += 1;
                assert!(got > 2.0, "{name}: occluder texel {i} at {s} shows {got}");
                blended += ((got - now).abs() > 1e-4) as u32;
            } else if s.x > 50.0 {
                stayed += 1;
                assert!(got < 1.0, "{name}: background texel {i} at {s} shows {got}");
                blended += ((got - now).abs() > 1e-4) as u32;
            }
        }
        println!("{name}: {uncovered} uncovered (reset), {followed} moved-occluder and {stayed} static texels ({blended} blended)");
        assert!(
            uncovered > 20 && followed > 5 && stayed > 20,
            "{name}: too few texels checked"
        );
        assert!(
            blended as f32 >= 0.95 * (followed + stayed) as f32,
            "{name}: only {blended} of {} texels kept a history",
            followed + stayed
        );
    }
    assert_clean(&ctx);
}

/// With TAA on, every sample lies at the frame's Halton offset inside its grid texel: on a still
/// camera the motion output (previous screen position) is the sample's own screen position, which
/// must be the CPU's mapping of texel + `TaaSettings::jitter(frame)`. With TAA off it must not be.
#[test]
fn taa_makes_the_tracer_use_the_frames_halton_offset() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], SCREEN.x, SCREEN.y);
    for (name, space) in spaces(SCREEN) {
        let vp = space.visual_polar().copied();
        let again = || -> Box<dyn SamplingSpace> {
            vp.map_or_else(
                || Box::new(Cartesian::new(SCREEN)) as Box<dyn SamplingSpace>,
                |v| Box::new(v),
            )
        };
        let grid = space.grid_size();
        drop(space);
        for taa_on in [true, false] {
            let s = if taa_on {
                with_taa(DenoiserSettings::None)
            } else {
                settings(DenoiserSettings::None)
            };
            let mut r = Renderer::new(&ctx, &scene, again(), s).unwrap();
            for f in [0u32, 1, 5, 17] {
                r.render_frame(&frame(camera, f)).unwrap();
                let motion: Vec<[f32; 2]> = read_image(&ctx, &r.view(0).gbuffer.motion);
                let jitter = TaaSettings::default().jitter(f);
                let (mut worst, mut checked, mut off) = (0f32, 0, 0);
                for y in 0..grid.y {
                    for x in 0..grid.x {
                        let m = Vec2::from(motion[(y * grid.x + x) as usize]);
                        let Some(expected) = r
                            .space()
                            .grid_to_screen(Vec2::new(x as f32, y as f32) + jitter)
                        else {
                            continue;
                        };
                        if m == Vec2::splat(-1.0)
                            || !(expected.cmpge(Vec2::ZERO).all()
                                && expected.cmplt(SCREEN.as_vec2()).all())
                        {
                            continue;
                        }
                        let e = (m - expected).length();
                        worst = worst.max(e);
                        checked += 1;
                        off += (e > 0.05) as u32;
                    }
                }
                assert!(checked > 1000, "{name}: only {checked} texels checked");
                if taa_on {
                    assert!(worst < 0.02, "{name} frame {f}: a sample lies {worst} px from the Halton offset {jitter}");
                } else {
                    assert!(
                        off as f32 > 0.5 * checked as f32,
                        "{name} frame {f}: random jitter matches Halton at {} of {checked}",
                        checked - off
                    );
                }
                if f == 5 {
                    println!("{name} taa {taa_on}: frame {f} jitter {jitter}, {checked} texels, worst {worst:.5} px, {off} off by > 0.05 px");
                }
            }
        }
    }
    assert_clean(&ctx);
}

/// `fovea render --taa vp|screen` after the denoiser (and on the raw colour): the report names it
/// and times the pass (`taa` in the grid, `taa_screen` after the remap; Cartesian's screen is its
/// grid); an unknown mode is refused.
#[test]
fn render_command_runs_taa_and_reports_it() {
    use fovea_tools::commands::render::{run, RenderArgs};
    let out = fovea_tests::artifacts_dir().join(format!("taa-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let args = |method, denoiser, taa| RenderArgs {
        method,
        denoiser,
        taa,
        exr: false,
        ..fovea_tests::small_render_args("cornell-box", &out)
    };
    let runs = [
        ("cartesian", "none", "vp", Some("taa")),
        ("cartesian", "none", "screen", Some("taa")),
        ("vp", "svgf", "vp", Some("taa")),
        ("vp", "svgf", "screen", Some("taa_screen")),
        ("vp", "none", "off", None),
    ];
    for (method, denoiser, taa, pass) in runs {
        run(&args(method, denoiser, taa)).unwrap();
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap())
                .unwrap();
        assert_eq!(report["taa"], taa);
        for name in ["taa", "taa_screen"] {
            assert_eq!(
                report["passes"].get(name).is_some(),
                pass == Some(name),
                "{method}/{denoiser}/{taa}: {name}"
            );
        }
    }
    let err = format!("{:#}", run(&args("vp", "none", "temporal")).unwrap_err());
    assert!(err.contains("expected one of off, vp, screen"), "{err}");
}
