//! The Visual-Polar part of `fovea bench`: whole frames in VP vs Cartesian at full
//! resolution on the same scene, gaze and device, per pass; the share of the way back to the
//! screen (φ-mips + remap + blur); and primary-ray coherence: the VP samples traced in VP order
//! vs the same rays shuffled.

use anyhow::Result;
use fovea_renderer::frame::{CameraPose, FrameInput, OffscreenSamples, RenderSettings};
use fovea_renderer::gpu_scene::GpuScene;
use fovea_renderer::layouts::RayGpu;
use fovea_renderer::passes::denoise::DenoiserSettings;
use fovea_renderer::passes::raycast::RayCaster;
use fovea_renderer::passes::resampling::{ResamplingMode, ResamplingSettings};
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::{
    Cartesian, FovTangents, SamplingSpace, VisualPolar, VisualPolarParams,
};
use fovea_renderer::way_back::blur::{BlurSettings, BlurSpace};
use fovea_stage::camera_keys::CameraKeys;
use glam::{UVec2, Vec2, Vec3};
use serde::Serialize;
use std::collections::BTreeMap;

/// Passes that take the VP image back to the screen.
/// The VP frame's way back; without a radiance read-back (the bench has none) the blur's last
/// axis writes the display image (`blur_v_tonemap`), so the share includes the tone mapping that
/// Cartesian's frame spends in `tonemap`.
/// With `--blur-space grid` the blur runs in the grid before the remap and the tonemap pass
/// writes the display image.
const TO_SCREEN_PASSES: &[&str] = &[
    "mip_phi",
    "remap",
    "blur_h",
    "blur_v",
    "blur_v_tonemap",
    "blur_grid_phi",
    "blur_grid_rho",
    "tonemap",
];

#[derive(Serialize)]
pub struct VpFrameReport {
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub vp_width: u32,
    pub vp_height: u32,
    pub vp_samples: u64,
    /// Of `vp_samples`, those traced in the last timed frame: samples far off the screen are
    /// culled (`OffscreenSamples::Cull`, the default).
    pub vp_samples_traced: u64,
    /// The same VP frames with every off-screen sample traced, as in the paper
    /// (`--offscreen-samples trace`), in the same interleaved run.
    pub vp_offscreen_traced: MethodCost,
    /// The same VP frames with the foveated blur in the grid (`--blur-space grid`), in the same
    /// interleaved run, and its way back's share of its frame (against `to_screen_share`).
    pub vp_grid_blur: MethodCost,
    pub grid_blur_to_screen_share: f64,
    pub gaze: [f32; 2],
    /// `still`, or `keys`: the frames followed `--camera-path FILE` (frame i at i / 70 Hz).
    pub camera_motion: &'static str,
    /// Median GPU ms per pass over the timed frames.
    pub cartesian_passes_ms: BTreeMap<String, f64>,
    pub vp_passes_ms: BTreeMap<String, f64>,
    pub cartesian_frame_ms: f64,
    pub vp_frame_ms: f64,
    /// VP frame / Cartesian frame (issue target ≤ 0.45; samples alone give ≈ 0.39).
    pub frame_ratio: f64,
    /// VP trace / Cartesian trace.
    pub trace_ratio: f64,
    /// (φ-mips + remap + blur) / VP frame (target ≤ 0.10 on lavapipe).
    pub to_screen_share: f64,
    /// Each denoiser (`DENOISERS`) at the same sizes and gaze.
    pub denoisers: Vec<DenoiserCost>,
    /// ReSTIR DI (`--resampling di`, its default parameters) at the same sizes and gaze, no
    /// denoiser.
    pub resampling: ResamplingCost,
    /// ReSTIR DI and GI (`--resampling di+gi`), likewise, in an interleaved run of its own.
    pub resampling_gi: ResamplingCost,
    /// Every other method of `--method` (the comparators, VP's variants, fixed foveation)
    /// in the same interleaved run as the VP and Cartesian frames above, no denoiser, each with
    /// its paper's defaults (`comparator_spaces`; `linear-falloff`'s samples: the expected count).
    pub comparators: Vec<MethodCost>,
    /// Primary rays of the VP samples: Mrays/s in VP order and shuffled, and their ratio.
    pub vp_order_mrays_per_s: f64,
    pub shuffled_mrays_per_s: f64,
    pub coherence_gain: f64,
    /// Primary rays through the screen's pixel centres, same pose and pass: Mrays/s in row
    /// order and shuffled. Where VP's per-sample trace overhead comes from: its rays' cost
    /// against a screen ray's, shuffled both (`vp_ray_cost_shuffled`: where the samples sit,
    /// order aside) and in each one's own order (`vp_ray_cost_ordered`: where and in what order).
    pub screen_mrays_per_s: f64,
    pub screen_shuffled_mrays_per_s: f64,
    pub vp_ray_cost_shuffled: f64,
    pub vp_ray_cost_ordered: f64,
}

