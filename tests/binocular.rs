//! Binocular consistency in stereo (docs/design/random-numbers.md): the measure of
//! `fovea quality --eyes both` (`fovea_tools::eval::binocular`: the right eye warped into the left
//! through the converged depth) on the engine's two views, and the surface-correlated noise
//! (`StereoNoise::Surface`): its random numbers are uniform in every ring of eccentricity and
//! independent between neighbouring cells, and one eye's quality is not worse for it.

use fovea_renderer::frame::{
    CameraPose, CrossEyeReuse, FrameInput, RenderSettings, StereoNoise, ViewInput,
};
use fovea_renderer::gpu_scene::GpuScene;
use fovea_renderer::passes::denoise::svgf::SvgfSettings;
use fovea_renderer::passes::denoise::DenoiserSettings;
use fovea_renderer::passes::resampling::{ResamplingMode, ResamplingSettings};
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::{Cartesian, SamplingSpace};
use fovea_renderer::scene::bvh::instanced::SceneBvh;
use fovea_renderer::scene::bvh::BvhBuilder;
use fovea_renderer::scene::Scene;
use fovea_renderer::vk::Context;
use fovea_tests::{assert_clean, assert_pictures_equal, gpu, Picture};
use fovea_tools::eval::binocular::{difference_map, EyeGeometry, Warp};
use fovea_tools::eval::metrics::{mean, Rings};
use fovea_tools::output::tonemap_preview;
use glam::{Mat4, UVec2, Vec3};
use std::sync::Arc;

const SCREEN: UVec2 = UVec2::new(64, 72);
/// Half the FOVE 0's eye distance (metres, the glTF unit).
const HALF_IPD: f32 = 0.0315;
const RINGS: usize = 4;
/// Frames each stereo run renders (SVGF's history fills over them).
const FRAMES: u32 = 6;

fn cornell() -> (Scene, CameraPose) {
    let scene = fovea_tests::owned_scene("cornell-box");
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], SCREEN.x, SCREEN.y);
    (scene, camera)
}

fn eye(head: &CameraPose, dx: f32) -> CameraPose {
    CameraPose {
        world_from_view: head.world_from_view * Mat4::from_translation(Vec3::new(dx, 0.0, 0.0)),
        fov_tan: head.fov_tan,
    }
}

fn svgf(noise: StereoNoise) -> RenderSettings {
    RenderSettings {
        denoiser: DenoiserSettings::Svgf(SvgfSettings::default()),
        stereo_noise: noise,
        ..Default::default()
    }
}

/// The displayed (tonemapped) left and right images of the last of `FRAMES` still frames, the
/// eyes `2 × half_ipd` apart, in Cartesian space.
fn stereo_pair(
    ctx: &Arc<Context>,
    scene: &Scene,
    head: &CameraPose,
    settings: RenderSettings,
    half_ipd: f32,
) -> (Vec<u8>, Vec<u8>) {
    let spaces: Vec<Box<dyn SamplingSpace>> = vec![
        Box::new(Cartesian::new(SCREEN)),
        Box::new(Cartesian::new(SCREEN)),
    ];
    let mut r = Renderer::with_views(
        ctx,
        GpuScene::upload(ctx, scene).unwrap(),
        spaces,
        settings,
        1,
    )
    .unwrap();
    let views = [
        ViewInput {
            camera: eye(head, -half_ipd),
            gaze: None,
        },
        ViewInput {
            camera: eye(head, half_ipd),
            gaze: None,
        },
    ];
    let mut last = 0;
    for f in 0..FRAMES {
        last = r
            .submit(&FrameInput::views(&views, f).unwrap(), None)
            .unwrap();
        r.wait_frame(last).unwrap();
    }
    let read = |view| {
        let mut out = Vec::new();
        r.read_view_ldr(last, view, &mut out).unwrap();
        out
    };
    (read(0), read(1))
}

