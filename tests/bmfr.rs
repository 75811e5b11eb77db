//! BMFR (Koskela et al. 2019, TOG) in the sampling grid, Cartesian and Visual-Polar: the GPU's
//! per-block least-squares fit against a CPU solve in f64; noise reduction against a converged
//! reference on the Cornell box; no NaN/Inf/negative output with fireflies and an empty view; no
//! history across a disocclusion (synthetic G-buffers, moving camera); the `--denoiser bmfr` flag
//! end to end. The φ seam is the conformance suite's (tests/conformance.rs), for every filter.

use fovea_renderer::frame::{CameraPose, FrameInput, RenderSettings};
use fovea_renderer::graph::FrameRecorder;
use fovea_renderer::layouts::BMFR_BLOCK;
use fovea_renderer::passes::denoise::bmfr::{Bmfr, BmfrSettings, BLOCK_OFFSETS};
use fovea_renderer::passes::denoise::DenoiserSettings;
use fovea_renderer::passes::grid::{GBuffer, GridFrame};
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::{Cartesian, SamplingSpace, VisualPolar, VisualPolarParams};
use fovea_renderer::vk::Context;
use fovea_renderer::way_back::blur::BlurSettings;
use fovea_tests::denoise::{
    assert_bit_equal, assert_finite_non_negative, denoise_over_culled_tiles, plain_materials,
    rmse_where, surface_interiors, texel_screens, upload_gbuffer, Texel,
};
use fovea_tests::{
    assert_clean, assert_pictures, gpu, inject_fireflies, owned_scene, read_image, save_preview,
    unit_hash, Picture, SpaceBuffers,
};
use glam::{Mat4, UVec2, Vec2, Vec3};
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