/// The denoisers measured, each with its defaults; a denoiser's passes are named `<name>_*`.
fn denoisers() -> Vec<DenoiserSettings> {
    DenoiserSettings::NAMES
        .iter()
        .filter(|n| **n != "none")
        .map(|n| DenoiserSettings::parse(n).expect("a listed denoiser"))
        .collect()
}

/// Name prefixes of a denoiser's passes: its own, and for A-SVGF the SVGF stages it reuses.
fn pass_prefixes(denoiser: &DenoiserSettings) -> Vec<String> {
    let own = format!("{}_", denoiser.name());
    if denoiser.needs_gradients() {
        vec![own, "svgf_".to_string()]
    } else {
        vec![own]
    }
}

/// One denoiser in VP vs Cartesian space: its passes' median ms per frame, their sum, VP /
/// Cartesian, and the bytes of history each space carries between frames.
#[derive(Serialize)]
pub struct DenoiserCost {
    pub name: String,
    /// Its passes, and the trace (listed, not summed: A-SVGF's tracer re-shades gradient samples).
    pub cartesian_passes_ms: BTreeMap<String, f64>,
    pub vp_passes_ms: BTreeMap<String, f64>,
    /// Its passes without the trace.
    pub cartesian_ms: f64,
    pub vp_ms: f64,
    pub ratio: f64,
    /// Whole frames with this denoiser (every pass of the frame, as `vp_frame_ms` without one).
    pub cartesian_frame_ms: f64,
    pub vp_frame_ms: f64,
    /// VP / Cartesian whole frame with this denoiser (the frame-ratio target with a denoiser).
    pub frame_ratio: f64,
    pub cartesian_history_bytes: u64,
    pub vp_history_bytes: u64,
}

/// A resampling mode's cost in VP and Cartesian space: frames with it and without it in one
/// interleaved run.
#[derive(Serialize)]
pub struct ResamplingCost {
    /// `di` or `di+gi`.
    pub mode: &'static str,
    /// The trace (its `*_resampled` or `*_resampled_gi` variant) and the resampling passes,
    /// median ms per frame.
    pub cartesian_passes_ms: BTreeMap<String, f64>,
    pub vp_passes_ms: BTreeMap<String, f64>,
    /// The resampling passes together.
    pub cartesian_ms: f64,
    pub vp_ms: f64,
    /// Their share of the whole frame with resampling.
    pub cartesian_share: f64,
    pub vp_share: f64,
    /// Whole frame with resampling / without it, each space.
    pub cartesian_frame_ratio: f64,
    pub vp_frame_ratio: f64,
    /// GPU bytes of reservoirs per view.
    pub cartesian_history_bytes: u64,
    pub vp_history_bytes: u64,
}

/// The resampling passes' names (`passes/resampling`; the last two with `di+gi` only).
const RESAMPLING_PASSES: [&str; 4] = [
    "resample_temporal",
    "resample_spatial",
    "resample_gi_temporal",
    "resample_gi_spatial",
];

/// A comparator method's whole frames against the Cartesian ones of the same run.
#[derive(Serialize)]
pub struct MethodCost {
    pub method: &'static str,
    pub grid: [u32; 2],
    /// The space's samples per frame (linear falloff: its expected count).
    pub samples: u64,
    /// Samples the GPU traced (off-screen culling and linear falloff's killed pixels excluded).
    pub samples_traced: u64,
    pub passes_ms: BTreeMap<String, f64>,
    pub frame_ms: f64,
    /// Its frame / the Cartesian frame.
    pub frame_ratio: f64,
    /// Its trace / the Cartesian trace.
    pub trace_ratio: f64,
}