/// The converged pair (1024 spp per eye: its own noise would otherwise dominate the
/// difference), displayed.
fn reference_pair(ctx: &Arc<Context>, scene: &Scene, head: &CameraPose) -> (Vec<u8>, Vec<u8>) {
    let mut r = Renderer::new(
        ctx,
        scene,
        Box::new(Cartesian::new(SCREEN)),
        RenderSettings::default(),
    )
    .unwrap();
    let mut one = |dx| {
        let hdr = r.render_reference(&eye(head, dx), 1024, 3, |_| {}).unwrap();
        tonemap_preview(&hdr, 1.0, fovea_renderer::passes::tonemap::ToneCurve::Aces)
    };
    (one(-HALF_IPD), one(HALF_IPD))
}

/// The right eye warped into the left, for eyes `2 × half_ipd` apart.
fn warp(scene: &Scene, head: &CameraPose, half_ipd: f32) -> Warp {
    let bvh = SceneBvh::build(scene, BvhBuilder::BINNED);
    let geometry = |dx| EyeGeometry::trace(&bvh, eye(head, dx), SCREEN.x, SCREEN.y);
    Warp::new(&geometry(-half_ipd), &geometry(half_ipd))
}

/// Per ring around the image centre, then the whole frame.
fn ring_means(map: &[f64]) -> Vec<f64> {
    let rings = Rings::new(SCREEN.x, SCREEN.y, SCREEN.as_vec2() * 0.5, RINGS);
    let mut v: Vec<f64> = rings.mean(map).into_iter().map(|m| m.unwrap()).collect();
    v.push(mean(map).unwrap());
    v
}

fn show(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:.4}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Both eyes at one position on a still scene: with shared noise (screen or surface seeds) the
/// denoised eyes are identical, with cross-eye reuse too, and the measure is 0 everywhere (every
/// pixel seen by both); independent noise gives a difference the measure sees.
#[test]
fn both_eyes_at_one_position_give_identical_denoised_images_and_a_zero_measure() {
    let ctx = gpu();
    let (scene, head) = cornell();
    let warp = warp(&scene, &head, 0.0);
    let n = (SCREEN.x * SCREEN.y) as usize;
    assert!((0..n).all(|i| warp.covers(i)), "one eye sees what it sees");
    let modes = [StereoNoise::Screen, StereoNoise::Surface]
        .into_iter()
        .flat_map(|noise| [(noise, false), (noise, true)]);
    for (noise, reuse) in modes {
        let settings = RenderSettings {
            cross_eye_reuse: if reuse {
                CrossEyeReuse::On
            } else {
                CrossEyeReuse::Off
            },
            ..svgf(noise)
        };
        let (left, right) = stereo_pair(&ctx, &scene, &head, settings, 0.0);
        assert_pictures_equal(
            &format!(
                "{} noise, SVGF, cross-eye reuse {reuse}, one eye position: right eye against left",
                noise.name()
            ),
            &Picture::rgba8(SCREEN.x, SCREEN.y, &right),
            &Picture::rgba8(SCREEN.x, SCREEN.y, &left),
        );
        let d = difference_map(&left, &right, &warp);
        assert!(d.iter().all(|&v| v == 0.0), "{} noise", noise.name());
    }
    let (left, right) = stereo_pair(&ctx, &scene, &head, svgf(StereoNoise::Independent), 0.0);
    let independent = ring_means(&difference_map(&left, &right, &warp));
    println!(
        "one position, independent noise after SVGF: {}",
        show(&independent)
    );
    assert!(
        independent.iter().all(|&v| v > 1e-3),
        "independent noise differs between the eyes: {independent:?}"
    );
    assert_clean(&ctx);
}

