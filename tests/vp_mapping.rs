//! The Visual-Polar mapping on the device: `shaders/sampling/visual_polar_math.glsl` and
//! `visual_polar_clipped.glsl` (run through the `passes/vp_mapping_probe` kernel, reading the
//! per-column arc table) agree with the Rust twin `VisualPolar` on ≥ 10⁴ points per case, in both
//! directions, for the paper's and the screen-clipped layout (max error < 10⁻³ px).
//!
//! Bounds:
//! - grid → screen, paper axis, either inverse CDF: < 1e-3 px, the required bound. The exact
//!   inverse solves for the CDF's tail beyond e (`cdf_tail`), not cdf(e) itself: near e = 80 the
//!   CDF is flat (cdf ≈ 1091, one f32 ulp of it moves e by 2e-5°, ~5e-4 px at r_max ≈ 1926 px),
//!   so the plain difference lets Rust and GLSL land a few such steps apart (2.0e-3 px measured);
//!   the tail is accurate relative to itself there. Measured worst: 5.0e-4 px.
//! - grid → screen, headset eccentricity axis (always the exact inverse CDF): < 1e-3 px for
//!   samples on the screen (measured worst 4.4e-4 px at 1280×1440). Samples off the screen are
//!   held to 1e-5 of their distance from the gaze instead (measured ≤ 4.3e-6, i.e. up to 2.4e-3 px
//!   some thousand pixels out): toward the image plane's horizon the distance a·sin e/(h·cos e −
//!   b·sin e) magnifies one ulp of e or of the driver's sin/cos (an op-for-op sin/cos was tried
//!   and changed nothing measurable), and nothing off the screen is ever displayed.
//! - log-polar law (log_polar.rs / log_polar.glsl, plain-arithmetic exp and ln on both sides):
//!   the paper's bounds, on-screen samples < 1e-3 px, off-screen ones (the diagonal extent) 1e-5
//!   of their distance from the gaze.
//! - screen → grid: x and y each < 1e-3 texel (a texel is ≥ ~0.3 px in the fovea, far more
//!   outside). y is compared as the angle φ wrapped to [−π, π) and then expressed in rows, so the
//!   seam (y ≈ 0 vs y ≈ n) and column-boundary cases compare correctly. In arc length at the far
//!   corner this is up to ~5e-3 px: one ulp of φ ≈ 2π is 4.8e-7 rad, ~1e-3 px at r = 1926 px.
//!   Screen-clipped columns lay their rows on the on-screen arcs only (total angle A), so one of
//!   their rows spans A/2π of a paper row and the same φ difference (atan differing by a few ulp
//!   between Rust and the driver) is 2π/A times more rows: up to ~0.4 rows where a far corner's
//!   arc is short. Their bound is the paper's angular one: φ within 1e-3 of a paper row (2π/n).

use fovea_renderer::graph::{read_buffer, read_texels, write_buffer, FrameRecorder};
use fovea_renderer::layouts::VpProbePush;
use fovea_renderer::sampling::{
    Eccentricity, FovTangents, InverseCdf, LogPolarExtent, LogPolarParams, RadialLaw, VisualPolar,
    VisualPolarParams, VpLayout,
};
use fovea_renderer::vk::{Buffer, ComputePipeline};
use fovea_tests::{assert_clean, gpu};
use glam::{IVec2, UVec2, UVec4, Vec2, Vec4};
use std::f32::consts::TAU;

const POINTS: usize = 12_000;
const SCREEN_BOUND_PX: f32 = 1e-3;
const GRID_BOUND: f32 = 1e-3;
/// Off-screen headset samples: error relative to their distance from the gaze.
const RELATIVE_BOUND_HEADSET_OFF_SCREEN: f32 = 1e-5;

/// splitmix64: deterministic, no dependency.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    fn f(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }
    fn below(&mut self, n: u32) -> u32 {
        (self.next() % n as u64) as u32
    }
}

