//! `fovea quality`: image quality over a gaze sequence for every sampling method × denoiser × TAA
//! mode, with a still and with a moving camera (the quality tables of docs/quality.md). Each
//! combination is a `fovea render` run (same scene, gaze source, seed and profile) into
//! `DIR/run_*`; its last `--eval-frames` frames are compared with converged Cartesian references of
//! the same camera poses (`DIR/reference_*.exr`), per ring of eccentricity around each frame's own
//! gaze, and the ring metrics are averaged over those frames → `DIR/quality.json` +
//! `DIR/quality.md`. With `--eyes both` every run renders both eyes, each eye is judged against
//! its own reference, and the binocular consistency measure (`quality_stereo`) compares the eyes.

use super::flags::{DeviceArgs, LatencyFlags, SceneFlags};
use super::quality_stereo::{self, BinocularQuality, EyeFiles, StereoReferences};
use super::render::{self, RenderArgs};
use super::setup::{Eyes, EXPOSURE_STOPS};
use crate::eval::flip::flip_map;
use crate::eval::metrics::{
    add_flip, evaluate, flicker_map, mean as metrics_mean, Evaluation, Rings,
};
use crate::output::{
    prepare_output_dir, tonemap_preview, write_exr, write_json, write_png, write_text,
};
use crate::render_profile::ProfileOverrides;
use crate::render_profile::RenderProfile;
use anyhow::{bail, Context, Result};
use fovea_hal::Eye;
use fovea_renderer::frame::{CameraPose, RenderSettings, StereoNoise};
use fovea_renderer::passes::denoise::DenoiserSettings;
use fovea_renderer::passes::resampling::ResamplingMode;
use fovea_renderer::passes::taa::TaaMode;
use fovea_renderer::passes::tonemap::ToneCurve;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::Cartesian;
use fovea_renderer::scene::Scene;
use fovea_stage::camera_path;
use glam::{UVec2, Vec2};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

#[derive(Clone)]
pub struct QualityArgs<'a> {
    pub scene: &'a str,
    pub width: u32,
    pub height: u32,
    pub headset: &'a str,
    pub gaze: &'a str,
    pub frames: u32,
    /// The last this many frames are evaluated.
    pub eval_frames: u32,
    pub methods: &'a [String],
    pub denoisers: &'a [String],
    pub taa: &'a [String],
    /// `still` and/or `moving` (the scene's default camera path).
    pub cameras: &'a [String],
    pub reference_spp: u32,
    pub rings: usize,
    pub seed: u32,
    pub profile: RenderProfile,
    /// `left` or `both` (stereo runs, the binocular consistency measure added).
    pub eyes: Eyes,
    /// How the eyes' random numbers relate, one run each; empty: the profile's, and the run
    /// folders keep their names without it.
    pub stereo_noises: &'a [StereoNoise],
    pub camera: &'a fovea_stage::look::CameraOptions,
    /// An earlier quality folder whose references (of the same [`reference_key`]) are copied
    /// instead of rendered.
    pub references: Option<&'a Path>,
    /// The one exposure every run and reference is displayed at (FLIP, flicker, the PNGs).
    pub display_exposure: DisplayExposure,
    pub out: &'a Path,
    pub device: Option<&'a str>,
    pub validation: bool,
}

/// `--display-exposure`: how frames and references are displayed for the figures judged on what
/// is shown (FLIP, flicker, the PNGs scripts/perceptual scores). Every run of a camera is shown at
/// the one exposure of its references, so the methods are compared on equal terms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DisplayExposure {
    /// A fixed exposure in stops (0: radiance as it is).
    Stops(f32),
    /// What automatic exposure meters on the camera's first converged reference (flat, without
    /// the gaze's weight: the display does not follow any one gaze), held for every frame.
    Metered,
}

impl DisplayExposure {
    pub fn parse(text: &str) -> Result<DisplayExposure> {
        if text == "metered" {
            return Ok(DisplayExposure::Metered);
        }
        match text.parse::<f32>() {
            Ok(ev) if ev.is_finite() && ev.abs() <= EXPOSURE_STOPS => {
                Ok(DisplayExposure::Stops(ev))
            }
            _ => bail!(
                "--display-exposure {text}: expected metered or stops within ±{EXPOSURE_STOPS}"
            ),
        }
    }

    /// The multiplier radiance is displayed at, given the camera's first reference.
    pub fn multiplier(self, first_reference: &[[f32; 4]], width: u32, height: u32) -> f32 {
        match self {
            DisplayExposure::Stops(ev) => ev.exp2(),
            DisplayExposure::Metered => {
                let flat = fovea_renderer::passes::exposure::AutoExposure {
                    gaze_boost: 0.0,
                    ..Default::default()
                };
                fovea_renderer::passes::exposure::metered_exposure(
                    first_reference,
                    width,
                    height,
                    &flat,
                    glam::Vec2::ZERO,
                    1.0,
                )
            }
        }
    }
}

pub const CAMERAS: &[&str] = &["still", "moving"];

/// The display exposure of a report written without one.
fn unit_exposure() -> f32 {
    1.0
}

/// One combination's metrics: per ring (mean over the evaluated frames) and whole frame.
#[derive(Serialize, Deserialize)]
pub struct RunQuality {
    /// The run's `fovea render` folder inside the output folder (read by the offline perceptual
    /// scorer, scripts/perceptual).
    #[serde(default)]
    run_dir: String,
    camera: String,
    method: String,
    denoiser: String,
    taa: String,
    /// How the eyes' random numbers related (`--stereo-noise`).
    stereo_noise: String,
    /// Whether each eye's samples took the other eye's (`--cross-eye-reuse`; the run's
    /// report.json).
    #[serde(default)]
    cross_eye_reuse: bool,
    /// The exposure multiplier its frames and references were displayed at
    /// (`--display-exposure`).
    #[serde(default = "unit_exposure")]
    display_exposure: f32,
    frame_gpu_ms: f64,
    /// Samples and rays per frame (the run's mean, its report.json).
    samples_traced: u64,
    rays_traced: u64,
    /// Frames whose metrics are averaged, and their gaze points (render pixels).
    frames: Vec<u32>,
    gaze: Vec<[f32; 2]>,
    /// The left eye's (the only one of a one-eye run).
    rings: Vec<RingMean>,
    frame_rmse: f64,
    frame_ssim: f64,
    /// Mean FLIP of the displayed frame against the tonemapped reference.
    frame_flip: f64,
    /// Mean temporal flicker over consecutive evaluated frames (`metrics::flicker_map`); null
    /// with a single evaluated frame.
    frame_flicker: Option<f64>,
    /// With the latency model (`--latency-ms`, `--tracker-hz`, `--gaze-predict`), the same frames
    /// judged where the eye is when they are shown: its gaze per evaluated frame (null without
    /// gaze or off the image; such frames are left out), the rings around it, and the mean FLIP
    /// of the innermost two rings around it (`foveal_flip_true_gaze`) and around the rendered
    /// gaze (`foveal_flip`).
    #[serde(skip_serializing_if = "Option::is_none")]
    gaze_true: Option<Vec<Option<[f32; 2]>>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    rings_true_gaze: Option<Vec<RingMean>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    foveal_flip: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    foveal_flip_true_gaze: Option<f64>,
    /// A stereo run (`--eyes both`): the binocular consistency measure (`quality_stereo`) and
    /// the right eye's own quality.
    #[serde(skip_serializing_if = "Option::is_none")]
    binocular: Option<Binocular>,
}