/// `VpFrameReport::vp_offscreen_traced`'s method name.
const VP_OFFSCREEN_TRACED: &str = "vp-offscreen-traced";
/// `VpFrameReport::vp_grid_blur`'s method name.
const VP_GRID_BLUR: &str = "vp-grid-blur";

/// Display rate of `--camera-path` keyframes in the bench (no headset there): the FOVE 0's 70 Hz,
/// the default headset of `fovea render`, so a path times the same in both.
pub const CAMERA_PATH_HZ: f64 = 70.0;

/// Median GPU ms per pass over `frames` frames after one untimed warm-up frame.
pub fn pass_medians(
    renderer: &mut Renderer,
    camera: CameraPose,
    gaze: Option<Vec2>,
    frames: u32,
) -> Result<BTreeMap<String, f64>> {
    let mut medians = interleaved_pass_medians(&mut [(renderer, gaze)], &|_| camera, frames)?;
    Ok(medians.remove(0).passes)
}

/// One renderer's figures from `interleaved_pass_medians`.
#[derive(Debug)]
pub struct FrameMedians {
    pub passes: BTreeMap<String, f64>,
    /// Samples its last timed frame traced (the GPU's count: culled off-screen samples and
    /// killed linear-falloff pixels excluded).
    pub samples_traced: u64,
}

/// `pass_medians` of several renderers (each with its gaze) whose frames alternate: a drift of
/// the machine's speed during the run (up to ±25 % within an hour on these CPU machines) then
/// hits every side alike, and the ratios between them stay fair. `camera` gives frame i's camera
/// (every renderer sees the same one).
pub fn interleaved_pass_medians(
    renderers: &mut [(&mut Renderer, Option<Vec2>)],
    camera: &dyn Fn(u32) -> CameraPose,
    frames: u32,
) -> Result<Vec<FrameMedians>> {
    let input = |frame_index, gaze| FrameInput::mono(camera(frame_index), frame_index, gaze);
    for (renderer, gaze) in renderers.iter_mut() {
        renderer.render_frame(&input(0, *gaze))?;
    }
    let mut samples: Vec<BTreeMap<String, Vec<f64>>> = vec![BTreeMap::new(); renderers.len()];
    let mut traced = vec![0u64; renderers.len()];
    for frame in 0..frames.max(1) {
        for (((renderer, gaze), samples), traced) in
            renderers.iter_mut().zip(&mut samples).zip(&mut traced)
        {
            *traced = renderer
                .render_frame(&input(frame + 1, *gaze))?
                .samples_traced;
            // A pass recorded several times in one frame (one mip level each) counts as one.
            let mut frame_sums: BTreeMap<&str, f64> = BTreeMap::new();
            for t in renderer.timings() {
                *frame_sums.entry(t.name).or_default() += t.ms;
            }
            for (name, ms) in frame_sums {
                samples.entry(name.to_string()).or_default().push(ms);
            }
        }
    }
    Ok(samples
        .into_iter()
        .zip(traced)
        .map(|(passes, samples_traced)| FrameMedians {
            passes: passes
                .into_iter()
                .map(|(name, mut v)| {
                    v.sort_by(f64::total_cmp);
                    (name, v[v.len() / 2])
                })
                .collect(),
            samples_traced,
        })
        .collect())
}

/// Methods the bench measures itself (the VP and Cartesian frames every ratio divides).
const MEASURED_APART: &[&str] = &["vp", "cartesian"];