/// Valid continuous grid coordinates (a kept texel plus jitter): half anywhere, half in the
/// clipped fovea columns, plus the corners of the layout. With the headset axis only samples that
/// land within one screen size of the screen: beyond, the cone meets the image-plane ray near its
/// horizon, where the closed-form distance grows without bound (and ulps of e become pixels), or
/// not at all (parked far away on both sides).
fn grid_points(vp: &VisualPolar, rng: &mut Rng, n: usize) -> Vec<Vec2> {
    let g = vp.grid_size();
    let fovea_cols = ((vp.u_fovea() * g.x as f32).ceil() as u32).clamp(1, g.x);
    let mut out = vec![
        Vec2::ZERO,
        Vec2::new(0.5, 0.5),
        Vec2::new(g.x as f32 - 0.5, g.y as f32 - 0.5),
        Vec2::new(vp.u_fovea() * g.x as f32, 0.25),
    ];
    while out.len() < n {
        let col = if out.len() % 2 == 0 {
            rng.below(g.x)
        } else {
            rng.below(fovea_cols)
        };
        let rows = vp.rows_in_column(col);
        let row = rng.below(rows);
        assert!(vp.is_valid_texel(IVec2::new(col as i32, row as i32)));
        // Jitter in [0, 1), kept strictly inside the texel so floor(x) stays the column.
        let p = Vec2::new(
            col as f32 + rng.f().min(0.999),
            row as f32 + rng.f().min(0.999),
        );
        if vp.headset().is_some() {
            let (s, q) = (vp.screen().as_vec2(), vp.vp_to_screen(p));
            if q.x < -s.x || q.y < -s.y || q.x > 2.0 * s.x || q.y > 2.0 * s.y {
                continue;
            }
        }
        out.push(p);
    }
    out
}

/// On-screen positions: half uniform over the screen, half within a few fovea radii of the gaze.
fn screen_points(vp: &VisualPolar, rng: &mut Rng, n: usize) -> Vec<Vec2> {
    let s = vp.screen().as_vec2();
    let gaze = vp.gaze();
    let mut out = vec![
        gaze,
        Vec2::ZERO,
        s - Vec2::splat(0.5),
        gaze + Vec2::new(vp.r_fovea(), 0.0),
    ];
    out.retain(|p| p.x >= 0.0 && p.y >= 0.0 && p.x < s.x && p.y < s.y);
    while out.len() < n {
        let p = if out.len() % 2 == 0 {
            Vec2::new(rng.f() * s.x, rng.f() * s.y)
        } else {
            let r = rng.f() * 3.0 * vp.r_fovea();
            let a = rng.f() * TAU;
            gaze + r * Vec2::new(a.cos(), a.sin())
        };
        if p.x >= 0.0 && p.y >= 0.0 && p.x < s.x && p.y < s.y {
            out.push(p);
        }
    }
    out
}

struct CaseResult {
    screen_px: f32,
    /// The grid → screen error over samples that land on the screen.
    screen_px_on_screen: f32,
    /// The grid → screen error of samples off the screen relative to their distance from the gaze.
    screen_relative_off_screen: f32,
    grid_x: f32,
    grid_y: f32,
    grid_arc_px: f32,
    /// The φ error in rows of the paper's layout (2π/n each): the screen-clipped bound.
    grid_y_paper_rows: f32,
}