/// quality.json's `binocular`: the measure, and the right eye judged as the left is (its rings
/// around its own gaze).
#[derive(Serialize, Deserialize)]
struct Binocular {
    #[serde(flatten)]
    measure: BinocularQuality,
    right_eye: EyeQuality,
}

/// One eye's quality against its own reference.
#[derive(Serialize, Deserialize)]
struct EyeQuality {
    rings: Vec<RingMean>,
    frame_rmse: f64,
    frame_ssim: f64,
    frame_flip: f64,
    frame_flicker: Option<f64>,
}

/// Rings of the fovea in `foveal_flip*`: the innermost two.
const FOVEAL_RINGS: usize = 2;

/// A combination the method cannot run (a denoiser or TAA on a space without temporal filters):
/// listed in the table with the reason instead of silently left out (once, whatever the stereo
/// noise).
#[derive(Serialize, Deserialize, PartialEq)]
pub struct RefusedRun {
    camera: String,
    method: String,
    denoiser: String,
    taa: String,
    reason: String,
}

#[derive(Serialize, Deserialize)]
struct RingMean {
    /// The paper's normalised eccentricity r / r_max · 80 of the ring's edges.
    ecc_inner: f64,
    ecc_outer: f64,
    rmse: Option<f64>,
    ssim: Option<f64>,
    flip: Option<f64>,
    flicker: Option<f64>,
}

#[derive(Serialize)]
struct Report<'a> {
    scene: &'a str,
    width: u32,
    height: u32,
    headset: &'a str,
    gaze_source: &'a str,
    /// `left` or `both`.
    eyes: &'static str,
    frames: u32,
    eval_frames: u32,
    reference_spp: u32,
    blur_sigma_at_30: f32,
    /// `off`, `di` or `di+gi`: every run's `--resampling`.
    resampling: &'static str,
    /// FLIP's pixels per degree: the width over the headset eye's horizontal FOV.
    flip_ppd: f32,
    /// Per camera, everything its converged references depend on ([`reference_key`]):
    /// `--references` takes another folder's only where its key is this.
    reference_keys: std::collections::BTreeMap<&'a str, String>,
    /// The display the frames are shown on, for video metrics: the headset's refresh (frames per
    /// second) and the left eye's FOV in degrees (left, right, down, up; left and down negative).
    refresh_hz: f32,
    eye_fov_deg: [f32; 4],
    /// With the latency model: its latency and predictor (the runs' report.json `gaze_latency`).
    #[serde(skip_serializing_if = "Option::is_none")]
    latency: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    gaze_predict: Option<String>,
    runs: &'a [RunQuality],
    refused: &'a [RefusedRun],
}

fn check_names(flag: &str, given: &[String], allowed: &[&str]) -> Result<()> {
    if given.is_empty() {
        bail!("{flag} needs at least one of {}", allowed.join(", "));
    }
    for g in given {
        if !allowed.contains(&g.as_str()) {
            bail!("{flag} {g}: expected one of {}", allowed.join(", "));
        }
    }
    Ok(())
}

/// `--methods all` → every method of `fovea render`.
pub fn expand_methods(methods: Vec<String>) -> Vec<String> {
    match methods.as_slice() {
        [one] if one == "all" => super::methods::names()
            .iter()
            .map(|m| m.to_string())
            .collect(),
        _ => methods,
    }
}

/// Why `method` cannot run a denoiser or TAA, if it cannot (asked of the space itself, once per
/// method: some spaces take a full-screen sum to build).
fn filters_refusal(
    args: &QualityArgs,
    hmd: &fovea_hal::HmdDescription,
    method: &str,
) -> Result<Option<String>> {
    let space = super::setup::space_for(
        method,
        &args.profile,
        hmd,
        fovea_hal::Eye::Left,
        UVec2::new(args.width, args.height),
    )?;
    let caps = space.capabilities();
    let resampling = match resampled(args) {
        true => " and no resampling",
        false => "",
    };
    Ok((!caps.temporal_filters).then(|| {
        format!(
            "{method} supports no denoiser or TAA{resampling} {}",
            caps.filters_note
        )
    }))
}

/// Whether every run resamples light (`--resampling` / the profile's `[resampling]`): the
/// resampling passes need a grid with temporal filters, as the denoisers do.
fn resampled(args: &QualityArgs) -> bool {
    args.profile.resampling.mode != ResamplingMode::Off
}

/// One cell of the grid: a camera (`still` or `moving`), a method, a denoiser, a TAA mode and,
/// where `--stereo-noise` is given, how the eyes' random numbers relate.
pub struct Combination<'a> {
    pub camera: &'a str,
    pub method: &'a str,
    pub denoiser: &'a str,
    pub taa: &'a str,
    /// `None`: the profile's, and the folder named as without `--stereo-noise`.
    pub noise: Option<StereoNoise>,
}

impl Combination<'_> {
    /// The `fovea render` folder of this combination inside the output folder.
    pub fn run_dir_name(&self) -> String {
        let noise = self
            .noise
            .map_or(String::new(), |n| format!("_noise-{}", n.name()));
        format!(
            "run_{}_{}_{}_taa-{}{noise}",
            self.camera, self.method, self.denoiser, self.taa
        )
    }

    /// Whether the combination runs a temporal filter (which some methods refuse).
    fn filtered(&self) -> bool {
        self.denoiser != "none" || self.taa != "off"
    }

    fn refused(&self, reason: String) -> RefusedRun {
        RefusedRun {
            camera: self.camera.to_string(),
            method: self.method.to_string(),
            denoiser: self.denoiser.to_string(),
            taa: self.taa.to_string(),
            reason,
        }
    }
}

/// How a run's eyes relate, as its tables name it: the stereo noise, and `+ cross-eye` where
/// each eye's samples took the other eye's (its report.json).
fn stereo_label(noise: &str, cross_eye_reuse: bool) -> String {
    if cross_eye_reuse {
        format!("{noise} + cross-eye")
    } else {
        noise.to_string()
    }
}

/// The stereo noises of the grid: `--stereo-noise`'s, or only the profile's (`None`).
pub fn stereo_noises(args: &QualityArgs) -> Vec<Option<StereoNoise>> {
    match args.stereo_noises {
        [] => vec![None],
        given => given.iter().copied().map(Some).collect(),
    }
}