fn same_space(space: &dyn SamplingSpace) -> Box<dyn SamplingSpace> {
    match space.visual_polar() {
        Some(v) => Box::new(*v),
        None => Box::new(Cartesian::new(space.screen_size())),
    }
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

fn with_bmfr() -> DenoiserSettings {
    DenoiserSettings::Bmfr(BmfrSettings::default())
}

fn frame(camera: CameraPose, frame_index: u32) -> FrameInput {
    FrameInput::mono(camera, frame_index, None).with_hdr(true)
}

/// Runs one BMFR frame; returns its output (re-modulated).
fn denoise(ctx: &Arc<Context>, bmfr: &mut Bmfr, frame: &GridFrame) -> Vec<[f32; 4]> {
    let mut rec = FrameRecorder::new(ctx, 8).unwrap();
    rec.begin().unwrap();
    bmfr.record(&mut rec, frame).unwrap();
    rec.submit_and_wait().unwrap();
    read_image(ctx, &bmfr.output)
}

/// Solves the least-squares problem min ‖F·w − c‖ in f64 by the normal equations (Gaussian
/// elimination with partial pivoting); `rows` are [10 features, colour].
fn cpu_least_squares(rows: &[([f64; 10], f64)]) -> [f64; 10] {
    let mut a = [[0f64; 11]; 10];
    for (f, c) in rows {
        for i in 0..10 {
            for j in 0..10 {
                a[i][j] += f[i] * f[j];
            }
            a[i][10] += f[i] * c;
        }
    }
    for k in 0..10 {
        let p = (k..10)
            .max_by(|&x, &y| a[x][k].abs().total_cmp(&a[y][k].abs()))
            .unwrap();
        a.swap(k, p);
        let pivot_row = a[k];
        for row in a.iter_mut().skip(k + 1) {
            let m = row[k] / pivot_row[k];
            for (x, p) in row.iter_mut().zip(pivot_row).skip(k) {
                *x -= m * p;
            }
        }
    }
    let mut w = [0f64; 10];
    for k in (0..10).rev() {
        w[k] = (a[k][10] - (k + 1..10).map(|j| a[k][j] * w[j]).sum::<f64>()) / a[k][k];
    }
    w
}

/// The block of each grid texel (`None`: no sample), derived here from the rule in
/// `shaders/denoise/bmfr.glsl`, independently of the GPU's enumeration of a block's texels:
/// blocks start at b·32 − (16 − offset) on x (and on y in Cartesian space); Visual-Polar rows are
/// placed at their angle on the block column's tallest height N and counted from the shift,
/// wrapping at N.
fn cpu_blocks(space: &dyn SamplingSpace, offset: [i32; 2]) -> Vec<Option<(i32, i32)>> {
    let grid = space.grid_size();
    let side = BMFR_BLOCK as i32;
    let shift = [16 - offset[0], 16 - offset[1]];
    let rows = |c: i32| {
        space
            .visual_polar()
            .map_or(grid.y, |v| v.rows_in_column(c as u32)) as i32
    };
    (0..grid.x * grid.y)
        .map(|i| {
            let (x, y) = ((i % grid.x) as i32, (i / grid.x) as i32);
            if y >= rows(x) {
                return None;
            }
            let bx = (x + shift[0]) / side;
            if space.visual_polar().is_none() {
                return Some((bx, (y + shift[1]) / side));
            }
            let big_n = rows((bx * side - shift[0] + side - 1).clamp(0, grid.x as i32 - 1));
            let v = (2 * y + 1) * big_n / (2 * rows(x));
            Some((bx, (v + shift[1]).rem_euclid(big_n) / side))
        })
        .collect()
}

/// The fit of every block (first frame: no history, block offset `BLOCK_OFFSETS[0]`,
/// regularisation noise off) against a CPU solve in f64 over the CPU's own partition of the grid
/// (`cpu_blocks`): each texel's fitted colour (before the accumulation after the fit) must match,
/// in Cartesian space (64×72) and in Visual-Polar space (screen 128×144, blocks crossing the φ
/// seam, clipped fovea columns). A texel the GPU fitted in another block than the one it reads
/// its weights from, or left out, shows an error of the added noise's size.
/// Features are generic (normals on a 1/256 lattice, exact in the fp16 history; x spans 4 units,
/// so it is min/max-scaled; y and z span < 1 and are not), colours a known linear combination
/// plus noise, so every block of ≥ 40 texels is a least-squares problem of full rank.
#[test]
fn fit_matches_a_cpu_least_squares_solve() {
    let ctx = gpu();
    let vp = VisualPolar::new(
        UVec2::new(128, 144),
        Vec2::new(64.0, 72.0),
        VisualPolarParams::default(),
    )
    .unwrap();
    let spaces: [(&str, Box<dyn SamplingSpace>); 2] = [
        ("cartesian", Box::new(Cartesian::new(SCREEN))),
        ("vp", Box::new(vp)),
    ];
    let lattice = |v: f32| (v * 256.0).round() / 256.0;
    let truth = [
        [2.0, 0.3, -0.2, 0.1, 0.4, 0.2, 0.05, -0.1, 0.3, 0.02],
        [1.5, -0.1, 0.2, 0.3, -0.3, 0.1, 0.02, 0.2, -0.2, 0.01],
        [2.5, 0.2, 0.1, -0.3, 0.1, -0.2, 0.04, 0.1, 0.1, 0.03],
    ];
    for (name, space) in spaces {
        let grid = space.grid_size();
        let offset = BLOCK_OFFSETS[0];
        let blocks_of = cpu_blocks(space.as_ref(), offset);
        let texels: Vec<Option<Texel>> = (0..grid.x * grid.y)
            .map(|i| {
                blocks_of[i as usize]?;
                let h = |k: u32| unit_hash(i * 11 + k);
                let normal = [
                    lattice(2.0 * h(1) - 1.0),
                    lattice(2.0 * h(2) - 1.0),
                    lattice(h(3)),
                ];
                let position = [4.0 * h(4) - 2.0, 0.8 * h(5) - 0.4, -5.0 + 0.9 * h(6)];
                let mut radiance = [0f32; 3];
                for (c, r) in radiance.iter_mut().enumerate() {
                    // Features before the per-block scaling; any linear combination of them is one
                    // of the scaled features too.
                    let f = features(normal, position, [0.0; 3], [1.0; 3]);
                    *r = (0..10).map(|k| truth[c][k] * f[k] as f32).sum::<f32>()
                        + 0.1 * (unit_hash(i * 11 + 7 + c as u32) - 0.5);
                    assert!(
                        *r > 0.0,
                        "test colours must be positive (the output is clamped)"
                    );
                }
                Some(Texel {
                    radiance,
                    normal,
                    position,
                    mesh: 1,
                    motion: Vec2::splat(-1.0),
                })
            })
            .collect();
        let g = GBuffer::new(&ctx, grid).unwrap();
        upload_gbuffer(&ctx, &g, &texels);
        let mut bmfr = Bmfr::new(
            &ctx,
            grid,
            space.shader_variant(),
            BmfrSettings {
                noise: 0.0,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(bmfr.next_block_offset().to_array(), offset);
        let buffers = SpaceBuffers::new(&ctx, space.as_ref(), 0, 1);
        let materials = plain_materials(&ctx);
        denoise(
            &ctx,
            &mut bmfr,
            &buffers.grid_frame(&g, (space.params(), None), &materials),
        );
        let fitted: Vec<[f32; 4]> = read_image(&ctx, &bmfr.fitted);

        let mut blocks: Vec<(i32, i32)> = blocks_of.iter().flatten().copied().collect();
        blocks.sort();
        blocks.dedup();
        let (mut worst, mut worst_rel, mut checked, mut seam_blocks) = (0f64, 0f64, 0usize, 0);
        for block in &blocks {
            let members: Vec<usize> = (0..texels.len())
                .filter(|&i| blocks_of[i] == Some(*block))
                .collect();
            if members.len() < 40 {
                continue;
            }
            let rows_of = |i: usize| {
                space
                    .visual_polar()
                    .map_or(grid.y, |v| v.rows_in_column(i as u32 % grid.x))
            };
            let row = |i: usize| i as u32 / grid.x;
            if members.iter().any(|&i| row(i) == 0)
                && members.iter().any(|&i| row(i) + 1 == rows_of(i))
            {
                seam_blocks += 1;
            }
            checked += members.len();
            let member_texels: Vec<Texel> = members.iter().map(|&i| texels[i].unwrap()).collect();
            let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
            for t in &member_texels {
                for a in 0..3 {
                    lo[a] = lo[a].min(t.position[a]);
                    hi[a] = hi[a].max(t.position[a]);
                }
            }
            let wide = |a: usize| hi[a] - lo[a] > 1.0;
            let offset = [0, 1, 2].map(|a| if wide(a) { lo[a] } else { 0.0 });
            let scale = [0, 1, 2].map(|a| if wide(a) { 1.0 / (hi[a] - lo[a]) } else { 1.0 });
            #[allow(clippy::needless_range_loop)] // c picks a channel of two different arrays
            for c in 0..3 {
                let rows: Vec<([f64; 10], f64)> = member_texels
                    .iter()
                    .map(|t| {
                        (
                            features(t.normal, t.position, offset, scale),
                            t.radiance[c] as f64,
                        )
                    })
                    .collect();
                let w = cpu_least_squares(&rows);
                for (&i, (f, _)) in members.iter().zip(&rows) {
                    let expected: f64 = (0..10).map(|k| w[k] * f[k]).sum();
                    let e = (fitted[i][c] as f64 - expected).abs();
                    worst = worst.max(e);
                    worst_rel = worst_rel.max(e / expected.abs());
                }
            }
        }
        let valid = blocks_of.iter().flatten().count();
        println!(
            "{name}: {} blocks, {checked} of {valid} texels checked ({seam_blocks} blocks across the φ seam): worst fitted-colour \
             difference GPU (fp32 QR) vs CPU (f64) {worst:.2e} ({worst_rel:.2e} relative)",
            blocks.len()
        );
        // fp32 Householder QR is backward stable: the fitted values (not the individual weights,
        // which the near-collinear 1, z, z² columns make ill-conditioned) carry errors of a few ulps
        // of the colour (~2.5, ulp 2.4e-7) times a small factor; 3e-6 is measured, 1e-4 leaves
        // ~30×, while a wrong block, wrong scaling, a missing row or a dropped feature shows errors
        // of the added noise's size (±0.05).
        assert!(
            worst < 1e-4,
            "{name}: fitted colours differ by up to {worst}"
        );
        assert!(
            checked as f64 >= 0.9 * valid as f64,
            "{name}: only {checked} of {valid} texels in blocks of ≥ 40"
        );
        if name == "vp" {
            assert!(seam_blocks > 0, "no block crosses the φ seam");
        }
    }
    assert_clean(&ctx);
}

/// A rank-deficient problem, regularisation off: a face-on plane (normal constant, z = −5
/// constant) leaves normal x, y as zero columns and normal z, z and z² as multiples of the
/// constant one. The fit must skip them and solve with 1, x, y, x², y² — compared with a CPU solve
/// on those five features (Cartesian 64×72, every block).
#[test]
fn rank_deficient_blocks_fit_the_remaining_features() {
    let ctx = gpu();
    let space = Cartesian::new(SCREEN);
    let grid = space.grid_size();
    let offset = BLOCK_OFFSETS[0];
    let blocks_of = cpu_blocks(&space, offset);
    let texels: Vec<Option<Texel>> = (0..grid.x * grid.y)
        .map(|i| {
            let (x, y) = ((i % grid.x) as f32 / 64.0, (i / grid.x) as f32 / 64.0);
            let v =
                0.5 + 0.3 * x - 0.2 * y + 0.4 * x * x + 0.1 * y * y + 0.05 * (unit_hash(i) - 0.5);
            Some(Texel {
                radiance: [v, 2.0 * v, 0.5 * v],
                normal: [0.0, 0.0, 1.0],
                position: [x, y, -5.0],
                mesh: 1,
                motion: Vec2::splat(-1.0),
            })
        })
        .collect();
    let g = GBuffer::new(&ctx, grid).unwrap();
    upload_gbuffer(&ctx, &g, &texels);
    let mut bmfr = Bmfr::new(
        &ctx,
        grid,
        space.shader_variant(),
        BmfrSettings {
            noise: 0.0,
            ..Default::default()
        },
    )
    .unwrap();
    let buffers = SpaceBuffers::new(&ctx, &space, 0, 1);
    let materials = plain_materials(&ctx);
    let out = denoise(
        &ctx,
        &mut bmfr,
        &buffers.grid_frame(&g, (space.params(), None), &materials),
    );
    assert_finite_non_negative("rank-deficient fit", &out);
    let fitted: Vec<[f32; 4]> = read_image(&ctx, &bmfr.fitted);
    let mut worst = 0f64;
    let mut blocks: Vec<(i32, i32)> = blocks_of.iter().flatten().copied().collect();
    blocks.sort();
    blocks.dedup();
    for block in blocks {
        let members: Vec<usize> = (0..texels.len())
            .filter(|&i| blocks_of[i] == Some(block))
            .collect();
        // Positions span < 1 per block: no scaling.
        let five = |t: &Texel| {
            let (x, y) = (t.position[0] as f64, t.position[1] as f64);
            let mut f = [0f64; 10];
            f[..5].copy_from_slice(&[1.0, x, y, x * x, y * y]);
            f
        };
        // The five features padded with independent dummy columns that the solve gives weight 0
        // (their rows are an identity block outside the data).
        #[allow(clippy::needless_range_loop)] // c picks a channel of two different arrays
        for c in 0..3 {
            let mut rows: Vec<([f64; 10], f64)> = members
                .iter()
                .map(|&i| {
                    (
                        five(&texels[i].unwrap()),
                        texels[i].unwrap().radiance[c] as f64,
                    )
                })
                .collect();
            for k in 5..10 {
                let mut f = [0f64; 10];
                f[k] = 1.0;
                rows.push((f, 0.0));
            }
            let w = cpu_least_squares(&rows);
            for &i in &members {
                let f = five(&texels[i].unwrap());
                let expected: f64 = (0..10).map(|k| w[k] * f[k]).sum();
                worst = worst.max((fitted[i][c] as f64 - expected).abs());
            }
        }
    }
    println!("rank-deficient blocks: worst fitted-colour difference vs the CPU's 5-feature solve {worst:.2e}");
    // As in the full-rank test, plus the round-off the skipped columns leave in the others' rows.
    assert!(worst < 1e-4, "fitted colours differ by up to {worst}");
    assert_clean(&ctx);
}

/// The 10 features, positions scaled as (p − offset)·scale.
fn features(n: [f32; 3], p: [f32; 3], offset: [f32; 3], scale: [f32; 3]) -> [f64; 10] {
    let s = [0, 1, 2].map(|a| ((p[a] - offset[a]) * scale[a]) as f64);
    [
        1.0,
        n[0] as f64,
        n[1] as f64,
        n[2] as f64,
        s[0],
        s[1],
        s[2],
        s[0] * s[0],
        s[1] * s[1],
        s[2] * s[2],
    ]
}

/// Still camera on the Cornell box at 128×144: 16 BMFR frames against the raw 1-sample frame, both
/// against a 256-spp Cartesian reference, on the screen (VP after the remap, blur off). Asserted
/// on surface interiors (whole frame and fovea); rings and the whole frame with edges are printed.
#[test]
fn bmfr_reduces_noise_in_both_spaces() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let size = UVec2::new(128, 144);
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
        let gaze = space.gaze();
        let r_fovea = space
            .visual_polar()
            .map_or(size.x as f32 * 0.1, |v| v.r_fovea());
        let r_max = (gaze.max(size.as_vec2() - gaze)).length();
        let radius = |i: usize| {
            (Vec2::new(
                (i as u32 % size.x) as f32 + 0.5,
                (i as u32 / size.x) as f32 + 0.5,
            ) - gaze)
                .length()
        };
        let again = same_space(space.as_ref());

        let mut raw_renderer =
            Renderer::new(&ctx, &scene, space, settings(DenoiserSettings::None)).unwrap();
        let mut raw = Vec::new();
        raw_renderer.render_frame(&frame(camera, 0)).unwrap();
        raw_renderer.read_hdr(&mut raw).unwrap();
        drop(raw_renderer);

        let mut r = Renderer::new(&ctx, &scene, again, settings(with_bmfr())).unwrap();
        let mut denoised = Vec::new();
        for f in 0..16 {
            r.render_frame(&frame(camera, f)).unwrap();
        }
        r.read_hdr(&mut denoised).unwrap();
        assert_finite_non_negative(name, &denoised);
        let interior = surface_interiors(&ctx, &r.view(0).gbuffer, r.space());
        save_preview(&format!("bmfr_{name}_raw.png"), size.x, size.y, &raw);
        save_preview(&format!("bmfr_{name}.png"), size.x, size.y, &denoised);

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
        let ring_edges = [
            0.0,
            r_fovea,
            r_fovea + (r_max - r_fovea) / 3.0,
            r_fovea + 2.0 * (r_max - r_fovea) / 3.0,
            r_max + 1.0,
        ];
        let rings: Vec<String> = ring_edges
            .windows(2)
            .map(|e| {
                let (_, _, f) = factor(&|i| interior[i] && radius(i) >= e[0] && radius(i) < e[1]);
                format!("[{:.0}, {:.0}) px {f:.1}×", e[0], e[1].min(r_max))
            })
            .collect();
        let ms: f64 = r
            .timings()
            .iter()
            .filter(|t| t.name.starts_with("bmfr_"))
            .map(|t| t.ms)
            .sum();
        println!(
            "{name}: surface interiors RMSE {a:.4} → {b:.4}: {whole:.2}× whole frame, {fovea:.2}× fovea (r < {r_fovea:.1} px); \
             rings {}; with edges {ea:.4} → {eb:.4} ({with_edges:.2}×); bmfr passes {ms:.1} ms",
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
            "bmfr_accumulate",
            "bmfr_fit",
            "bmfr_weighted_sum",
            "bmfr_accumulate_filtered",
        ] {
            assert!(
                names.contains(&pass),
                "{name}: pass {pass} missing from {names:?}"
            );
        }
    }
    assert_clean(&ctx);
}

/// Fireflies (huge, infinite, NaN and negative radiance injected into traced Cornell frames) and
/// an empty view: every output texel stays finite and non-negative, the empty view exactly black.
#[test]
fn bmfr_output_is_finite_and_non_negative_with_fireflies_and_an_empty_view() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], SCREEN.x, SCREEN.y);
    let origin = camera.world_from_view.w_axis.truncate();
    let away = CameraPose {
        world_from_view: camera.world_from_view * Mat4::from_rotation_y(std::f32::consts::PI),
        ..camera
    };
    for (name, space) in spaces(SCREEN) {
        let grid = space.grid_size();
        let variant = space.shader_variant();
        let again = same_space(space.as_ref());
        let mut r = Renderer::new(&ctx, &scene, space, settings(DenoiserSettings::None)).unwrap();
        let mut bmfr = Bmfr::new(&ctx, grid, variant, BmfrSettings::default()).unwrap();
        let mut previous = None;
        let mut peak = 0f32;
        for f in 0..6 {
            r.render_frame(&frame(camera, f)).unwrap();
            inject_fireflies(&ctx, &r.view(0).gbuffer.radiance, f);
            let current = r.space().params();
            let buffers = SpaceBuffers::new(&ctx, r.space(), f, 1);
            let materials = &r.scene.materials;
            let out = denoise(
                &ctx,
                &mut bmfr,
                &GridFrame {
                    camera_origin: origin,
                    ..buffers.grid_frame(&r.view(0).gbuffer, (current, previous), materials)
                },
            );
            previous = Some(current);
            assert_finite_non_negative(&format!("{name} frame {f} output"), &out);
            assert_finite_non_negative(
                &format!("{name} frame {f} history"),
                &read_image(&ctx, bmfr.noisy()),
            );
            peak = peak.max(
                out.iter()
                    .flat_map(|p| p[..3].iter().copied())
                    .fold(0.0, f32::max),
            );
        }
        println!("{name}: brightest output with fireflies {peak:.1}");

        let mut r = Renderer::new(&ctx, &scene, again, settings(with_bmfr())).unwrap();
        let mut hdr = Vec::new();
        for f in 0..3 {
            r.render_frame(&frame(away, f)).unwrap();
            r.read_hdr(&mut hdr).unwrap();
            assert!(
                hdr.iter().all(|p| p[..3] == [0.0; 3]),
                "{name}: the empty view is not black (frame {f})"
            );
        }
    }
    assert_clean(&ctx);
}