/// At the FOVE 0's eye distance the measure is finite in every ring and the converged pair's
/// (view-dependent shading and resampling alone) lies below independent noise's after SVGF.
/// Prints each noise's difference per ring beside the pair's.
#[test]
fn at_the_fove0_eye_distance_the_converged_pair_differs_less_than_independent_noise() {
    let ctx = gpu();
    let (scene, head) = cornell();
    let warp = warp(&scene, &head, HALF_IPD);
    let covered = (0..(SCREEN.x * SCREEN.y) as usize)
        .filter(|&i| warp.covers(i))
        .count() as f64
        / (SCREEN.x * SCREEN.y) as f64;
    assert!(covered > 0.8, "{covered} of the pixels seen by both eyes");
    let (ref_left, ref_right) = reference_pair(&ctx, &scene, &head);
    let pair = ring_means(&difference_map(&ref_left, &ref_right, &warp));
    let measure = |noise| {
        let (left, right) = stereo_pair(&ctx, &scene, &head, svgf(noise), HALF_IPD);
        ring_means(&difference_map(&left, &right, &warp))
    };
    let independent = measure(StereoNoise::Independent);
    println!(
        "binocular difference at 63 mm after SVGF, {RINGS} rings + frame ({:.0} % seen by both):\n  converged pair {}\n  independent    {}",
        100.0 * covered,
        show(&pair),
        show(&independent)
    );
    for noise in [StereoNoise::Screen, StereoNoise::Surface] {
        println!("  {:<14} {}", noise.name(), show(&measure(noise)));
    }
    assert!(independent.iter().all(|v| v.is_finite()));
    for (ring, (p, i)) in pair.iter().zip(&independent).enumerate() {
        assert!(p < i, "ring {ring}: converged pair {p} vs independent {i}");
    }
    assert_clean(&ctx);
}

/// The first number each traced sample's path draws after the primary hit, from the A-SVGF
/// G-buffer's random state (`GBuffer::visibility`, z), with the texel's screen position; texels
/// that missed (their path keeps the screen seed) or hold no sample are left out.
struct PathState {
    state: u32,
    screen: glam::Vec2,
}

fn path_states(r: &Renderer, space_screens: &[Option<glam::Vec2>]) -> Vec<Option<PathState>> {
    let ctx = r.context();
    let g = &r.view(0).gbuffer;
    let visibility: Vec<[u32; 4]> =
        fovea_tests::read_image(ctx, g.visibility.as_ref().expect("A-SVGF's G-buffer"));
    let ids: Vec<[u32; 2]> = fovea_tests::read_image(ctx, &g.ids);
    visibility
        .iter()
        .zip(&ids)
        .zip(space_screens)
        .map(|((v, id), screen)| {
            // Sign bit of w: a sample that hit a surface (without resampling every such sample
            // may be its stratum's gradient source).
            let keep = id[0] != 0 && v[3] & 0x8000_0000 != 0;
            Some(PathState {
                state: v[2],
                screen: (*screen)?,
            })
            .filter(|_| keep)
        })
        .collect()
}

/// `rng_next` of random.glsl: the uniform number a state gives.
fn first_uniform(state: u32) -> f64 {
    (fovea_renderer::sampling::random::pcg_hash(state) >> 8) as f64 / 16_777_216.0
}