/// What one combination gives: its metrics (boxed: a stereo run's outweigh a refusal), or why
/// the method cannot run it.
#[derive(Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    Run(Box<RunQuality>),
    Refused(RefusedRun),
}

/// The settings every combination shares, checked once.
pub struct Prepared {
    /// The frames whose metrics are averaged.
    pub evaluated: Vec<u32>,
    ppd: f32,
    hmd: fovea_hal::HmdDescription,
    model: Option<fovea_hal::latency::LatencyModel>,
}

/// Checks the flags (before anything renders) and resolves what every combination shares.
pub fn prepare(args: &QualityArgs) -> Result<Prepared> {
    check_names("--methods", args.methods, &super::methods::names())?;
    check_names("--denoisers", args.denoisers, DenoiserSettings::NAMES)?;
    check_names("--taa", args.taa, TaaMode::NAMES)?;
    check_names("--cameras", args.cameras, CAMERAS)?;
    if args.eyes == Eyes::Right {
        bail!("--eyes right: fovea quality judges the left eye or both (left, both)");
    }
    if args.eval_frames == 0 || args.eval_frames > args.frames {
        bail!(
            "--eval-frames {} must be in 1..={} (--frames)",
            args.eval_frames,
            args.frames
        );
    }
    if args.rings == 0 || args.reference_spp == 0 || args.width == 0 || args.height == 0 {
        bail!("--rings, --reference-spp, --width and --height must be at least 1");
    }
    let max_spp = super::reference::MAX_REFERENCE_SPP;
    if args.reference_spp > max_spp {
        bail!(
            "--reference-spp {} must be at most {max_spp} (as fovea reference --spp)",
            args.reference_spp
        );
    }
    // Every frame is read back within the image budget: a larger run would render for nothing.
    let max_pixels = fovea_stage::decode::MAX_IMAGE_PIXELS;
    if args.width as u64 * args.height as u64 > max_pixels {
        bail!(
            "--width {} --height {}: at most {max_pixels} pixels (the frames are read back for the figures)",
            args.width,
            args.height
        );
    }
    super::eval::check_rings(args.rings, Some((args.width, args.height)))?;
    let evaluated: Vec<u32> = (args.frames - args.eval_frames..args.frames).collect();
    let ppd = flip_ppd(args)?;
    let hmd = fovea_hal::HmdDescription::resolve(args.headset)
        .with_context(|| format!("--headset {}", args.headset))?;
    let model = args.profile.gaze_timing.model(&hmd)?;
    Ok(Prepared {
        evaluated,
        ppd,
        hmd,
        model,
    })
}

pub fn run(args: &QualityArgs) -> Result<()> {
    let prepared = prepare(args)?;
    let _out_dir = prepare_output_dir(args.out)?;
    let noises = stereo_noises(args);
    let mut outcomes = Vec::new();
    for camera in args.cameras {
        let references = references(args, camera, &prepared.evaluated)?;
        for method in args.methods {
            let filtered = resampled(args)
                || args.denoisers.iter().any(|d| d != "none")
                || args.taa.iter().any(|t| t != "off");
            // Asked once per method (some spaces take a full-screen sum to build).
            let refusal = if filtered {
                filters_refusal(args, &prepared.hmd, method)?
            } else {
                None
            };
            for denoiser in args.denoisers {
                for taa in args.taa {
                    for &noise in &noises {
                        let combination = Combination {
                            camera,
                            method,
                            denoiser,
                            taa,
                            noise,
                        };
                        let dir = args.out.join(combination.run_dir_name());
                        let needs_filters = resampled(args) || combination.filtered();
                        let refused = refusal
                            .as_ref()
                            .filter(|_| needs_filters)
                            .map(|reason| combination.refused(reason.clone()));
                        outcomes.push(match refused {
                            Some(refused) => Outcome::Refused(refused),
                            None => Outcome::Run(Box::new(run_combination(
                                args,
                                &prepared,
                                &combination,
                                &references,
                                &dir,
                            )?)),
                        });
                    }
                }
            }
        }
    }
    write_report(args, &prepared, outcomes, args.out)
}

/// Why the method of `combination` cannot run it, if it cannot.
pub fn refusal(
    args: &QualityArgs,
    prepared: &Prepared,
    combination: &Combination,
) -> Result<Option<RefusedRun>> {
    if !(combination.filtered() || resampled(args)) {
        return Ok(None);
    }
    Ok(filters_refusal(args, &prepared.hmd, combination.method)?
        .map(|reason| combination.refused(reason)))
}

/// Renders one combination into `dir` (a `fovea render` folder, both eyes in a stereo run) and
/// measures its evaluated frames against `references`: each eye against its own, and in a stereo
/// run the eyes against each other.
pub fn run_combination(
    args: &QualityArgs,
    prepared: &Prepared,
    combination: &Combination,
    references: &References,
    dir: &Path,
) -> Result<RunQuality> {
    let Combination {
        camera,
        method,
        denoiser,
        taa,
        noise,
    } = *combination;
    let mut profile = args.profile.clone();
    if let Some(noise) = noise {
        profile.stereo_noise = noise;
    }
    let render_args = RenderArgs {
        scene: args.scene,
        method,
        width: Some(args.width),
        height: Some(args.height),
        scale: 1.0,
        headset: args.headset,
        gaze: args.gaze,
        frames: args.frames,
        out: dir,
        exr: true,
        camera_path: if camera == "moving" {
            camera_path::CameraMotion::Orbit
        } else {
            camera_path::CameraMotion::Still
        },
        seed: args.seed,
        max_depth: fovea_renderer::frame::REALTIME_MAX_DEPTH,
        // Every method is judged at one fixed exposure and curve, its references'
        // (`write_displayed_references`).
        exposure: fovea_renderer::passes::exposure::Exposure::Manual(references.exposure),
        tone: ToneCurve::Aces,
        overview: false,
        profile: profile.clone(),
        debug_views: false,
        denoiser,
        taa,
        device: args.device,
        validation: args.validation,
        eyes: args.eyes,
        frames_in_flight: 2,
        camera: args.camera,
    };
    let what = format!(
        "{camera} camera, {method} + {denoiser}, taa {taa}, stereo noise {}, cross-eye reuse {}",
        profile.stereo_noise.name(),
        profile.cross_eye_reuse.name()
    );
    render::run(&render_args).with_context(|| what.clone())?;
    let evaluated = &prepared.evaluated;
    let stereo = references.stereo.as_ref();
    let left = match stereo {
        Some(_) => EyeFiles::LEFT,
        None => EyeFiles::MONO,
    };
    let exposure = references.exposure;
    let mut q = measure(
        args,
        dir,
        evaluated,
        (&references.left, exposure),
        prepared.ppd,
        &left,
    )?;
    if let Some(stereo) = stereo {
        let right = measure(
            args,
            dir,
            evaluated,
            (&stereo.right, exposure),
            prepared.ppd,
            &EyeFiles::RIGHT,
        )?;
        let measure = quality_stereo::measure(dir, evaluated, &references.left, stereo, args.rings)
            .with_context(|| what.clone())?;
        q.binocular = Some(Binocular {
            measure,
            right_eye: EyeQuality {
                rings: right.rings,
                frame_rmse: right.frame_rmse,
                frame_ssim: right.frame_ssim,
                frame_flip: right.frame_flip,
                frame_flicker: right.frame_flicker,
            },
        });
    }
    q.run_dir = dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    (q.camera, q.method, q.denoiser, q.taa, q.stereo_noise) = (
        camera.to_string(),
        method.to_string(),
        denoiser.to_string(),
        taa.to_string(),
        profile.stereo_noise.name().to_string(),
    );
    Ok(q)
}