/// Every other method of the registry (`methods::METHODS`: the comparators with
/// their papers' defaults, VP's variants, fixed foveation), as `fovea render` builds it with the
/// default profile for the FOVE 0's left eye, around `gaze`; each one measured beside `vp`.
fn comparator_spaces(
    screen: UVec2,
    gaze: Vec2,
) -> Result<Vec<(&'static str, Box<dyn SamplingSpace>)>> {
    let (profile, hmd) = (
        crate::render_profile::RenderProfile::default(),
        fovea_hal::HmdDescription::resolve("fove0")?,
    );
    let names = super::methods::names()
        .into_iter()
        .filter(|n| !MEASURED_APART.contains(n));
    names
        .map(|name| {
            let mut space =
                super::setup::space_for(name, &profile, &hmd, fovea_hal::Eye::Left, screen)?;
            space.set_gaze(gaze)?;
            Ok((name, space))
        })
        .collect()
}

/// The parameters of `--method vp` with the default profile (its layout).
fn default_vp_params() -> VisualPolarParams {
    crate::render_profile::RenderProfile::default().visual_polar
}

/// The FOVE 0 left eye's FOV from its headset profile, for the headset-axis variant.
pub fn fove0_fov() -> Result<FovTangents> {
    let hmd = fovea_hal::HmdDescription::resolve("fove0")?;
    Ok(crate::render_profile::fov_tangents(
        &hmd.eye(fovea_hal::Eye::Left).fov,
    ))
}

/// Passes of the displayed frame (read-backs are I/O, not rendering).
fn frame_ms(passes: &BTreeMap<String, f64>) -> f64 {
    passes
        .iter()
        .filter(|(k, _)| !k.starts_with("readback") && *k != "clear_counters")
        .map(|(_, v)| v)
        .sum()
}

/// What a Visual-Polar frame measurement renders: the device, the scene (its name and a fresh GPU
/// upload per renderer), the ray caster of the ray-order figures, the camera and its path.
pub struct VpBenchScene<'a> {
    pub ctx: &'a std::sync::Arc<fovea_renderer::vk::Context>,
    pub name: &'a str,
    pub make_scene: &'a dyn Fn() -> Result<GpuScene>,
    pub caster: &'a mut RayCaster,
    pub camera: &'a fovea_renderer::scene::Camera,
    pub camera_path: Option<&'a CameraKeys>,
}