/// χ² of the surface seeds in Visual-Polar space, where the footprint (and so the cell's level)
/// grows with eccentricity. Per ring around the gaze: the first number each surface cell's paths
/// draw is uniform (16 cells of [0, 1), one count per surface cell: its samples all draw it), and
/// the numbers of neighbouring texels in different surface cells are independent (4 × 4 cells of
/// the pair's numbers, each cell in one pair at most). Šidák-corrected over the rings and both
/// tests. Prints the share of neighbouring samples that share a cell.
#[test]
fn surface_seeds_are_uniform_and_independent_between_cells_in_every_ring() {
    use fovea_renderer::sampling::{VisualPolar, VisualPolarParams};
    use fovea_test_kit::chi2::{chi2_test, sidak};
    const VP_SCREEN: UVec2 = UVec2::new(128, 144);
    const BINS: usize = 16;
    const PAIR_BINS: usize = 4;
    let ctx = gpu();
    let scene = fovea_tests::owned_scene("cornell-box");
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], VP_SCREEN.x, VP_SCREEN.y);
    let gaze = VP_SCREEN.as_vec2() * glam::Vec2::new(0.4, 0.55);
    let space = VisualPolar::new(VP_SCREEN, gaze, VisualPolarParams::default()).unwrap();
    let grid = space.grid_size();
    let screens = fovea_tests::denoise::texel_screens(&space);
    let settings = RenderSettings {
        denoiser: DenoiserSettings::Asvgf(Default::default()),
        stereo_noise: StereoNoise::Surface,
        ..Default::default()
    };
    let mut r = Renderer::new(&ctx, &scene, Box::new(space), settings).unwrap();
    let r_max = [0.0, VP_SCREEN.x as f32]
        .iter()
        .flat_map(|&x| [0.0, VP_SCREEN.y as f32].map(|y| (glam::Vec2::new(x, y) - gaze).length()))
        .fold(0.0, f32::max);
    let ring_of =
        |p: glam::Vec2| (((p - gaze).length() / r_max * RINGS as f32) as usize).min(RINGS - 1);
    let mut single = vec![vec![0.0; BINS]; RINGS];
    let mut pairs = vec![vec![0.0; PAIR_BINS * PAIR_BINS]; RINGS];
    let (mut shared, mut neighbours) = (0usize, 0usize);
    for f in 0..8 {
        r.render_frame(&FrameInput::mono(camera, f, Some(gaze)))
            .unwrap();
        let states = path_states(&r, &screens);
        // One count per surface cell: its samples all draw the same number.
        let mut counted = std::collections::HashSet::new();
        let mut paired = std::collections::HashSet::new();
        for (i, s) in states.iter().enumerate() {
            let Some(s) = s else { continue };
            let u = first_uniform(s.state);
            if counted.insert(s.state) {
                single[ring_of(s.screen)][(u * BINS as f64) as usize] += 1.0;
            }
            // The next texel along ρ and along φ (φ wraps).
            let (x, y) = (i as u32 % grid.x, i as u32 / grid.x);
            let along = [
                (x + 1 < grid.x).then(|| i + 1),
                Some(((y + 1) % grid.y * grid.x + x) as usize),
            ];
            for j in along.into_iter().flatten() {
                let Some(t) = &states[j] else { continue };
                neighbours += 1;
                if t.state == s.state {
                    shared += 1;
                    continue;
                }
                // Disjoint pairs: each cell's number counted in one pair at most, so that the
                // counts are independent under the hypothesis.
                if paired.contains(&s.state) || paired.contains(&t.state) {
                    continue;
                }
                paired.extend([s.state, t.state]);
                let v = first_uniform(t.state);
                let cell = |u: f64| (u * PAIR_BINS as f64) as usize;
                pairs[ring_of(s.screen)][cell(u) * PAIR_BINS + cell(v)] += 1.0;
            }
        }
    }
    let level = sidak(0.01, 2 * RINGS);
    for ring in 0..RINGS {
        let n: f64 = single[ring].iter().sum();
        assert!(n > 1000.0, "ring {ring}: {n} cells");
        let outcome = chi2_test(&single[ring], &[n / BINS as f64; BINS], level)
            .unwrap_or_else(|e| panic!("ring {ring}, first number: {e}"));
        let m: f64 = pairs[ring].iter().sum();
        let pair_outcome = chi2_test(
            &pairs[ring],
            &[m / (PAIR_BINS * PAIR_BINS) as f64; PAIR_BINS * PAIR_BINS],
            level,
        )
        .unwrap_or_else(|e| panic!("ring {ring}, neighbouring cells: {e}"));
        println!("ring {ring}: {n} cells, {outcome}; {m} neighbour pairs in different cells, {pair_outcome}");
    }
    let share = shared as f64 / neighbours as f64;
    println!(
        "neighbouring samples sharing a cell: {:.1} %",
        100.0 * share
    );
    // Cells of 1–2 footprints: a minority of neighbours share one.
    assert!(share < 0.5, "{share}");
    assert_clean(&ctx);
}