/// Writes `out/quality.json` and `out/quality.md` from the outcomes in the order of the grid
/// (cameras, methods, denoisers, TAA modes, stereo noises), and prints the table.
pub fn write_report(
    args: &QualityArgs,
    prepared: &Prepared,
    outcomes: Vec<Outcome>,
    out: &Path,
) -> Result<()> {
    let (mut runs, mut refused) = (Vec::new(), Vec::new());
    for outcome in outcomes {
        match outcome {
            Outcome::Run(q) => runs.push(*q),
            // A refusal holds for every stereo noise: listed once.
            Outcome::Refused(r) if !refused.contains(&r) => refused.push(r),
            Outcome::Refused(_) => {}
        }
    }
    let model = prepared.model.as_ref();
    let report = Report {
        scene: args.scene,
        width: args.width,
        height: args.height,
        headset: args.headset,
        gaze_source: args.gaze,
        eyes: args.eyes.name(),
        frames: args.frames,
        eval_frames: args.eval_frames,
        reference_spp: args.reference_spp,
        blur_sigma_at_30: args.profile.blur.sigma_at_30,
        resampling: args.profile.resampling.mode.name(),
        flip_ppd: prepared.ppd,
        reference_keys: args
            .cameras
            .iter()
            .map(|c| (c.as_str(), reference_key(args, c)))
            .collect(),
        refresh_hz: prepared.hmd.refresh_hz,
        eye_fov_deg: {
            let fov = prepared.hmd.eye(Eye::Left).fov;
            [
                fov.angle_left,
                fov.angle_right,
                fov.angle_down,
                fov.angle_up,
            ]
            .map(f32::to_degrees)
        },
        latency: model.map(|m| m.describe()),
        gaze_predict: model.map(|_| args.profile.gaze_timing.mode().name().to_string()),
        runs: &runs,
        refused: &refused,
    };
    write_json(&out.join("quality.json"), &report)?;
    let table = markdown(&report);
    write_text(&out.join("quality.md"), &table)?;
    print!("{table}");
    Ok(())
}

/// The camera poses that get a converged reference: frame 0 for a still camera, every evaluated
/// frame for a moving one.
pub fn reference_frames(camera: &str, evaluated: &[u32]) -> Vec<u32> {
    if camera == "moving" {
        evaluated.to_vec()
    } else {
        vec![0]
    }
}

/// The eyes that get converged references: the left, and in a stereo run the right after it.
pub fn reference_eyes(args: &QualityArgs) -> &'static [Eye] {
    match args.eyes {
        Eyes::Both => Eyes::Both.list(),
        Eyes::Left | Eyes::Right => Eyes::Left.list(),
    }
}

/// The name of the reference of `camera` at `frame` for `eye` in the output folder; the eye is
/// named in a stereo run (`eyes` both) only.
pub fn reference_file_name(eyes: Eyes, camera: &str, eye: Eye, frame: u32) -> String {
    match eyes {
        Eyes::Both => format!(
            "reference_{camera}_{}_{frame:04}.exr",
            super::setup::eye_name(eye)
        ),
        Eyes::Left | Eyes::Right => format!("reference_{camera}_{frame:04}.exr"),
    }
}

/// Writes a converged reference into `out` ([`reference_file_name`]); the displayed `.png`
/// beside it follows once the camera's display exposure is known
/// ([`write_displayed_references`]).
pub fn write_reference(
    out: &Path,
    args: &QualityArgs,
    camera: &str,
    eye: Eye,
    frame: u32,
    image: &[[f32; 4]],
) -> Result<()> {
    let path = out.join(reference_file_name(args.eyes, camera, eye, frame));
    write_exr(&path, args.width, args.height, image)
}

/// The scene and the head of the references of one camera: the eyes `fovea render --eyes
/// left|both` renders, through the same projection, at each frame of [`reference_frames`].
pub struct ReferenceViews {
    scene: Scene,
    rig: fovea_stage::projection::EyeRig,
    /// The head pose at each reference frame.
    heads: Vec<(u32, CameraPose)>,
}

impl ReferenceViews {
    /// The pose of `eye` at reference frame `frame`.
    pub fn pose(&self, frame: u32, eye: Eye) -> Option<CameraPose> {
        self.heads
            .iter()
            .find(|(f, _)| *f == frame)
            .map(|(_, head)| self.rig.eye(head, eye))
    }
}

/// Loads the scene (no device) and places the head at each frame of [`reference_frames`].
pub fn reference_views(
    args: &QualityArgs,
    camera: &str,
    evaluated: &[u32],
) -> Result<ReferenceViews> {
    let moving = camera == "moving";
    let hmd = fovea_hal::HmdDescription::resolve(args.headset)
        .with_context(|| format!("--headset {}", args.headset))?;
    // A stereo run offsets the eyes (in either projection): the references see what the runs do.
    let rig = fovea_stage::projection::EyeRig {
        projection: args.camera.projection,
        hmd,
        stereo: args.eyes == Eyes::Both,
        width: args.width,
        height: args.height,
        metres_per_unit: args.camera.world_scale,
    };
    let (scene, scene_camera) = fovea_stage::look::load(
        args.scene,
        args.camera,
        &args.profile.environment,
        rig.framing(),
    )?;
    let start = rig.head(&scene_camera);
    let centre = scene.bounds().center();
    let heads = reference_frames(camera, evaluated)
        .into_iter()
        .map(|f| {
            let head = if moving {
                camera_path::orbit(&start, centre, f, args.frames)
            } else {
                start
            };
            (f, head)
        })
        .collect();
    Ok(ReferenceViews { scene, rig, heads })
}

/// A Cartesian renderer set up for the references of `camera`, and their views.
pub struct ReferenceRenderer {
    pub ctx: std::sync::Arc<fovea_renderer::vk::Context>,
    pub renderer: Renderer,
    pub views: ReferenceViews,
}