fn run_case(
    ctx: &std::sync::Arc<fovea_renderer::vk::Context>,
    pipeline: &ComputePipeline,
    recorder: &mut FrameRecorder,
    vp: &VisualPolar,
    seed: u64,
) -> CaseResult {
    let mut rng = Rng(seed);
    let grid_in = grid_points(vp, &mut rng, POINTS);
    let screen_in = screen_points(vp, &mut rng, POINTS);
    let input: Vec<Vec4> = grid_in
        .iter()
        .zip(&screen_in)
        .map(|(g, s)| Vec4::new(g.x, g.y, s.x, s.y))
        .collect();

    let storage = ash::vk::BufferUsageFlags::STORAGE_BUFFER;
    let params = Buffer::with_data(ctx, "vp_params", &[vp.sampling_params()], storage).unwrap();
    let points = Buffer::with_data(ctx, "vp_points", &input, storage).unwrap();
    let columns = Buffer::texels(ctx, "vp_columns", &vp.column_table()).unwrap();
    let mapped = Buffer::new(
        ctx,
        "vp_mapped",
        (POINTS * 16) as u64,
        storage,
        gpu_allocator::MemoryLocation::GpuToCpu,
    )
    .unwrap();
    let push = VpProbePush {
        config: UVec4::new(POINTS as u32, 0, 0, 0),
    };
    recorder.begin().unwrap();
    let binds = [
        read_buffer("sampling", &params),
        read_buffer("points", &points),
        write_buffer("mapped", &mapped),
        read_texels("vp_columns", &columns),
    ];
    recorder
        .dispatch(
            "vp_mapping_probe",
            pipeline,
            &binds,
            bytemuck::bytes_of(&push),
            [POINTS as u32, 1, 1],
        )
        .unwrap();
    recorder.submit_and_wait().unwrap();
    let got: Vec<Vec4> = mapped.read().unwrap();

    let mut res = CaseResult {
        screen_px: 0.0,
        screen_px_on_screen: 0.0,
        screen_relative_off_screen: 0.0,
        grid_x: 0.0,
        grid_y: 0.0,
        grid_arc_px: 0.0,
        grid_y_paper_rows: 0.0,
    };
    let mut worst = (Vec2::ZERO, Vec2::ZERO);
    for (i, o) in got[..POINTS].iter().enumerate() {
        // Grid → screen.
        let want = vp.vp_to_screen(grid_in[i]);
        let e = (Vec2::new(o.x, o.y) - want).length();
        let size = vp.screen().as_vec2();
        if want.x >= 0.0 && want.y >= 0.0 && want.x < size.x && want.y < size.y {
            res.screen_px_on_screen = res.screen_px_on_screen.max(e);
        } else {
            res.screen_relative_off_screen = res
                .screen_relative_off_screen
                .max(e / (want - vp.gaze()).length());
        }
        if e > res.screen_px {
            res.screen_px = e;
            worst.0 = grid_in[i];
        }
        // Screen → grid: x in texels; φ compared as an angle (wrapped; each side with its own
        // column's rows and arcs, in case the two land on either side of a column boundary),
        // then expressed in rows of the Rust column.
        let want = vp.screen_to_vp(screen_in[i]);
        let gpu = Vec2::new(o.z, o.w);
        let ex = (gpu.x - want.x).abs();
        let phi_of = |g: Vec2| {
            let col = vp.column_of(g.x);
            let arcs = vp.column_arcs(col);
            (
                arcs.phi_of_arc(g.y / vp.rows_in_column(col) as f32 * arcs.total()),
                arcs.total(),
            )
        };
        let ((phi_cpu, total_cpu), (phi_gpu, _)) = (phi_of(want), phi_of(gpu));
        let mut dphi = (phi_gpu - phi_cpu).rem_euclid(TAU);
        dphi = dphi.min(TAU - dphi);
        let n_cpu = vp.rows_in_column(vp.column_of(want.x)) as f32;
        let ey = dphi / total_cpu * n_cpu;
        let arc = dphi * (screen_in[i] - vp.gaze()).length();
        res.grid_y_paper_rows = res.grid_y_paper_rows.max(dphi / TAU * n_cpu);
        if ex.max(ey) > res.grid_x.max(res.grid_y) {
            worst.1 = screen_in[i];
        }
        res.grid_x = res.grid_x.max(ex);
        res.grid_y = res.grid_y.max(ey);
        res.grid_arc_px = res.grid_arc_px.max(arc);
    }
    println!(
        "    worst grid input {:?}, worst screen input {:?}",
        worst.0, worst.1
    );
    res
}