/// One eye's own quality is not worse with surface noise than with independent noise: mean FLIP
/// of the left eye against its converged reference over frames 6–11 of a still Visual-Polar stereo
/// run, raw and after SVGF, at the FOVE 0's eye distance, with the default cell (and, printed,
/// with cells of half and twice that).
#[test]
fn surface_noise_keeps_each_eyes_flip() {
    use fovea_renderer::sampling::{VisualPolar, VisualPolarParams};
    let ctx = gpu();
    let (scene, head) = cornell();
    let (reference, _) = reference_pair(&ctx, &scene, &head);
    // FLIP's pixels per degree as `fovea quality` takes them (the FOVE 0's 90° across the width).
    let ppd = SCREEN.x as f32 / 90.0;
    let flip = |denoiser, stereo_noise, surface_cell| {
        let vp = || -> Box<dyn SamplingSpace> {
            let params = VisualPolarParams::default();
            Box::new(VisualPolar::new(SCREEN, SCREEN.as_vec2() * 0.5, params).unwrap())
        };
        let settings = RenderSettings {
            denoiser,
            stereo_noise,
            surface_cell,
            ..Default::default()
        };
        let scene = GpuScene::upload(&ctx, &scene).unwrap();
        let mut r = Renderer::with_views(&ctx, scene, vec![vp(), vp()], settings, 1).unwrap();
        let views = [-HALF_IPD, HALF_IPD].map(|dx| ViewInput {
            camera: eye(&head, dx),
            gaze: None,
        });
        let mut sum = 0.0;
        for f in 0..12 {
            let frame = r
                .submit(&FrameInput::views(&views, f).unwrap(), None)
                .unwrap();
            r.wait_frame(frame).unwrap();
            if f >= 6 {
                let mut left = Vec::new();
                r.read_view_ldr(frame, 0, &mut left).unwrap();
                let map =
                    fovea_tools::eval::flip::flip_map(&reference, &left, SCREEN.x, SCREEN.y, ppd);
                sum += mean(&map).unwrap();
            }
        }
        sum / 6.0
    };
    let cell = RenderSettings::default().surface_cell;
    for denoiser in [
        DenoiserSettings::None,
        DenoiserSettings::Svgf(SvgfSettings::default()),
    ] {
        let independent = flip(denoiser, StereoNoise::Independent, cell);
        let surface = flip(denoiser, StereoNoise::Surface, cell);
        let (half, twice) = (
            flip(denoiser, StereoNoise::Surface, cell * 0.5),
            flip(denoiser, StereoNoise::Surface, cell * 2.0),
        );
        println!(
            "left eye FLIP, VP + {}: independent {independent:.4}, surface {surface:.4} (cells of {} / {} footprints: {half:.4} / {twice:.4})",
            denoiser.name(),
            cell * 0.5,
            cell * 2.0
        );
        // Seeded runs; the margin covers the frames' sampling noise of the mean.
        assert!(
            surface <= independent * 1.02,
            "{}: surface {surface} vs independent {independent}",
            denoiser.name()
        );
    }
    assert_clean(&ctx);
}