pub fn reference_renderer(
    args: &QualityArgs,
    camera: &str,
    evaluated: &[u32],
) -> Result<ReferenceRenderer> {
    let views = reference_views(args, camera, evaluated)?;
    let ctx = super::open_device(args.device, args.validation)?;
    let size = UVec2::new(args.width, args.height);
    let settings = RenderSettings {
        seed: args.seed.wrapping_add(0x5eed),
        ..Default::default()
    };
    let renderer = Renderer::new(&ctx, &views.scene, Box::new(Cartesian::new(size)), settings)?;
    Ok(ReferenceRenderer {
        ctx,
        renderer,
        views,
    })
}

/// The converged references of one camera, one per evaluated frame: the left eye's, and in a
/// stereo run the right eye's with the warp of the right eye into the left.
pub struct References {
    left: Vec<Vec<[f32; 4]>>,
    stereo: Option<StereoReferences>,
    /// The display exposure of every run of this camera ([`QualityArgs::display_exposure`]).
    exposure: f32,
}

impl References {
    /// From the images of [`reference_frames`] of each eye of [`reference_eyes`], in that order
    /// (`images[eye][frame]`); a still camera's one image stands for every evaluated frame. A
    /// stereo run needs the references' views (the eyes' depth for the warp).
    pub fn new(
        args: &QualityArgs,
        camera: &str,
        evaluated: &[u32],
        images: Vec<Vec<Vec<[f32; 4]>>>,
        views: Option<&ReferenceViews>,
    ) -> Result<References> {
        let eyes = reference_eyes(args);
        if images.len() != eyes.len() {
            bail!(
                "{} eyes' references for a run of {} eyes",
                images.len(),
                eyes.len()
            );
        }
        let exposure = display_multiplier(args, &images)?;
        let mut per_eye = images
            .into_iter()
            .map(|v| per_evaluated_frame(camera, v, evaluated));
        let left = per_eye.next().context("the left eye's references")?;
        let stereo = match (per_eye.next(), views) {
            (None, _) => None,
            (Some(right), Some(views)) => {
                let heads: Vec<CameraPose> = views.heads.iter().map(|(_, h)| *h).collect();
                Some(StereoReferences::new(
                    &views.scene,
                    &views.rig,
                    &heads,
                    right,
                    exposure,
                ))
            }
            (Some(_), None) => bail!("a stereo run's references need their views"),
        };
        Ok(References {
            left,
            stereo,
            exposure,
        })
    }
}

/// The display exposure of a camera whose references are `images[eye][frame]`: metered on the
/// left eye's first.
fn display_multiplier(args: &QualityArgs, images: &[Vec<Vec<[f32; 4]>>]) -> Result<f32> {
    let first = images
        .first()
        .and_then(|eye| eye.first())
        .context("a camera without references")?;
    Ok(args
        .display_exposure
        .multiplier(first, args.width, args.height))
}

/// Writes the references of `camera` as displayed (`.png` beside each `.exr`), at the display
/// exposure of [`display_multiplier`].
pub fn write_displayed_references(
    out: &Path,
    args: &QualityArgs,
    camera: &str,
    evaluated: &[u32],
    images: &[Vec<Vec<[f32; 4]>>],
) -> Result<()> {
    let exposure = display_multiplier(args, images)?;
    for (&eye, eye_images) in reference_eyes(args).iter().zip(images) {
        for (f, image) in reference_frames(camera, evaluated)
            .into_iter()
            .zip(eye_images)
        {
            let path = out.join(reference_file_name(args.eyes, camera, eye, f));
            write_png(
                &path.with_extension("png"),
                args.width,
                args.height,
                &tonemap_preview(image, exposure, ToneCurve::Aces),
            )?;
        }
    }
    Ok(())
}

/// Converged references of the evaluated frames' camera poses (one for a still camera, the same
/// for every evaluated frame) for each eye of [`reference_eyes`], written to
/// `DIR/reference_<camera>_NNNN.exr` (a stereo run: `reference_<camera>_<eye>_NNNN.exr`), and
/// each as displayed beside it (`.png`).
fn references(args: &QualityArgs, camera: &str, evaluated: &[u32]) -> Result<References> {
    if let Some(from) = args.references {
        return copied_references(args, from, camera, evaluated);
    }
    let mut r = reference_renderer(args, camera, evaluated)?;
    let mut images = Vec::new();
    for &eye in reference_eyes(args) {
        let mut eye_images = Vec::new();
        for f in reference_frames(camera, evaluated) {
            let pose = r.views.pose(f, eye).context("a reference frame's pose")?;
            let reference = crate::reference_sum::render(
                &mut r.renderer,
                &pose,
                args.reference_spp,
                fovea_renderer::frame::REALTIME_MAX_DEPTH,
                &mut |_| Ok(()),
            )?;
            write_reference(args.out, args, camera, eye, f, &reference)?;
            eye_images.push(reference);
        }
        images.push(eye_images);
    }
    super::check_validation(&r.ctx)?;
    write_displayed_references(args.out, args, camera, evaluated, &images)?;
    References::new(args, camera, evaluated, images, Some(&r.views))
}

/// What the converged references of `camera` depend on, as one string: the scene, size,
/// headset, eyes, samples, seed, the camera and light flags and, for the moving camera, the frames
/// (its poses). The gaze and the render profile's sampling settings do not touch them: references
/// trace every pixel with the engine's defaults. A file named in it (scene, environment map) is
/// named, not hashed.
pub fn reference_key(args: &QualityArgs, camera: &str) -> String {
    let poses = match camera {
        "moving" => format!("frames {}/{}", args.frames, args.eval_frames),
        _ => "still".to_string(),
    };
    format!(
        "{} {}x{} {} eyes {} {poses} spp {} seed {} {:?} {:?}",
        args.scene,
        args.width,
        args.height,
        args.headset,
        args.eyes.name(),
        args.reference_spp,
        args.seed,
        args.camera,
        args.profile.environment
    )
}

/// `--references FROM`: the references of `camera` read from an earlier quality folder whose
/// quality.json has this run's [`reference_key`], and copied into this run's folder.
fn copied_references(
    args: &QualityArgs,
    from: &Path,
    camera: &str,
    evaluated: &[u32],
) -> Result<References> {
    let report_path = from.join("quality.json");
    let text = std::fs::read_to_string(&report_path)
        .with_context(|| format!("--references: reading {}", report_path.display()))?;
    let report: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("--references: {}", report_path.display()))?;
    let key = reference_key(args, camera);
    match report["reference_keys"][camera].as_str() {
        Some(theirs) if theirs == key => {}
        Some(theirs) => bail!(
            "--references {}: its {camera} camera's references are of other settings \
             (quality.json reference_keys.{camera} \"{theirs}\", this run's \"{key}\")",
            from.display()
        ),
        None => bail!(
            "--references {}: quality.json has no reference_keys.{camera} (no {camera} camera \
             in that run, or written by an older fovea)",
            from.display()
        ),
    }
    let size = Some((args.width, args.height));
    let mut images = Vec::new();
    for &eye in reference_eyes(args) {
        let mut eye_images = Vec::new();
        for f in reference_frames(camera, evaluated) {
            let path = from.join(reference_file_name(args.eyes, camera, eye, f));
            let (_, _, image) =
                fovea_stage::decode::read_exr(&path, fovea_stage::decode::MAX_IMAGE_PIXELS, size)
                    .with_context(|| format!("--references: {}", path.display()))?;
            write_reference(args.out, args, camera, eye, f, &image)?;
            eye_images.push(image);
        }
        images.push(eye_images);
    }
    write_displayed_references(args.out, args, camera, evaluated, &images)?;
    let views = match args.eyes {
        Eyes::Both => Some(reference_views(args, camera, evaluated)?),
        Eyes::Left | Eyes::Right => None,
    };
    References::new(args, camera, evaluated, images, views.as_ref())
}