pub fn measure(
    scene: VpBenchScene,
    (w, h): (u32, u32),
    gaze_fraction: Vec2,
    frames: u32,
) -> Result<VpFrameReport> {
    let VpBenchScene {
        ctx,
        name: scene_name,
        make_scene,
        caster,
        camera,
        camera_path,
    } = scene;
    let screen = UVec2::new(w, h);
    let gaze = screen.as_vec2() * gaze_fraction;
    let pose = CameraPose::from_scene_camera(camera, w, h);
    let camera_at = |frame: u32| {
        camera_path.map_or(pose, |keys| keys.pose(frame as f64 / CAMERA_PATH_HZ, &pose))
    };
    // `vp` as `fovea render` builds it (the default profile's layout); the variants that trace
    // off-screen samples or blur in the grid are of the paper layout, the one they change.
    let vp = VisualPolar::new(screen, gaze, default_vp_params())?;
    let paper = VisualPolar::new(screen, gaze, VisualPolarParams::default())?;
    // One renderer per space (Cartesian first, gaze-less) with these settings, their frames
    // interleaved: each one's pass medians and denoiser history bytes (the renderers are dropped
    // before the next measurement).
    // A foveated space may come with its own settings (VP with every off-screen sample traced).
    let measure = |settings: RenderSettings,
                   foveated: Vec<(Box<dyn SamplingSpace>, Option<RenderSettings>)>|
     -> Result<Vec<(FrameMedians, u64)>> {
        let mut renderers = vec![(
            Renderer::with_gpu_scene(
                ctx,
                make_scene()?,
                Box::new(Cartesian::new(screen)),
                settings,
            )?,
            None,
        )];
        for (space, own) in foveated {
            renderers.push((
                Renderer::with_gpu_scene(ctx, make_scene()?, space, own.unwrap_or(settings))?,
                Some(gaze),
            ));
        }
        let history: Vec<u64> = renderers
            .iter()
            .map(|(r, _)| {
                r.denoiser().map_or(0, |d| d.history_bytes())
                    + r.view(0).resampling().map_or(0, |s| s.history_bytes())
            })
            .collect();
        let mut timed: Vec<(&mut Renderer, Option<Vec2>)> =
            renderers.iter_mut().map(|(r, g)| (r, *g)).collect();
        Ok(interleaved_pass_medians(&mut timed, &camera_at, frames)?
            .into_iter()
            .zip(history)
            .collect())
    };
    // Without a denoiser the comparators join the same interleaved run.
    let comparator_spaces = comparator_spaces(screen, gaze)?;
    let described_vp = |name| (name, paper.grid_size().to_array(), paper.sample_count());
    let mut described: Vec<(&'static str, [u32; 2], u64)> = vec![
        described_vp(VP_OFFSCREEN_TRACED),
        described_vp(VP_GRID_BLUR),
    ];
    described.extend(
        comparator_spaces
            .iter()
            .map(|(name, s)| (*name, s.grid_size().to_array(), s.sample_count())),
    );
    let traced_everywhere = RenderSettings {
        offscreen_samples: OffscreenSamples::Trace,
        ..Default::default()
    };
    let blur_in_grid = RenderSettings {
        blur: BlurSettings {
            space: BlurSpace::Grid,
            ..Default::default()
        },
        ..Default::default()
    };
    let mut spaces: Vec<(Box<dyn SamplingSpace>, Option<RenderSettings>)> = vec![
        (Box::new(vp), None),
        (Box::new(paper), Some(traced_everywhere)),
        (Box::new(paper), Some(blur_in_grid)),
    ];
    spaces.extend(comparator_spaces.into_iter().map(|(_, s)| (s, None)));
    let mut plain = measure(RenderSettings::default(), spaces)?
        .into_iter()
        .map(|(medians, _)| medians);
    let cartesian_passes_ms = plain.next().expect("the Cartesian medians").passes;
    let FrameMedians {
        passes: vp_passes_ms,
        samples_traced: vp_samples_traced,
    } = plain.next().expect("the Visual-Polar medians");
    let cartesian_frame_ms = frame_ms(&cartesian_passes_ms);
    let mut comparators: Vec<MethodCost> = described
        .into_iter()
        .zip(plain)
        .map(
            |(
                (method, grid, samples),
                FrameMedians {
                    passes: passes_ms,
                    samples_traced,
                },
            )| {
                let frame = frame_ms(&passes_ms);
                MethodCost {
                    method,
                    grid,
                    samples,
                    samples_traced,
                    frame_ratio: frame / cartesian_frame_ms,
                    trace_ratio: passes_ms["trace"] / cartesian_passes_ms["trace"],
                    passes_ms,
                    frame_ms: frame,
                }
            },
        )
        .collect();
    let vp_offscreen_traced = comparators.remove(0);
    let vp_grid_blur = comparators.remove(0);
    let mut costs = Vec::new();
    for denoiser in denoisers() {
        let prefixes = pass_prefixes(&denoiser);
        let [(cart_all, cartesian_history_bytes), (vp_all, vp_history_bytes)]: [_; 2] = measure(
            RenderSettings {
                denoiser,
                ..Default::default()
            },
            vec![(Box::new(vp), None)],
        )?
        .try_into()
        .expect("one median map per renderer");
        let (cart_all, vp_all) = (cart_all.passes, vp_all.passes);
        let (cartesian_frame_ms, vp_frame_ms) = (frame_ms(&cart_all), frame_ms(&vp_all));
        let (cartesian_passes_ms, vp_passes_ms) = (
            denoiser_passes(cart_all, &prefixes),
            denoiser_passes(vp_all, &prefixes),
        );
        let own = |m: &BTreeMap<String, f64>| {
            m.iter()
                .filter(|(k, _)| *k != "trace")
                .map(|(_, v)| v)
                .sum::<f64>()
        };
        let (cartesian_ms, vp_ms) = (own(&cartesian_passes_ms), own(&vp_passes_ms));
        costs.push(DenoiserCost {
            name: denoiser.name().to_string(),
            cartesian_passes_ms,
            vp_passes_ms,
            cartesian_ms,
            vp_ms,
            ratio: vp_ms / cartesian_ms,
            cartesian_frame_ms,
            vp_frame_ms,
            frame_ratio: vp_frame_ms / cartesian_frame_ms,
            cartesian_history_bytes,
            vp_history_bytes,
        });
    }
    let resampling = resampling_cost(screen, &vp, ResamplingMode::Di, &measure)?;
    let resampling_gi = resampling_cost(screen, &vp, ResamplingMode::DiGi, &measure)?;
    let vp_frame_ms = frame_ms(&vp_passes_ms);
    let to_screen = |passes: &BTreeMap<String, f64>| -> f64 {
        TO_SCREEN_PASSES.iter().filter_map(|p| passes.get(*p)).sum()
    };
    let grid_blur_to_screen_share = to_screen(&vp_grid_blur.passes_ms) / vp_grid_blur.frame_ms;

    let rays = vp_primary_rays(&vp, &pose);
    let gpu = make_scene()?;
    let (_, ordered_ms) = super::bench_rays::timed_trace(caster, &gpu, &rays, false)?;
    let shuffled = shuffle(rays.clone());
    let (_, shuffled_ms) = super::bench_rays::timed_trace(caster, &gpu, &shuffled, false)?;
    let screen_rays = super::bench_rays::primary_rays(&pose, w, h);
    let (_, screen_ms) = super::bench_rays::timed_trace(caster, &gpu, &screen_rays, false)?;
    let (_, screen_shuffled_ms) =
        super::bench_rays::timed_trace(caster, &gpu, &shuffle(screen_rays.clone()), false)?;
    let rate = |ms: f64| rays.len() as f64 / (ms * 1e-3) * 1e-6;
    let screen_rate = |ms: f64| screen_rays.len() as f64 / (ms * 1e-3) * 1e-6;
    let grid = vp.grid_size();
    let report = VpFrameReport {
        scene: scene_name.to_string(),
        camera_motion: if camera_path.is_some() {
            "keys"
        } else {
            "still"
        },
        width: w,
        height: h,
        vp_width: grid.x,
        vp_height: grid.y,
        vp_samples: vp.sample_count(),
        vp_samples_traced,
        vp_offscreen_traced,
        vp_grid_blur,
        grid_blur_to_screen_share,
        gaze: gaze.to_array(),
        trace_ratio: vp_passes_ms["trace"] / cartesian_passes_ms["trace"],
        frame_ratio: vp_frame_ms / cartesian_frame_ms,
        to_screen_share: to_screen(&vp_passes_ms) / vp_frame_ms,
        cartesian_passes_ms,
        vp_passes_ms,
        cartesian_frame_ms,
        vp_frame_ms,
        denoisers: costs,
        resampling,
        resampling_gi,
        comparators,
        vp_order_mrays_per_s: rate(ordered_ms),
        shuffled_mrays_per_s: rate(shuffled_ms),
        coherence_gain: shuffled_ms / ordered_ms,
        screen_mrays_per_s: screen_rate(screen_ms),
        screen_shuffled_mrays_per_s: screen_rate(screen_shuffled_ms),
        vp_ray_cost_shuffled: screen_rate(screen_shuffled_ms) / rate(shuffled_ms),
        vp_ray_cost_ordered: screen_rate(screen_ms) / rate(ordered_ms),
    };
    println!(
        "{scene_name} {w}×{h} VP {}×{}: frame {:.1} ms vs Cartesian {:.1} ms = {:.3} (trace {:.3}); way back (mips+remap+blur, and the tone mapping it writes) {:.1} % of the VP frame; \
         primary rays VP-ordered {:.2} vs shuffled {:.2} Mrays/s ({:.2}×); screen rays {:.2} / shuffled {:.2} Mrays/s: a VP ray costs {:.2}× a screen ray ({:.2}× both shuffled)",
        grid.x,
        grid.y,
        report.vp_frame_ms,
        report.cartesian_frame_ms,
        report.frame_ratio,
        report.trace_ratio,
        100.0 * report.to_screen_share,
        report.vp_order_mrays_per_s,
        report.shuffled_mrays_per_s,
        report.coherence_gain,
        report.screen_mrays_per_s,
        report.screen_shuffled_mrays_per_s,
        report.vp_ray_cost_ordered,
        report.vp_ray_cost_shuffled,
    );
    println!(
        "  VP traced {} of its {} samples (the rest lay far off the screen)",
        report.vp_samples_traced, report.vp_samples
    );
    println!(
        "  way back with the blur in the grid: {:.1} % of that frame",
        100.0 * report.grid_blur_to_screen_share
    );
    for m in [&report.vp_offscreen_traced, &report.vp_grid_blur]
        .into_iter()
        .chain(&report.comparators)
    {
        println!(
            "  {} {}×{} ({} samples, {} traced, vs VP's {}): frame {:.1} ms = {:.3} of Cartesian (trace {:.3})",
            m.method, m.grid[0], m.grid[1], m.samples, m.samples_traced, report.vp_samples, m.frame_ms, m.frame_ratio, m.trace_ratio
        );
    }
    let mib = |b: u64| b as f64 / (1 << 20) as f64;
    for d in &report.denoisers {
        let passes: Vec<String> = d
            .vp_passes_ms
            .iter()
            .map(|(pass, vp_ms)| match d.cartesian_passes_ms.get(pass) {
                Some(cartesian_ms) => format!("{pass} {vp_ms:.2} vs {cartesian_ms:.2}"),
                // The idle-tile passes: Cartesian's grid is the screen, it has no idle tile.
                None => format!("{pass} {vp_ms:.2}, VP only"),
            })
            .collect();
        println!(
            "  {}: {:.1} ms VP vs {:.1} ms Cartesian = {:.3} ({}); whole frame {:.3}, history {:.1} vs {:.1} MiB",
            d.name,
            d.vp_ms,
            d.cartesian_ms,
            d.ratio,
            passes.join(", "),
            d.frame_ratio,
            mib(d.vp_history_bytes),
            mib(d.cartesian_history_bytes)
        );
    }
    for r in [&report.resampling, &report.resampling_gi] {
        println!(
        "  resampling {}: {:.1} ms VP vs {:.1} ms Cartesian ({:.1} % vs {:.1} % of the frame); whole frame with it / without {:.3} VP, {:.3} Cartesian; reservoirs {:.1} vs {:.1} MiB",
        r.mode,
        r.vp_ms,
        r.cartesian_ms,
        100.0 * r.vp_share,
        100.0 * r.cartesian_share,
        r.vp_frame_ratio,
        r.cartesian_frame_ratio,
        mib(r.vp_history_bytes),
        mib(r.cartesian_history_bytes)
    );
    }
    Ok(report)
}