/// A static world seen by a camera that moves 1 unit to the right after 8 frames: a bright
/// occluder plane (depth 2, world x < 0) in front of a dim background (depth 10). The occluder
/// slides 16 px left on the screen, the background 3.2 px, uncovering background at screen
/// x ∈ [16, 28.8): there the history must restart (length 1) without the occluder's colour; the
/// occluder and the static background keep theirs (reprojected by world position).
#[test]
fn bmfr_drops_history_where_a_moving_camera_uncovers_the_background() {
    let ctx = gpu();
    let (background, occluder) = (0.25f32, 4.0f32);
    let focal = 32.0;
    let centre = SCREEN.as_vec2() * 0.5;
    for (name, space) in spaces(SCREEN) {
        let screens = texel_screens(space.as_ref());
        let g = GBuffer::new(&ctx, space.grid_size()).unwrap();
        let mut bmfr = Bmfr::new(
            &ctx,
            space.grid_size(),
            space.shader_variant(),
            BmfrSettings::default(),
        )
        .unwrap();
        let params = space.params();
        let buffers = SpaceBuffers::new(&ctx, space.as_ref(), 0, 1);
        let materials = plain_materials(&ctx);
        let mut out = Vec::new();
        for f in 0..9u32 {
            let (camera_x, prev_camera_x) = if f < 8 { (0.0, 0.0) } else { (1.0, 0.0) };
            let texels: Vec<Option<Texel>> = screens
                .iter()
                .enumerate()
                .map(|(i, s)| {
                    let s = (*s)?;
                    // The occluder's screen edge: world x = 0 at depth 2.
                    let edge = centre.x + focal * (0.0 - camera_x) / 2.0;
                    let (depth, level, mesh) = if s.x < edge {
                        (2.0, occluder, 2)
                    } else {
                        (10.0, background, 1)
                    };
                    let rel = Vec3::new(
                        (s.x - centre.x) / focal * depth,
                        (s.y - centre.y) / focal * depth,
                        -depth,
                    );
                    let world_x = camera_x + rel.x;
                    let motion =
                        Vec2::new(centre.x + focal * (world_x - prev_camera_x) / depth, s.y);
                    let v = level * (0.5 + unit_hash(i as u32 * 31 + f * 7919));
                    Some(Texel {
                        radiance: [v; 3],
                        normal: [0.0, 0.0, 1.0],
                        position: rel.to_array(),
                        mesh,
                        motion,
                    })
                })
                .collect();
            upload_gbuffer(&ctx, &g, &texels);
            let previous = (f > 0).then_some(params);
            out = denoise(
                &ctx,
                &mut bmfr,
                &GridFrame {
                    camera_origin: Vec3::new(camera_x, 0.0, 0.0),
                    ..buffers.grid_frame(&g, (params, previous), &materials)
                },
            );
        }
        let lengths: Vec<[f32; 4]> = read_image(&ctx, bmfr.noisy());
        let (mut uncovered, mut followed, mut stayed) = (0, 0, 0);
        for (i, s) in screens.iter().enumerate() {
            let Some(s) =
                s.filter(|s| s.cmpge(Vec2::ZERO).all() && s.cmplt(SCREEN.as_vec2()).all())
            else {
                continue;
            };
            // Margins of a few pixels keep bilinear footprints across the edges (and coarse
            // peripheral VP texels) out of the checked sets. Lengths blend over bilinear taps:
            // compared to 1e-3.
            let (len, lum) = (lengths[i][3], out[i][1]);
            if s.x > 18.0 && s.x < 27.0 {
                uncovered += 1;
                assert_eq!(
                    len, 1.0,
                    "{name}: uncovered texel {i} at {s} kept a history"
                );
                assert!(
                    lum < 1.0,
                    "{name}: uncovered texel {i} at {s} shows {lum} (occluder colour)"
                );
            } else if s.x > 2.0 && s.x < 14.0 {
                followed += 1;
                assert!(
                    (len - 9.0).abs() < 1e-3,
                    "{name}: the occluder's history at {s} did not follow the camera ({len})"
                );
                assert!(lum > 2.0, "{name}: occluder texel {i} at {s} shows {lum}");
            } else if s.x > 34.0 && s.x < 60.0 {
                // (Beyond 60.8 px the background was off the screen last frame.)
                stayed += 1;
                assert!(
                    (len - 9.0).abs() < 1e-3,
                    "{name}: background at {s} lost its history ({len})"
                );
                assert!(lum < 1.0, "{name}: background texel {i} at {s} shows {lum}");
            }
        }
        println!("{name}: {uncovered} uncovered, {followed} occluder and {stayed} background texels checked");
        assert!(
            uncovered > 20 && followed > 20 && stayed > 20,
            "{name}: too few texels checked"
        );
    }
    assert_clean(&ctx);
}