/// The references of [`reference_frames`] as one per evaluated frame (the still camera's one
/// repeated).
fn per_evaluated_frame(
    camera: &str,
    mut references: Vec<Vec<[f32; 4]>>,
    evaluated: &[u32],
) -> Vec<Vec<[f32; 4]>> {
    if camera == "moving" {
        references
    } else {
        vec![references.remove(0); evaluated.len()]
    }
}

/// The run's evaluated frames against their references, ring metrics averaged over frames.
fn measure(
    args: &QualityArgs,
    dir: &Path,
    evaluated: &[u32],
    (references, exposure): (&[Vec<[f32; 4]>], f32),
    ppd: f32,
    eye: &EyeFiles,
) -> Result<RunQuality> {
    let report_path = dir.join("report.json");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report_path)?)
            .with_context(|| format!("reading {}", report_path.display()))?;
    let mut evals: Vec<Evaluation> = Vec::new();
    let mut gazes = Vec::new();
    // Per consecutive pair: flicker per ring and whole frame.
    let mut flickers: Vec<(Vec<Option<f64>>, Option<f64>)> = Vec::new();
    let mut previous: Option<(u32, Vec<u8>, Vec<u8>)> = None;
    // With the latency model: the frames judged around the true gaze.
    let latency = eye.latency && report.get("gaze_true").is_some();
    let (mut evals_true, mut gazes_true, mut foveal, mut foveal_true) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (&f, reference) in evaluated.iter().zip(references) {
        let gaze = &report[eye.gaze_key][f as usize];
        let gaze = Vec2::new(
            gaze[0].as_f64().unwrap_or(0.0) as f32,
            gaze[1].as_f64().unwrap_or(0.0) as f32,
        );
        let path: PathBuf = dir.join(format!("frame_{f:04}{}.exr", eye.suffix));
        let size = Some((args.width, args.height));
        let (_, _, test) =
            fovea_stage::decode::read_exr(&path, fovea_stage::decode::MAX_IMAGE_PIXELS, size)?;
        let mut eval = evaluate(reference, &test, args.width, args.height, gaze, args.rings);
        // FLIP on what is displayed: the frame's PNG against the reference through the tone curve.
        let displayed = fovea_stage::decode::read_rgba8(
            &dir.join(format!("frame_{f:04}{}.png", eye.suffix)),
            fovea_stage::decode::MAX_IMAGE_PIXELS,
            size,
        )?
        .2;
        let reference_displayed = tonemap_preview(reference, exposure, ToneCurve::Aces);
        let flip = flip_map(
            &reference_displayed,
            &displayed,
            args.width,
            args.height,
            ppd,
        );
        add_flip(&mut eval, &flip);
        if latency {
            let g = &report["gaze_true"][f as usize];
            let true_gaze = g[0]
                .as_f64()
                .zip(g[1].as_f64())
                .map(|(x, y)| Vec2::new(x as f32, y as f32));
            gazes_true.push(true_gaze.map(|g| g.to_array()));
            let inner = |g: Vec2| {
                Rings::new(args.width, args.height, g, args.rings).inner_mean(&flip, FOVEAL_RINGS)
            };
            if let Some(tg) = true_gaze {
                let mut e = evaluate(reference, &test, args.width, args.height, tg, args.rings);
                add_flip(&mut e, &flip);
                evals_true.push(e);
                foveal_true.extend(inner(tg));
                foveal.extend(inner(gaze));
            }
        }
        if let Some((_, test_prev, reference_prev)) = previous.as_ref().filter(|p| p.0 + 1 == f) {
            let map = flicker_map(test_prev, &displayed, reference_prev, &reference_displayed);
            flickers.push((
                Rings::new(args.width, args.height, gaze, args.rings).mean(&map),
                metrics_mean(&map),
            ));
        }
        previous = Some((f, displayed, reference_displayed));
        evals.push(eval);
        gazes.push(gaze.to_array());
    }
    let n = evals.len() as f64;
    let mean = |v: Vec<Option<f64>>| -> Option<f64> {
        v.iter()
            .copied()
            .sum::<Option<f64>>()
            .map(|s| s / v.len() as f64)
    };
    let mean_of = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
    let rings_true_gaze = (latency && !evals_true.is_empty()).then(|| {
        (0..args.rings)
            .map(|i| RingMean {
                ecc_inner: evals_true[0].rings[i].ecc_inner,
                ecc_outer: evals_true[0].rings[i].ecc_outer,
                rmse: mean(
                    evals_true
                        .iter()
                        .map(|e| e.rings[i].metrics.rmse.map(|r| r * r))
                        .collect(),
                )
                .map(f64::sqrt),
                ssim: mean(evals_true.iter().map(|e| e.rings[i].metrics.ssim).collect()),
                flip: mean(evals_true.iter().map(|e| e.rings[i].metrics.flip).collect()),
                flicker: None,
            })
            .collect()
    });
    let rings = (0..args.rings)
        .map(|i| RingMean {
            ecc_inner: evals[0].rings[i].ecc_inner,
            ecc_outer: evals[0].rings[i].ecc_outer,
            // RMSE averaged as MSE, so frames add like pixels do.
            rmse: mean(
                evals
                    .iter()
                    .map(|e| e.rings[i].metrics.rmse.map(|r| r * r))
                    .collect(),
            )
            .map(f64::sqrt),
            ssim: mean(evals.iter().map(|e| e.rings[i].metrics.ssim).collect()),
            flip: mean(evals.iter().map(|e| e.rings[i].metrics.flip).collect()),
            flicker: (!flickers.is_empty())
                .then(|| mean(flickers.iter().map(|f| f.0[i]).collect()))
                .flatten(),
        })
        .collect();
    Ok(RunQuality {
        display_exposure: exposure,
        run_dir: String::new(),
        camera: String::new(),
        method: String::new(),
        denoiser: String::new(),
        taa: String::new(),
        stereo_noise: String::new(),
        cross_eye_reuse: report["cross_eye_reuse"].as_bool().unwrap_or(false),
        frame_gpu_ms: report["frame_gpu_ms"].as_f64().unwrap_or(0.0),
        samples_traced: report["samples_traced"].as_u64().unwrap_or(0),
        rays_traced: report["rays_traced"].as_u64().unwrap_or(0),
        frames: evaluated.to_vec(),
        gaze: gazes,
        rings,
        frame_rmse: (evals
            .iter()
            .map(|e| e.frame.rmse.unwrap_or(0.0).powi(2))
            .sum::<f64>()
            / n)
            .sqrt(),
        frame_ssim: evals
            .iter()
            .map(|e| e.frame.ssim.unwrap_or(0.0))
            .sum::<f64>()
            / n,
        frame_flip: evals
            .iter()
            .map(|e| e.frame.flip.unwrap_or(0.0))
            .sum::<f64>()
            / n,
        frame_flicker: (!flickers.is_empty())
            .then(|| mean(flickers.iter().map(|f| f.1).collect()))
            .flatten(),
        gaze_true: latency.then_some(gazes_true),
        rings_true_gaze,
        foveal_flip: mean_of(&foveal),
        foveal_flip_true_gaze: mean_of(&foveal_true),
        binocular: None,
    })
}