#[test]
fn rust_and_glsl_visual_polar_mappings_agree() {
    let ctx = gpu();
    let pipeline = ComputePipeline::new(
        &ctx,
        "passes/vp_mapping_probe",
        std::mem::size_of::<VpProbePush>() as u32,
    )
    .unwrap();
    let mut recorder = FrameRecorder::new(&ctx, 4).unwrap();
    let mut failures = Vec::new();
    let mut seed = 1u64;
    for screen in [UVec2::new(1280, 1440), UVec2::new(640, 720)] {
        let s = screen.as_vec2();
        let gazes = [
            ("centre", s * 0.5),
            ("edge", Vec2::new(0.02, 0.45) * s),
            ("corner", Vec2::new(0.97, 0.985) * s),
        ];
        for (gaze_name, gaze) in gazes {
            for (inverse_cdf, layout) in [
                (InverseCdf::Polynomial, VpLayout::Paper),
                (InverseCdf::Exact, VpLayout::Paper),
                (InverseCdf::Polynomial, VpLayout::ScreenClipped),
                (InverseCdf::Exact, VpLayout::ScreenClipped),
                (InverseCdf::Polynomial, VpLayout::ScreenAware),
            ] {
                let params = VisualPolarParams {
                    inverse_cdf,
                    layout,
                    ..Default::default()
                };
                let vp = VisualPolar::new(screen, gaze, params).unwrap();
                seed += 1;
                let r = run_case(&ctx, &pipeline, &mut recorder, &vp, seed);
                let line = format!(
                    "{}x{} gaze {gaze_name} {inverse_cdf:?} {layout:?}: grid→screen {:.2e} px, screen→grid x {:.2e} / y {:.2e} \
                     texels (φ arc {:.2e} px, {:.2e} paper rows)",
                    screen.x, screen.y, r.screen_px, r.grid_x, r.grid_y, r.grid_arc_px, r.grid_y_paper_rows
                );
                println!("{line}");
                let phi_ok = match layout {
                    VpLayout::Paper => r.grid_y < GRID_BOUND,
                    VpLayout::ScreenClipped | VpLayout::ScreenAware => {
                        r.grid_y_paper_rows < GRID_BOUND
                    }
                };
                if !(r.screen_px < SCREEN_BOUND_PX && r.grid_x < GRID_BOUND && phi_ok) {
                    failures.push(line);
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "Rust and GLSL disagree:\n{}",
        failures.join("\n")
    );
    assert_clean(&ctx);
}

/// The headset-aware axis (true eccentricity through the FOV tangents; always the exact inverse
/// CDF): FOVE 0 and the Pimax Crystal's wider, asymmetric left eye, gaze at the centre, near an
/// edge and in a corner, two screen sizes.
#[test]
fn rust_and_glsl_headset_mappings_agree() {
    let ctx = gpu();
    let pipeline = ComputePipeline::new(
        &ctx,
        "passes/vp_mapping_probe",
        std::mem::size_of::<VpProbePush>() as u32,
    )
    .unwrap();
    let mut recorder = FrameRecorder::new(&ctx, 4).unwrap();
    let mut failures = Vec::new();
    let mut seed = 100u64;
    let headsets = [
        (
            "fove0",
            FovTangents::from_angles_deg(-45.0, 45.0, -48.4, 48.4),
        ),
        (
            "pimax_crystal",
            FovTangents::from_angles_deg(-51.7, 41.7, -51.9, 51.9),
        ),
    ];
    for (headset, fov) in headsets {
        for screen in [UVec2::new(1280, 1440), UVec2::new(320, 360)] {
            let s = screen.as_vec2();
            let gazes = [
                ("centre", s * 0.5),
                ("edge", Vec2::new(0.02, 0.45) * s),
                ("corner", Vec2::new(0.97, 0.985) * s),
            ];
            for (gaze_name, gaze) in gazes {
                let params = VisualPolarParams {
                    eccentricity: Eccentricity::Headset(fov),
                    ..Default::default()
                };
                let vp = VisualPolar::new(screen, gaze, params).unwrap();
                seed += 1;
                let r = run_case(&ctx, &pipeline, &mut recorder, &vp, seed);
                let line = format!(
                    "{headset} {}x{} gaze {gaze_name}: grid→screen {:.2e} px ({:.2e} px on screen, {:.2e} of the distance \
                     off it), screen→grid x {:.2e} / y {:.2e} texels",
                    screen.x, screen.y, r.screen_px, r.screen_px_on_screen, r.screen_relative_off_screen, r.grid_x, r.grid_y
                );
                println!("{line}");
                let screen_ok = r.screen_px_on_screen < SCREEN_BOUND_PX
                    && r.screen_relative_off_screen < RELATIVE_BOUND_HEADSET_OFF_SCREEN;
                if !(screen_ok && r.grid_x < GRID_BOUND && r.grid_y < GRID_BOUND) {
                    failures.push(line);
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "Rust and GLSL disagree:\n{}",
        failures.join("\n")
    );
    assert_clean(&ctx);
}

/// One polar space with a radial law other than the acuity's through the probe: its line, printed,
/// and returned when Rust and GLSL disagree beyond the bounds. Rows span 2π however many there are,
/// so the driver's atan error in rows grows with the grid's height: the row bound is `GRID_BOUND`
/// up to 800 rows and scales beyond (composite's tallest grid has 1688).
fn polar_law_case(
    ctx: &std::sync::Arc<fovea_renderer::vk::Context>,
    pipeline: &ComputePipeline,
    recorder: &mut FrameRecorder,
    vp: &VisualPolar,
    seed: u64,
    label: &str,
) -> Option<String> {
    let r = run_case(ctx, pipeline, recorder, vp, seed);
    let line = format!(
        "{label}: grid→screen {:.2e} px on screen ({:.2e} of the distance off it), screen→grid x {:.2e} / y {:.2e} texels",
        r.screen_px_on_screen, r.screen_relative_off_screen, r.grid_x, r.grid_y
    );
    println!("{line}");
    let screen_ok = r.screen_px_on_screen < SCREEN_BOUND_PX && r.screen_relative_off_screen < 1e-5;
    let rows_bound = GRID_BOUND * (vp.grid_size().y as f32 / 800.0).max(1.0);
    (!(screen_ok && r.grid_x < GRID_BOUND && r.grid_y < rows_bound)).then_some(line)
}

/// Composite foveation (Andersson & Hansson 2020): the gaze disc as a linear fovea and the
/// log-polar law from the disc's edge, their four modes, through the same probe.
#[test]
fn rust_and_glsl_composite_mappings_agree() {
    use fovea_renderer::sampling::CompositeMode;
    let ctx = gpu();
    let pipeline = ComputePipeline::new(
        &ctx,
        "passes/vp_mapping_probe",
        std::mem::size_of::<VpProbePush>() as u32,
    )
    .unwrap();
    let mut recorder = FrameRecorder::new(&ctx, 4).unwrap();
    let mut failures = Vec::new();
    let mut seed = 300u64;
    for screen in [UVec2::new(1280, 1440), UVec2::new(320, 360)] {
        let s = screen.as_vec2();
        for (gaze_name, gaze) in [("centre", s * 0.5), ("corner", Vec2::new(0.97, 0.985) * s)] {
            for mode in [
                CompositeMode::Fov,
                CompositeMode::Kernel,
                CompositeMode::Composite,
                CompositeMode::CompositeKernel,
            ] {
                let radial = RadialLaw::Composite(mode.params(s.x / 2.0));
                let vp = VisualPolar::new(
                    screen,
                    gaze,
                    VisualPolarParams {
                        radial,
                        ..Default::default()
                    },
                )
                .unwrap();
                seed += 1;
                let label = format!(
                    "composite {}x{} gaze {gaze_name} {}",
                    screen.x,
                    screen.y,
                    mode.name()
                );
                failures.extend(polar_law_case(
                    &ctx,
                    &pipeline,
                    &mut recorder,
                    &vp,
                    seed,
                    &label,
                ));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "Rust and GLSL disagree:\n{}",
        failures.join("\n")
    );
    assert_clean(&ctx);
}

/// The log-polar radial law (Meng et al. 2018) through the same probe: α 4 (Meng) and 1 (plain
/// log-polar), L from the farthest corner and from the diagonal, gaze at the centre, near an edge
/// and in a corner, two screen sizes.
#[test]
fn rust_and_glsl_log_polar_mappings_agree() {
    let ctx = gpu();
    let pipeline = ComputePipeline::new(
        &ctx,
        "passes/vp_mapping_probe",
        std::mem::size_of::<VpProbePush>() as u32,
    )
    .unwrap();
    let mut recorder = FrameRecorder::new(&ctx, 4).unwrap();
    let mut failures = Vec::new();
    let mut seed = 200u64;
    for screen in [UVec2::new(1280, 1440), UVec2::new(320, 360)] {
        let s = screen.as_vec2();
        let gazes = [
            ("centre", s * 0.5),
            ("edge", Vec2::new(0.02, 0.45) * s),
            ("corner", Vec2::new(0.97, 0.985) * s),
        ];
        for (gaze_name, gaze) in gazes {
            for (alpha, extent) in [
                (4.0, LogPolarExtent::FarthestCorner),
                (4.0, LogPolarExtent::Diagonal),
                (1.0, LogPolarExtent::FarthestCorner),
            ] {
                let lp = LogPolarParams {
                    alpha,
                    extent,
                    ..Default::default()
                };
                let vp = VisualPolar::new(
                    screen,
                    gaze,
                    VisualPolarParams {
                        radial: RadialLaw::LogPolar(lp),
                        ..Default::default()
                    },
                )
                .unwrap();
                seed += 1;
                let label = format!(
                    "log-polar {}x{} gaze {gaze_name} α {alpha} {extent:?}",
                    screen.x, screen.y
                );
                failures.extend(polar_law_case(
                    &ctx,
                    &pipeline,
                    &mut recorder,
                    &vp,
                    seed,
                    &label,
                ));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "Rust and GLSL disagree:\n{}",
        failures.join("\n")
    );
    assert_clean(&ctx);
}