/// Cross-eye reuse (`RenderSettings::cross_eye_reuse`): with independent noise at the FOVE 0's
/// eye distance, each eye's samples taking the other eye's sample of the same surface bring the
/// two eyes' displayed frames together (the binocular difference over the frame) and lower each
/// eye's own error (left-eye FLIP against its converged reference), raw and after SVGF, in
/// Cartesian space and in the screen-clipped Visual-Polar grid (each eye its own gaze, so the
/// other eye's sample is found through its own grid), and in VP after ReSTIR DI and GI (each eye
/// shares its resampled samples). Means over frames 4–7 of still runs.
#[test]
fn cross_eye_reuse_brings_the_eyes_together_and_lowers_each_eyes_error() {
    use fovea_renderer::sampling::{VisualPolar, VisualPolarParams, VpLayout};
    const FIRST: u32 = 4;
    const LAST: u32 = 8;
    let ctx = gpu();
    let (scene, head) = cornell();
    let warp = warp(&scene, &head, HALF_IPD);
    let (reference, reference_right) = reference_pair(&ctx, &scene, &head);
    println!(
        "converged pair's difference: {:.4}",
        mean(&difference_map(&reference, &reference_right, &warp)).unwrap()
    );
    let ppd = SCREEN.x as f32 / 90.0;
    let cartesian = |_: f32| -> Box<dyn SamplingSpace> { Box::new(Cartesian::new(SCREEN)) };
    let visual_polar = |x: f32| -> Box<dyn SamplingSpace> {
        let params = VisualPolarParams {
            layout: VpLayout::ScreenClipped,
            ..Default::default()
        };
        let gaze = SCREEN.as_vec2() * glam::Vec2::new(x, 0.5);
        Box::new(VisualPolar::new(SCREEN, gaze, params).unwrap())
    };
    // (difference over the frame, left-eye FLIP), means over the measured frames.
    let run = |space: &dyn Fn(f32) -> Box<dyn SamplingSpace>, denoiser, resampling, reuse| {
        let settings = RenderSettings {
            denoiser,
            resampling: ResamplingSettings::default().with_mode(resampling),
            stereo_noise: StereoNoise::Independent,
            cross_eye_reuse: if reuse {
                CrossEyeReuse::On
            } else {
                CrossEyeReuse::Off
            },
            ..Default::default()
        };
        let gpu_scene = GpuScene::upload(&ctx, &scene).unwrap();
        // The eyes converge a little: each gaze slightly toward the nose.
        let spaces = vec![space(0.52), space(0.48)];
        let mut r = Renderer::with_views(&ctx, gpu_scene, spaces, settings, 1).unwrap();
        let views = [-HALF_IPD, HALF_IPD].map(|dx| ViewInput {
            camera: eye(&head, dx),
            gaze: None,
        });
        let (mut difference, mut flip) = (0.0, 0.0);
        for f in 0..LAST {
            let frame = r
                .submit(&FrameInput::views(&views, f).unwrap(), None)
                .unwrap();
            r.wait_frame(frame).unwrap();
            if f >= FIRST {
                let (mut left, mut right) = (Vec::new(), Vec::new());
                r.read_view_ldr(frame, 0, &mut left).unwrap();
                r.read_view_ldr(frame, 1, &mut right).unwrap();
                difference += mean(&difference_map(&left, &right, &warp)).unwrap();
                let map =
                    fovea_tools::eval::flip::flip_map(&reference, &left, SCREEN.x, SCREEN.y, ppd);
                flip += mean(&map).unwrap();
            }
        }
        let n = (LAST - FIRST) as f64;
        (difference / n, flip / n)
    };
    type SpaceFn<'a> = &'a dyn Fn(f32) -> Box<dyn SamplingSpace>;
    let spaces: [(&str, SpaceFn); 2] = [("Cartesian", &cartesian), ("VP", &visual_polar)];
    let svgf = DenoiserSettings::Svgf(SvgfSettings::default());
    let cases = spaces
        .into_iter()
        .flat_map(|(name, space)| {
            [DenoiserSettings::None, svgf].map(|d| (name, space, d, ResamplingMode::Off))
        })
        // Resampling runs before the reuse: each eye's resampled samples are what it shares.
        .chain([("VP", spaces[1].1, svgf, ResamplingMode::DiGi)]);
    for (name, space, denoiser, resampling) in cases {
        let (d_off, f_off) = run(space, denoiser, resampling, false);
        let (d_on, f_on) = run(space, denoiser, resampling, true);
        let what = format!(
            "{name} + {}, resampling {}",
            denoiser.name(),
            resampling.name()
        );
        println!(
            "{what}: difference {d_off:.4} → {d_on:.4} ({:.2}×), left-eye FLIP {f_off:.4} → {f_on:.4}",
            d_on / d_off
        );
        // Raw, the merged samples agree by construction where both eyes see the surface;
        // SVGF's own spatial filter leaves less to bring together.
        let bound = if denoiser == DenoiserSettings::None {
            0.6
        } else {
            0.95
        };
        assert!(d_on < bound * d_off, "{what}: difference {d_off} → {d_on}");
        assert!(f_on < f_off, "{what}: left-eye FLIP {f_off} → {f_on}");
    }
    assert_clean(&ctx);
}