/// The render across the headset eye's horizontal FOV, in pixels per degree.
fn flip_ppd(args: &QualityArgs) -> Result<f32> {
    let hmd = fovea_hal::HmdDescription::resolve(args.headset)
        .with_context(|| format!("--headset {}", args.headset))?;
    Ok(crate::eval::flip::headset_ppd(&hmd, args.width))
}

/// A run's row label: method + denoiser, TAA, and the stereo noise where runs differ in it or
/// render both eyes.
fn label(r: &Report, q: &RunQuality) -> String {
    let noises_differ = r.runs.iter().any(|o| o.stereo_noise != q.stereo_noise);
    match noises_differ || r.eyes == "both" {
        true => format!(
            "{} + {}, {}, {}",
            q.method,
            q.denoiser,
            q.taa,
            stereo_label(&q.stereo_noise, q.cross_eye_reuse)
        ),
        false => format!("{} + {}, {}", q.method, q.denoiser, q.taa),
    }
}

/// Per camera: one row per combination, RMSE / SSIM per ring and whole frame; then, per filter,
/// whether VP beats Cartesian in the innermost ring (the paper's claim).
fn markdown(r: &Report) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Quality over a gaze sequence: {} at {}×{}, gaze {}, {} frames, metrics averaged over the last {}, \
         against {}-spp Cartesian references; rings of the paper's normalised eccentricity around each frame's gaze; \
         blur σ at 30° {}; resampling {}.\n",
        r.scene, r.width, r.height, r.gaze_source, r.frames, r.eval_frames, r.reference_spp, r.blur_sigma_at_30,
        r.resampling
    );
    for camera in CAMERAS {
        let runs: Vec<&RunQuality> = r.runs.iter().filter(|q| q.camera == *camera).collect();
        let Some(first) = runs.first() else {
            for q in r.refused.iter().filter(|q| q.camera == *camera) {
                let _ = writeln!(
                    s,
                    "- {camera} camera, {} + {}, {}: refused: {}",
                    q.method, q.denoiser, q.taa, q.reason
                );
            }
            continue;
        };
        let _ = write!(
            s,
            "**{camera} camera** — RMSE / SSIM / FLIP\n\n| method + denoiser, TAA |"
        );
        for ring in &first.rings {
            let _ = write!(s, " {:.0}–{:.0}° |", ring.ecc_inner, ring.ecc_outer);
        }
        let _ = writeln!(s, " frame | GPU ms |");
        let _ = writeln!(s, "|---|{}---|---|", "---|".repeat(first.rings.len()));
        for q in &runs {
            let _ = write!(s, "| {} |", label(r, q));
            for ring in &q.rings {
                match (ring.rmse, ring.ssim, ring.flip) {
                    (Some(e), Some(m), Some(f)) => {
                        let _ = write!(s, " {e:.4} / {m:.3} / {f:.3} |");
                    }
                    _ => s.push_str(" – |"),
                }
            }
            let _ = writeln!(
                s,
                " {:.4} / {:.3} / {:.3} | {:.1} |",
                q.frame_rmse, q.frame_ssim, q.frame_flip, q.frame_gpu_ms
            );
        }
        for q in r.refused.iter().filter(|q| q.camera == *camera) {
            let _ = writeln!(
                s,
                "| {} + {}, {} | refused: {}{} |",
                q.method,
                q.denoiser,
                q.taa,
                q.reason,
                " |".repeat(first.rings.len() + 1)
            );
        }
        s.push('\n');
        if first.frame_flicker.is_some() {
            let _ = write!(s, "Temporal flicker (frame-to-frame change beyond the reference's, displayed sRGB)\n\n| method + denoiser, TAA |");
            for ring in &first.rings {
                let _ = write!(s, " {:.0}–{:.0}° |", ring.ecc_inner, ring.ecc_outer);
            }
            let _ = writeln!(s, " frame |\n|---|{}---|", "---|".repeat(first.rings.len()));
            for q in &runs {
                let _ = write!(s, "| {} |", label(r, q));
                for ring in &q.rings {
                    let _ = write!(
                        s,
                        " {} |",
                        ring.flicker.map_or("–".to_string(), |f| format!("{f:.4}"))
                    );
                }
                let _ = writeln!(
                    s,
                    " {} |",
                    q.frame_flicker
                        .map_or("–".to_string(), |f| format!("{f:.4}"))
                );
            }
            s.push('\n');
        }
        if let Some(first_true) = first.rings_true_gaze.as_ref() {
            let _ = write!(
                s,
                "FLIP around the true gaze at display time ({}, predictor {})\n\n| method + denoiser, TAA |",
                r.latency.as_deref().unwrap_or(""),
                r.gaze_predict.as_deref().unwrap_or("")
            );
            for ring in first_true {
                let _ = write!(s, " {:.0}–{:.0}° |", ring.ecc_inner, ring.ecc_outer);
            }
            let _ = writeln!(
                s,
                " foveal (2 rings), true gaze | foveal, rendered gaze |\n|---|{}---|---|",
                "---|".repeat(first_true.len())
            );
            let cell = |v: Option<f64>| v.map_or("–".to_string(), |f| format!("{f:.4}"));
            for q in &runs {
                let _ = write!(s, "| {} |", label(r, q));
                for ring in q.rings_true_gaze.iter().flatten() {
                    let _ = write!(s, " {} |", cell(ring.flip));
                }
                let _ = writeln!(
                    s,
                    " {} | {} |",
                    cell(q.foveal_flip_true_gaze),
                    cell(q.foveal_flip)
                );
            }
            s.push('\n');
        }
        let stereo: Vec<quality_stereo::StereoRow> = runs
            .iter()
            .filter_map(|q| {
                let b = q.binocular.as_ref()?;
                Some(quality_stereo::StereoRow {
                    label: label(r, q),
                    binocular: &b.measure,
                    flip: [q.frame_flip, b.right_eye.frame_flip],
                    flicker: [q.frame_flicker, b.right_eye.frame_flicker],
                })
            })
            .collect();
        s.push_str(&quality_stereo::markdown(&stereo));
        for vp in runs.iter().filter(|q| q.method == "vp") {
            let cartesian = runs.iter().find(|q| {
                q.method == "cartesian"
                    && q.denoiser == vp.denoiser
                    && q.taa == vp.taa
                    && q.stereo_noise == vp.stereo_noise
                    && q.cross_eye_reuse == vp.cross_eye_reuse
            });
            if let (Some(c), Some(v_rmse)) = (cartesian, vp.rings[0].rmse) {
                if let Some(c_rmse) = c.rings[0].rmse {
                    let verdict = if v_rmse < c_rmse {
                        "VP wins"
                    } else {
                        "Cartesian wins"
                    };
                    let _ = writeln!(
                        s,
                        "- {} + TAA {}, innermost ring: Cartesian / VP RMSE = {:.2}× ({verdict})",
                        vp.denoiser,
                        vp.taa,
                        c_rmse / v_rmse
                    );
                }
            }
        }
        s.push('\n');
    }
    s
}