/// Medians and history bytes of each renderer of one interleaved run: a Cartesian renderer with
/// the settings given, then one per foveated space (with its own settings, if any).
type MeasureFn<'a> = dyn Fn(
        RenderSettings,
        Vec<(Box<dyn SamplingSpace>, Option<RenderSettings>)>,
    ) -> Result<Vec<(FrameMedians, u64)>>
    + 'a;

/// Resampling in `mode` against plain frames, Cartesian and VP, in one interleaved run.
fn resampling_cost(
    screen: UVec2,
    vp: &VisualPolar,
    mode: ResamplingMode,
    measure: &MeasureFn,
) -> Result<ResamplingCost> {
    let resampled = RenderSettings {
        resampling: ResamplingSettings::default().with_mode(mode),
        ..Default::default()
    };
    let plain = RenderSettings::default();
    let [(cart, cartesian_history_bytes), (vp_di, vp_history_bytes), (vp_plain, _), (cart_plain, _)]: [_; 4] =
        measure(
            resampled,
            vec![
                (Box::new(*vp), None),
                (Box::new(*vp), Some(plain)),
                (Box::new(Cartesian::new(screen)), Some(plain)),
            ],
        )?
        .try_into()
        .map_err(|_| anyhow::anyhow!("one median map per renderer"))?;
    let own = |m: &BTreeMap<String, f64>| -> f64 {
        RESAMPLING_PASSES.iter().filter_map(|p| m.get(*p)).sum()
    };
    let listed = |m: &BTreeMap<String, f64>| -> BTreeMap<String, f64> {
        m.iter()
            .filter(|(k, _)| *k == "trace" || RESAMPLING_PASSES.contains(&k.as_str()))
            .map(|(k, v)| (k.clone(), *v))
            .collect()
    };
    let (cart_frame, vp_frame) = (frame_ms(&cart.passes), frame_ms(&vp_di.passes));
    Ok(ResamplingCost {
        mode: mode.name(),
        cartesian_ms: own(&cart.passes),
        vp_ms: own(&vp_di.passes),
        cartesian_share: own(&cart.passes) / cart_frame,
        vp_share: own(&vp_di.passes) / vp_frame,
        cartesian_frame_ratio: cart_frame / frame_ms(&cart_plain.passes),
        vp_frame_ratio: vp_frame / frame_ms(&vp_plain.passes),
        cartesian_passes_ms: listed(&cart.passes),
        vp_passes_ms: listed(&vp_di.passes),
        cartesian_history_bytes,
        vp_history_bytes,
    })
}