/// Cross-eye reuse needs a grid the filters address: a space without temporal filters refuses
/// `on` by name and runs without it under `auto`; one view ignores it.
#[test]
fn cross_eye_reuse_is_refused_by_name_where_the_grid_has_no_filters() {
    use fovea_renderer::sampling::{
        FalloffShape, LinearFalloff, VisualPolarParams, FALLOFF_BUDGET_OF_VP,
    };
    let ctx = gpu();
    let (scene, _) = cornell();
    let settings = RenderSettings {
        cross_eye_reuse: CrossEyeReuse::On,
        ..Default::default()
    };
    let falloff = || -> Box<dyn SamplingSpace> {
        let params = VisualPolarParams::default();
        let shape = FalloffShape::default();
        Box::new(LinearFalloff::new(SCREEN, params, shape, FALLOFF_BUDGET_OF_VP).unwrap())
    };
    let gpu_scene = GpuScene::upload(&ctx, &scene).unwrap();
    let error = Renderer::with_views(&ctx, gpu_scene, vec![falloff(), falloff()], settings, 1)
        .err()
        .expect("refused")
        .to_string();
    assert!(
        error.contains("cross-eye reuse") && error.contains("linear-falloff"),
        "{error}"
    );
    let gpu_scene = GpuScene::upload(&ctx, &scene).unwrap();
    let mono = Renderer::with_views(&ctx, gpu_scene, vec![falloff()], settings, 1).unwrap();
    assert!(!mono.reuses_across_eyes());
    let auto = RenderSettings {
        cross_eye_reuse: CrossEyeReuse::Auto,
        ..settings
    };
    let gpu_scene = GpuScene::upload(&ctx, &scene).unwrap();
    let r = Renderer::with_views(&ctx, gpu_scene, vec![falloff(), falloff()], auto, 1).unwrap();
    assert!(
        !r.reuses_across_eyes(),
        "auto: off where the eyes cannot share"
    );
    assert_clean(&ctx);
}

/// A renderer replacing one view by two (`Renderer::replace_views`, as `fovea view` does) starts
/// sharing between the eyes: its frame ring grows for the cross-eye passes' timestamps and the
/// stereo frames run without a validation message.
#[test]
fn replacing_one_view_by_two_starts_cross_eye_reuse() {
    let ctx = gpu();
    let (scene, head) = cornell();
    let settings = RenderSettings {
        cross_eye_reuse: CrossEyeReuse::On,
        ..svgf(StereoNoise::Screen)
    };
    let cartesian = || -> Box<dyn SamplingSpace> { Box::new(Cartesian::new(SCREEN)) };
    let gpu_scene = GpuScene::upload(&ctx, &scene).unwrap();
    let mut r = Renderer::with_views(&ctx, gpu_scene, vec![cartesian()], settings, 2).unwrap();
    assert!(!r.reuses_across_eyes());
    r.render_frame(&FrameInput::mono(head, 0, None)).unwrap();
    r.replace_views(vec![cartesian(), cartesian()], settings)
        .unwrap();
    assert!(r.reuses_across_eyes());
    let views = [-HALF_IPD, HALF_IPD].map(|dx| ViewInput {
        camera: eye(&head, dx),
        gaze: None,
    });
    for f in 1..4 {
        r.submit(&FrameInput::views(&views, f).unwrap(), None)
            .unwrap();
    }
    r.finish().unwrap();
    let names: Vec<(&str, u32)> = r.timings().iter().map(|p| (p.name, p.view)).collect();
    for pass in ["cross_eye", "cross_eye_resolve"] {
        for view in 0..2 {
            assert!(
                names.contains(&(pass, view)),
                "{pass} of view {view}: {names:?}"
            );
        }
    }
    assert_clean(&ctx);
}