// `fovea quality`'s flags (also the command a quality sweep splits; its help is the variant's in
// `crate::cli::Command`).
#[derive(clap::Args)]
pub struct QualityCommand {
    #[arg(long, default_value = fovea_stage::scenes::DEFAULT_SCENE)]
    pub scene: String,
    #[arg(long, default_value_t = 160)]
    pub width: u32,
    #[arg(long, default_value_t = 180)]
    pub height: u32,
    #[arg(long, default_value = "fove0")]
    pub headset: String,
    /// Gaze source of every run (as for `render`); rings follow each frame's gaze.
    #[arg(long, default_value = "sim:1")]
    pub gaze: String,
    #[arg(long, default_value_t = 16)]
    pub frames: u32,
    /// The last this many frames are evaluated and averaged.
    #[arg(long, default_value_t = 4)]
    pub eval_frames: u32,
    /// Sampling methods (`all`: every `--method` of `fovea render`).
    #[arg(long, value_delimiter = ',', default_value = "vp,cartesian")]
    pub methods: Vec<String>,
    /// Denoisers to compare (default: every one built in).
    #[arg(long, value_delimiter = ',')]
    pub denoisers: Vec<String>,
    #[arg(long, value_delimiter = ',', default_value = "off")]
    pub taa: Vec<String>,
    /// still and/or moving (the scene's default camera path).
    #[arg(long, value_delimiter = ',', default_value = "still,moving")]
    pub cameras: Vec<String>,
    /// left, or both: every run renders both eyes (the headset's eye offsets), each eye is
    /// judged against its own reference, and the binocular consistency measure is added
    /// (the right eye warped into the left through the converged depth).
    #[arg(long, default_value = "left")]
    pub eyes: String,
    #[arg(long, default_value_t = 256)]
    pub reference_spp: u32,
    /// Take the converged references from an earlier `fovea quality` folder instead of rendering
    /// them: its quality.json must record the same reference settings for each camera (scene,
    /// size, headset, eyes, samples, seed, camera and light flags; the frames for the moving
    /// camera); they are copied into --out. E.g. the same scene at several sample budgets
    /// (profiles) or gaze sources with one set of references
    #[arg(long)]
    pub references: Option<PathBuf>,
    /// Equal-width rings from the gaze out to the farthest corner.
    #[arg(long, default_value_t = 10)]
    pub rings: usize,
    #[arg(long, default_value_t = 1)]
    pub seed: u32,
    /// Render profile (TOML) for every run; flags below override it.
    #[arg(long)]
    pub profile: Option<PathBuf>,
    /// Foveated blur σ at 30° (0 turns it off).
    #[arg(long)]
    pub blur_sigma: Option<f32>,
    /// Where the foveated blur runs: screen | grid (see `fovea render --blur-space`).
    #[arg(long)]
    pub blur_space: Option<String>,
    /// The one exposure every run and reference of a camera is displayed at (FLIP, flicker, the
    /// PNGs): stops (0: radiance as it is), or metered (automatic exposure's meter on the
    /// camera's first converged reference, flat over the image, held for every frame).
    #[arg(long, default_value = "0", allow_hyphen_values = true)]
    pub display_exposure: String,
    #[arg(long, default_value = "out/quality")]
    pub out: PathBuf,
    #[command(flatten)]
    pub look: SceneFlags,
    #[command(flatten)]
    pub latency: LatencyFlags,
    #[command(flatten)]
    pub device: DeviceArgs,
}

impl QualityCommand {
    pub fn run(self) -> Result<()> {
        self.with_args(&mut run)
    }

    /// The flags as the command's arguments, handed to `run` (the command itself, or a sweep).
    pub fn with_args(self, run: &mut dyn FnMut(&QualityArgs) -> Result<()>) -> Result<()> {
        let QualityCommand {
            scene,
            width,
            height,
            headset,
            gaze,
            frames,
            eval_frames,
            methods,
            denoisers,
            taa,
            cameras,
            eyes,
            reference_spp,
            references,
            rings,
            seed,
            profile,
            blur_sigma,
            blur_space,
            display_exposure,
            out,
            look,
            latency,
            device,
        } = self;
        device.choose_traversal()?;
        let base = match &profile {
            Some(path) => RenderProfile::load(path)?,
            None => RenderProfile::default(),
        };
        let profile = base.override_with(&ProfileOverrides {
            blur_sigma,
            blur_space,
            environment: look.environment()?,
            texture_lod: look.texture_lod.clone(),
            path_regularisation: look.path_regularisation,
            offscreen_samples: look.offscreen_samples.clone(),
            resampling: look.resampling.clone(),
            cross_eye_reuse: look.cross_eye_reuse.clone(),
            gaze_timing: latency.timing()?,
            ..Default::default()
        })?;
        let all: Vec<String> = DenoiserSettings::NAMES
            .iter()
            .map(|s| s.to_string())
            .collect();
        let stereo_noises = match &look.stereo_noise {
            Some(list) => list
                .split(',')
                .map(|n| StereoNoise::parse(n.trim()).context("--stereo-noise"))
                .collect::<Result<Vec<_>>>()?,
            None => Vec::new(),
        };
        run(&QualityArgs {
            scene: &scene,
            width,
            height,
            headset: &headset,
            gaze: &gaze,
            frames,
            eval_frames,
            methods: &expand_methods(methods),
            denoisers: if denoisers.is_empty() {
                &all
            } else {
                &denoisers
            },
            taa: &taa,
            cameras: &cameras,
            reference_spp,
            rings,
            seed,
            profile,
            eyes: Eyes::parse(&eyes)?,
            stereo_noises: &stereo_noises,
            camera: &look.camera()?,
            references: references.as_deref(),
            display_exposure: DisplayExposure::parse(&display_exposure)?,
            out: &out,
            device: device.device.as_deref(),
            validation: device.validation,
        })
    }
}