/// Of a renderer's pass medians: the denoiser's passes (named `prefix*` for one of `prefixes`)
/// and the trace.
fn denoiser_passes(passes: BTreeMap<String, f64>, prefixes: &[String]) -> BTreeMap<String, f64> {
    passes
        .into_iter()
        .filter(|(k, _)| k == "trace" || prefixes.iter().any(|p| k.starts_with(p.as_str())))
        .collect()
}

/// One primary ray per kept VP texel (centre), in grid order (row by row, as the trace kernel's
/// lanes walk the grid), through the same pinhole model as the tracer.
fn vp_primary_rays(vp: &VisualPolar, pose: &CameraPose) -> Vec<RayGpu> {
    let grid = vp.grid_size();
    let screen = vp.screen().as_vec2();
    let origin = pose.world_from_view.w_axis.truncate();
    let t = pose.fov_tan;
    let mut rays = Vec::with_capacity(vp.sample_count() as usize);
    for y in 0..grid.y {
        for x in 0..grid.x {
            if y >= vp.rows_in_column(x) {
                continue;
            }
            let s = vp.vp_to_screen(Vec2::new(x as f32 + 0.5, y as f32 + 0.5)) / screen;
            let view = Vec3::new(t.x + s.x * (t.y - t.x), t.w + s.y * (t.z - t.w), -1.0);
            let dir = pose.world_from_view.transform_vector3(view).normalize();
            rays.push(RayGpu {
                origin_tmin: origin.extend(0.0),
                direction_tmax: dir.extend(1e30),
            });
        }
    }
    rays
}