/// `fovea render --denoiser bmfr`: the report names the denoiser and times its passes, in
/// Cartesian space and both Visual-Polar layouts.
#[test]
fn render_command_runs_bmfr_and_reports_it() {
    use fovea_tools::commands::render::{run, RenderArgs};
    let out = fovea_tests::artifacts_dir().join(format!("bmfr-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    for method in ["cartesian", "vp", "vp-screen-clipped"] {
        run(&RenderArgs {
            method,
            denoiser: "bmfr",
            exr: false,
            ..fovea_tests::small_render_args("cornell-box", &out)
        })
        .unwrap();
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap())
                .unwrap();
        assert_eq!(report["denoiser"], "bmfr");
        for pass in [
            "bmfr_accumulate",
            "bmfr_fit",
            "bmfr_weighted_sum",
            "bmfr_accumulate_filtered",
        ] {
            assert!(
                report["passes"].get(pass).is_some(),
                "{method}: pass {pass} missing"
            );
        }
    }
}

/// BMFR's per-texel kernels run over the trace's live tiles only and its idle pass writes the idle
/// ones before the fit reads whole blocks: the output, the fitted colour and every history image
/// must be those of the whole grid, bit for bit, while the gaze moves (tiles turn idle and live).
#[test]
fn bmfr_over_the_live_tiles_equals_bmfr_over_the_whole_grid() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let origin = CameraPose::from_scene_camera(&scene.cameras[0], 128, 144)
        .world_from_view
        .w_axis
        .truncate();
    let mut pair: Option<[Bmfr; 2]> = None;
    denoise_over_culled_tiles(&ctx, 6, |f, r, over_tiles, over_grid| {
        let new = || {
            Bmfr::new(
                &ctx,
                r.space().grid_size(),
                r.space().shader_variant(),
                BmfrSettings::default(),
            )
            .unwrap()
        };
        let [a, b] = pair.get_or_insert_with(|| [new(), new()]);
        for (bmfr, frame) in [(&mut *a, over_tiles), (&mut *b, over_grid)] {
            let frame = GridFrame {
                camera_origin: origin,
                ..*frame
            };
            denoise(&ctx, bmfr, &frame);
        }
        let cur = (f % 2) as usize;
        let (ha, hb) = (&a.history, &b.history);
        assert_bit_equal(
            &ctx,
            &format!("frame {f}"),
            &[
                ("output", &a.output, &b.output),
                ("fitted", &a.fitted, &b.fitted),
                ("noisy history", &ha.noisy[cur], &hb.noisy[cur]),
                ("normal history", &ha.normal[cur], &hb.normal[cur]),
                ("position history", &ha.position[cur], &hb.position[cur]),
                ("filtered history", &ha.filtered[cur], &hb.filtered[cur]),
            ],
        );
    });
    assert_clean(&ctx);
}