/// Fisher–Yates with a fixed-seed xorshift: the same "random order" every run.
fn shuffle(mut rays: Vec<RayGpu>) -> Vec<RayGpu> {
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    for i in (1..rays.len()).rev() {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        rays.swap(i, (state % (i as u64 + 1)) as usize);
    }
    rays
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The comparators come from the registry as `fovea render` builds them, around the bench's
    /// gaze, and the bench's own VP frame is the registry's `vp` with the default profile.
    #[test]
    fn comparators_are_the_registry_around_the_gaze() {
        let screen = UVec2::new(320, 360);
        let gaze = Vec2::new(100.0, 120.0);
        let spaces = comparator_spaces(screen, gaze).unwrap();
        let names: Vec<_> = spaces.iter().map(|(name, _)| *name).collect();
        let expected: Vec<_> = super::super::methods::names()
            .into_iter()
            .filter(|n| !MEASURED_APART.contains(n))
            .collect();
        assert_eq!(names, expected);
        assert!(spaces.iter().all(|(_, s)| s.gaze() == gaze), "{names:?}");
        let (profile, hmd) = (
            crate::render_profile::RenderProfile::default(),
            fovea_hal::HmdDescription::resolve("fove0").unwrap(),
        );
        let registry_vp =
            super::super::setup::space_for("vp", &profile, &hmd, fovea_hal::Eye::Left, screen)
                .unwrap();
        let bench_vp =
            VisualPolar::new(screen, screen.as_vec2() * 0.5, default_vp_params()).unwrap();
        assert_eq!(registry_vp.params(), bench_vp.sampling_params());
        assert_eq!(
            default_vp_params().layout,
            crate::render_profile::DEFAULT_VP_LAYOUT
        );
    }
}
