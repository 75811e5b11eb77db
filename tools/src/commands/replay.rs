//! `fovea replay TRACE… --baseline DIR`: renders each gaze trace deterministically (fixed seed,
//! frame k at k / refresh of the headset profile, still camera) and compares every frame with the
//! stored baseline: change (FLIP, RMSE), quality (FLIP against the converged reference; may not grow),
//! the gaze used (the playback), cost (reported, never a failure). Exit 0 within tolerance, 1 on
//! a regression, 2 on bad input. `--update-baseline` writes the baseline instead.

use super::flags::DeviceArgs;
use super::render::RenderArgs;
use super::render_args::{RenderDefaults, RenderOpts, DEFAULT_SCALE};
use crate::eval::flip::{flip_image, flip_map};
use crate::eval::metrics::Rings;
use crate::output::{prepare_output_dir, tonemap_preview, write_json, write_png, write_text};
use crate::replay::baseline::{
    current_commit, Baseline, FrameRecord, Params, Store, TraceId, FORMAT, MAX_FRAMES, MAX_PIXELS,
    MAX_REFERENCE_SPP, MAX_RINGS,
};
use crate::replay::{check_frame, quality_flip, FrameCheck, FrameImages, Tolerances};
use anyhow::{bail, Context, Result};
use fovea_renderer::frame::RenderSettings;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::Cartesian;
use glam::{UVec2, Vec2};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

pub struct ReplayArgs<'a> {
    pub traces: &'a [String],
    pub baseline: &'a Path,
    /// The render settings; `gaze`, `out` and `exr` are set per trace.
    pub render: RenderArgs<'a>,
    /// `--frames` as given (`None`: the baseline's count, or 8 for a new baseline).
    pub frames: Option<u32>,
    pub out: &'a Path,
    pub update: bool,
    pub reference_spp: u32,
    pub rings: usize,
    pub tolerances: Tolerances,
}

/// Frames of a new baseline without `--frames`.
pub const DEFAULT_FRAMES: u32 = 8;

/// Some frame left the tolerances (exit status 1).
#[derive(Debug)]
pub struct Regression {
    pub failed_frames: usize,
    pub report: std::path::PathBuf,
}

impl std::fmt::Display for Regression {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} frame(s) outside the tolerances; see {}",
            self.failed_frames,
            self.report.display()
        )
    }
}

impl std::error::Error for Regression {}

/// Anything but a regression: bad flags, traces or baselines (exit status 2).
#[derive(Debug)]
pub struct BadInput(pub String);

impl std::fmt::Display for BadInput {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for BadInput {}

/// One trace's checks (a part of `replay.json`; a sweep job's result).
#[derive(Serialize, Deserialize)]
pub struct TraceResult {
    trace: String,
    baseline: String,
    /// The folder of this run's frames under `--out` (`run_<baseline folder name>`).
    run: String,
    baseline_commit: String,
    baseline_device: String,
    /// Settings that differ from the baseline's: (name, baseline, now).
    param_changes: Vec<(String, String, String)>,
    frames: Vec<FrameCheck>,
    failed_frames: Vec<u32>,
    /// Pass → GPU ms now / in the baseline (report only).
    cost_ratio: BTreeMap<String, f64>,
    /// With the latency model: mean FLIP against the reference of the innermost two rings
    /// around the rendered gaze and around the true gaze at display time (report only).
    #[serde(skip_serializing_if = "Option::is_none")]
    foveal_flip: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    foveal_flip_true_gaze: Option<f64>,
}

/// Rings of the fovea in `foveal_flip*`: the innermost two.
const FOVEAL_RINGS: usize = 2;

#[derive(Serialize)]
struct ReplayReport<'a> {
    tolerances: &'a Tolerances,
    traces: Vec<TraceResult>,
    passed: bool,
}

pub fn run(args: &ReplayArgs) -> Result<()> {
    run_checked(args).map_err(|e| {
        if e.is::<Regression>() {
            e
        } else {
            BadInput(format!("{e:#}")).into()
        }
    })
}

/// Checks the flags before anything renders.
pub fn check(args: &ReplayArgs) -> Result<()> {
    if args.traces.is_empty() {
        bail!(
            "fovea replay needs at least one trace (a trace file or a gaze source such as sim:1)"
        );
    }
    if !(1..=MAX_RINGS).contains(&args.rings)
        || !(1..=MAX_REFERENCE_SPP).contains(&args.reference_spp)
    {
        bail!("--rings must be in 1..={MAX_RINGS} and --reference-spp in 1..={MAX_REFERENCE_SPP}");
    }
    if let Some(n) = args.frames.filter(|n| !(1..=MAX_FRAMES).contains(n)) {
        bail!("--frames {n}: a baseline holds 1..={MAX_FRAMES} frames");
    }
    if let (Some(w), Some(h)) = (args.render.width, args.render.height) {
        if w as u64 * h as u64 > MAX_PIXELS {
            bail!("--width {w} --height {h}: a baseline frame holds at most {MAX_PIXELS} pixels");
        }
    }
    if args.render.camera_path.moves() || args.render.debug_views {
        bail!("fovea replay renders a still camera without debug views (--camera-path/--debug-views do not apply)");
    }
    Ok(())
}

fn run_checked(args: &ReplayArgs) -> Result<()> {
    check(args)?;
    // Baselines first: a folder another run updates is refused before anything renders.
    let store = if args.update {
        Store::open_update(args.baseline)?
    } else {
        Store::open_read(args.baseline)?
    };
    let _out_dir = prepare_output_dir(args.out)?;
    let mut results = Vec::new();
    for trace in args.traces {
        let result = replay_trace(args, &store, trace, args.out)
            .with_context(|| format!("trace {trace}"))?;
        results.push(result);
    }
    if args.update {
        println!(
            "fovea replay: wrote {} baseline(s) under {}",
            results.len(),
            args.baseline.display()
        );
        return Ok(());
    }
    match write_report(args, results, args.out)? {
        Some(regression) => Err(regression.into()),
        None => Ok(()),
    }
}

/// Writes `out/replay.json` and `out/replay.md` from the traces' results (in the order of the
/// traces) and prints the table; the regression, if a frame left the tolerances (naming the
/// `replay.md` of the command's own `--out`).
pub fn write_report(
    args: &ReplayArgs,
    results: Vec<TraceResult>,
    out: &Path,
) -> Result<Option<Regression>> {
    let failed: usize = results.iter().map(|r| r.failed_frames.len()).sum();
    let report = ReplayReport {
        tolerances: &args.tolerances,
        passed: failed == 0,
        traces: results,
    };
    write_json(&out.join("replay.json"), &report)?;
    let table = markdown(&report);
    write_text(&out.join("replay.md"), &table)?;
    print!("{table}");
    Ok((failed > 0).then(|| Regression {
        failed_frames: failed,
        report: args.out.join("replay.md"),
    }))
}

/// The folder of `trace`'s frames inside the output folder (`run_` and its baseline folder's name).
pub fn run_dir_name(trace: &str) -> Result<String> {
    Ok(format!("run_{}", TraceId::of(trace)?.key))
}

/// Renders `trace` into `out`/[`run_dir_name`] and checks it against its baseline in `store` (or
/// stages the baseline with `--update-baseline`).
pub fn replay_trace(
    args: &ReplayArgs,
    store: &Store,
    trace: &str,
    out: &Path,
) -> Result<TraceResult> {
    // The trace first: a file that is not one is named as such, not as a missing baseline.
    let hmd = fovea_hal::HmdDescription::resolve(args.render.headset)?;
    fovea_stage::gaze::GazeDriver::open(
        trace,
        &hmd,
        args.render.width.unwrap_or(64),
        args.render.height.unwrap_or(72),
    )?;
    let id = TraceId::of(trace)?;
    let base_dir = store.folder(&id);
    let loaded = if args.update {
        None
    } else {
        Some(store.load(&id)?)
    };
    let baseline = loaded.as_ref().map(|l| &l.baseline);
    let frames = match (baseline, args.frames) {
        (Some(b), Some(n)) if n != b.params.frames => bail!(
            "--frames {n}: the baseline {} has {} frames",
            base_dir.display(),
            b.params.frames
        ),
        (Some(b), _) => b.params.frames,
        (None, n) => n.unwrap_or(DEFAULT_FRAMES),
    };
    if let (Some(b), Some(w), Some(h)) = (baseline, args.render.width, args.render.height) {
        if (w, h) != (b.params.width, b.params.height) {
            bail!(
                "--width {w} --height {h}: the baseline {} is {}×{} (replay at its size)",
                base_dir.display(),
                b.params.width,
                b.params.height
            );
        }
    }
    let mut staging = match args.update {
        true => Some(store.begin(&id)?),
        false => None,
    };
    let run_dir = out.join(format!("run_{}", id.key));
    let render = RenderArgs {
        gaze: trace,
        out: &run_dir,
        frames,
        eyes: super::setup::Eyes::Left,
        camera_path: Default::default(),
        ..args.render.clone()
    };
    super::render::run(&render)?;
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run_dir.join("report.json"))?)?;
    let (width, height) = (
        report["width"].as_u64().unwrap_or(0) as u32,
        report["height"].as_u64().unwrap_or(0) as u32,
    );
    if let Some(b) = baseline {
        // FLIP compares pixel by pixel: never a reference or frame of another size.
        if (width, height) != (b.params.width, b.params.height) {
            bail!(
                "the replay rendered {width}×{height}; the baseline {} is {}×{}",
                base_dir.display(),
                b.params.width,
                b.params.height
            );
        }
    }
    let params = params_of(args, &render, width, height);
    let reference = match &loaded {
        Some(l) => l.reference.clone(),
        None => reference_for(args, &render, width, height)?,
    };
    let ppd = pixels_per_degree(args, width)?;
    let passes: BTreeMap<String, f64> =
        serde_json::from_value(report["passes"].clone()).unwrap_or_default();
    let mut records = Vec::new();
    let mut checks = Vec::new();
    let (mut foveal, mut foveal_true) = (Vec::new(), Vec::new());
    for k in 0..frames {
        let (_, _, ldr) = fovea_stage::decode::read_rgba8(
            &run_dir.join(format!("frame_{k:04}.png")),
            MAX_PIXELS,
            Some((width, height)),
        )?;
        // The reference displayed as the frame was: its exposure (automatic exposure moves it
        // frame by frame) and its curve.
        let exposure = report["exposure"][k as usize].as_f64().unwrap_or(1.0) as f32;
        let reference_ldr = tonemap_preview(&reference, exposure, render.tone);
        let reference_flip = flip_map(&reference_ldr, &ldr, width, height, ppd);
        let g = &report["gaze"][k as usize];
        let gaze = Vec2::new(
            g[0].as_f64().unwrap_or(0.0) as f32,
            g[1].as_f64().unwrap_or(0.0) as f32,
        );
        let origin = report["gaze_origin"][k as usize]
            .as_str()
            .unwrap_or("")
            .to_string();
        match baseline {
            None => {
                let images = FrameImages {
                    width,
                    height,
                    ldr: &ldr,
                    ldr_baseline: &ldr,
                    reference_flip: &reference_flip,
                    gaze,
                    origin: &origin,
                };
                records.push(FrameRecord {
                    frame: k,
                    gaze: gaze.to_array(),
                    origin: origin.clone(),
                    quality_flip: quality_flip(&images, args.rings),
                });
                if let Some(staging) = &mut staging {
                    staging.write_frame(k, width, height, &ldr)?;
                }
            }
            Some(b) => {
                // Checked when loaded; read again, its size and SHA-256 checked again.
                let base_ldr = loaded
                    .as_ref()
                    .map(|l| l.frame(k))
                    .transpose()?
                    .unwrap_or_default();
                let images = FrameImages {
                    width,
                    height,
                    ldr: &ldr,
                    ldr_baseline: &base_ldr,
                    reference_flip: &reference_flip,
                    gaze,
                    origin: &origin,
                };
                let flip = flip_map(&base_ldr, &ldr, width, height, ppd);
                let mut check =
                    check_frame(&images, &b.frames[k as usize], &flip, &args.tolerances);
                let g = &report["gaze_true"][k as usize];
                if let (Some(x), Some(y)) = (g[0].as_f64(), g[1].as_f64()) {
                    let true_gaze = Vec2::new(x as f32, y as f32);
                    let rings = |g: Vec2| Rings::new(width, height, g, args.rings);
                    check.gaze_true = Some(true_gaze.to_array());
                    check.quality_flip_true_gaze = Some(rings(true_gaze).mean(&reference_flip));
                    foveal_true.extend(rings(true_gaze).inner_mean(&reference_flip, FOVEAL_RINGS));
                    foveal.extend(rings(gaze).inner_mean(&reference_flip, FOVEAL_RINGS));
                }
                if check.failed() {
                    write_png(
                        &run_dir.join(format!("frame_{k:04}_baseline.png")),
                        width,
                        height,
                        &base_ldr,
                    )?;
                    write_png(
                        &run_dir.join(format!("frame_{k:04}_flip.png")),
                        width,
                        height,
                        &flip_image(&flip, width, height),
                    )?;
                }
                checks.push(check);
            }
        }
    }
    if let Some(staging) = staging {
        let device = report["device"].as_str().unwrap_or("").to_string();
        let new = Baseline {
            format: FORMAT.into(),
            trace: trace.into(),
            trace_sha256: id.sha256.clone(),
            commit: current_commit(),
            device,
            params: params.clone(),
            frames: records,
            passes: passes.clone(),
            files: Vec::new(),
        };
        staging.commit(new, width, height, &reference)?;
    }
    let b = baseline;
    let mean = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
    Ok(TraceResult {
        foveal_flip: mean(&foveal),
        foveal_flip_true_gaze: mean(&foveal_true),
        trace: trace.into(),
        baseline: base_dir.display().to_string(),
        run: format!("run_{}", id.key),
        baseline_commit: b.map(|b| b.commit.clone()).unwrap_or_default(),
        baseline_device: b.map(|b| b.device.clone()).unwrap_or_default(),
        param_changes: b
            .map(|b| param_changes(&b.params, &params))
            .unwrap_or_default(),
        failed_frames: checks
            .iter()
            .filter(|c| c.failed())
            .map(|c| c.frame)
            .collect(),
        frames: checks,
        cost_ratio: b
            .map(|b| {
                passes
                    .iter()
                    .filter_map(|(k, v)| {
                        Some((k.clone(), v / b.passes.get(k).filter(|&&x| x > 0.0)?))
                    })
                    .collect()
            })
            .unwrap_or_default(),
    })
}

fn params_of(args: &ReplayArgs, r: &RenderArgs, width: u32, height: u32) -> Params {
    Params {
        scene: r.scene.to_string(),
        method: r.method.to_string(),
        denoiser: r.denoiser.to_string(),
        taa: r.taa.to_string(),
        headset: r.headset.to_string(),
        width,
        height,
        frames: r.frames,
        seed: r.seed,
        max_depth: r.max_depth,
        blur_sigma_at_30: r.profile.blur.sigma_at_30,
        reference_spp: args.reference_spp,
        rings: args.rings,
        camera: format!("{:?}", r.camera),
        environment: r.profile.environment.describe(),
        gaze_timing: fovea_stage::gaze::describe_timing(&r.profile.gaze_timing),
    }
}

fn param_changes(base: &Params, now: &Params) -> Vec<(String, String, String)> {
    let (a, b) = (
        serde_json::to_value(base).unwrap_or_default(),
        serde_json::to_value(now).unwrap_or_default(),
    );
    let (Some(a), Some(b)) = (a.as_object(), b.as_object()) else {
        return Vec::new();
    };
    a.iter()
        .filter(|(k, v)| b.get(*k) != Some(v))
        .map(|(k, v)| {
            (
                k.clone(),
                v.to_string(),
                b.get(k).map(|x| x.to_string()).unwrap_or_default(),
            )
        })
        .collect()
}

/// The converged image of the still camera (Cartesian, `--reference-spp` samples per pixel).
fn reference_for(
    args: &ReplayArgs,
    r: &RenderArgs,
    width: u32,
    height: u32,
) -> Result<Vec<[f32; 4]>> {
    let rig = fovea_stage::projection::EyeRig {
        projection: r.camera.projection,
        hmd: fovea_hal::HmdDescription::resolve(r.headset)?,
        stereo: false,
        width,
        height,
        metres_per_unit: r.camera.world_scale,
    };
    let (scene, camera) =
        fovea_stage::look::load(r.scene, r.camera, &r.profile.environment, rig.framing())?;
    let ctx = super::open_device(r.device, r.validation)?;
    let settings = RenderSettings {
        seed: r.seed.wrapping_add(0x5eed),
        ..Default::default()
    };
    let mut renderer = Renderer::new(
        &ctx,
        &scene,
        Box::new(Cartesian::new(UVec2::new(width, height))),
        settings,
    )?;
    // The replayed frames are the left eye's.
    let pose = rig.eye(&rig.head(&camera), fovea_hal::Eye::Left);
    let reference = renderer.render_reference(&pose, args.reference_spp, r.max_depth, |_| {})?;
    super::check_validation(&ctx)?;
    Ok(reference)
}

/// FLIP's viewing condition: the render stretched over the headset eye's horizontal FOV.
fn pixels_per_degree(args: &ReplayArgs, width: u32) -> Result<f32> {
    let hmd = fovea_hal::HmdDescription::resolve(args.render.headset)?;
    Ok(crate::eval::flip::headset_ppd(&hmd, width))
}

fn markdown(r: &ReplayReport) -> String {
    let mut s = format!(
        "# fovea replay: {}\n\n",
        if r.passed {
            "within tolerance"
        } else {
            "REGRESSION"
        }
    );
    for t in &r.traces {
        s += &format!(
            "## {} (baseline {} from commit {} on {})\n\n",
            t.trace, t.baseline, t.baseline_commit, t.baseline_device
        );
        for (k, was, now) in &t.param_changes {
            s += &format!("- setting `{k}`: {was} in the baseline, {now} now\n");
        }
        if t.failed_frames.is_empty() {
            s += &format!("{} frame(s), all within tolerance.\n\n", t.frames.len());
        } else {
            s += "| frame | changed rings (FLIP, RMSE) | worse rings (error now > limit) | gaze |\n|---|---|---|---|\n";
            for c in t.frames.iter().filter(|c| c.failed()) {
                let changed: Vec<String> = c
                    .change
                    .iter()
                    .filter(|x| x.changed)
                    .map(|x| {
                        format!(
                            "{}: {:.4}, {:.4}",
                            x.ring,
                            x.flip.unwrap_or(0.0),
                            x.rmse.unwrap_or(0.0)
                        )
                    })
                    .collect();
                let worse: Vec<String> = c
                    .quality
                    .iter()
                    .filter(|x| x.regressed)
                    .map(|x| {
                        format!(
                            "{}: {:.4} > {:.4}",
                            x.ring,
                            x.actual.unwrap_or(0.0),
                            x.limit.unwrap_or(0.0)
                        )
                    })
                    .collect();
                let gaze = if c.gaze_differs {
                    format!(
                        "{:?} {} (baseline {:?} {})",
                        c.gaze, c.origin, c.gaze_baseline, c.origin_baseline
                    )
                } else {
                    "same".into()
                };
                s += &format!(
                    "| {} | {} | {} | {} |\n",
                    c.frame,
                    changed.join("; "),
                    worse.join("; "),
                    gaze
                );
            }
            s += &format!("\nImages of failing frames: `{}/frame_NNNN.png` (now), `_baseline.png`, `_flip.png` (FLIP map).\n\n", t.run);
        }
        if let (Some(rendered), Some(seen)) = (t.foveal_flip, t.foveal_flip_true_gaze) {
            s += &format!(
                "Latency model: mean FLIP of the innermost two rings {rendered:.4} around the rendered gaze, {seen:.4} around the true gaze at display time.\n\n"
            );
        }
        if !t.cost_ratio.is_empty() {
            let costs: Vec<String> = t
                .cost_ratio
                .iter()
                .map(|(k, v)| format!("{k} {v:.2}×"))
                .collect();
            s += &format!(
                "Cost now / baseline (GPU ms per pass, report only): {}\n\n",
                costs.join(", ")
            );
        }
    }
    s
}

// `fovea replay`'s flags (also the command a replay sweep splits; its help is the variant's in
// `crate::cli::Command`).
#[derive(clap::Args)]
pub struct ReplayCommand {
    /// Gaze traces (files) or gaze sources (sim:SEED, center, X,Y), one baseline each.
    pub traces: Vec<String>,
    /// Baseline folder (one subfolder per trace).
    #[arg(long)]
    pub baseline: PathBuf,
    /// Write the baselines from this run instead of comparing (overwrites them).
    #[arg(long)]
    pub update_baseline: bool,
    /// Samples per pixel of the converged reference made with a new baseline.
    #[arg(long, default_value_t = 256)]
    pub reference_spp: u32,
    /// Rings of distance from the gaze for every per-ring figure.
    #[arg(long, default_value_t = 4)]
    pub rings: usize,
    /// Largest mean FLIP per ring against the baseline's frame.
    #[arg(long, default_value_t = Tolerances::default().change_flip)]
    pub change_flip: f64,
    /// Largest sRGB RMSE (0…1) per ring against the baseline's frame.
    #[arg(long, default_value_t = Tolerances::default().change_rmse)]
    pub change_rmse: f64,
    /// A ring's error against the reference may grow to baseline × (1 + this) + --quality-abs.
    #[arg(long, default_value_t = Tolerances::default().quality_rel)]
    pub quality_rel: f64,
    #[arg(long, default_value_t = Tolerances::default().quality_abs)]
    pub quality_abs: f64,
    #[command(flatten)]
    pub opts: Box<RenderOpts>,
    #[command(flatten)]
    pub device: DeviceArgs,
}

impl ReplayCommand {
    pub fn run(self) -> Result<()> {
        self.with_args(&mut run)
    }

    /// The flags as the command's arguments, handed to `run` (the command itself, or a sweep).
    pub fn with_args(self, run: &mut dyn FnMut(&ReplayArgs) -> Result<()>) -> Result<()> {
        let ReplayCommand {
            traces,
            baseline,
            update_baseline,
            reference_spp,
            rings,
            change_flip,
            change_rmse,
            quality_rel,
            quality_abs,
            opts,
            device,
        } = self;
        device.choose_traversal()?;
        let camera = opts.look.camera()?;
        let mut render = opts.args(
            &camera,
            &device,
            RenderDefaults {
                frames: DEFAULT_FRAMES,
                gaze: "center",
                out: "out/replay",
                scale: DEFAULT_SCALE,
            },
        )?;
        // Small by default: replays run in the test suite.
        render.width = Some(opts.width.unwrap_or(64));
        render.height = Some(opts.height.unwrap_or(72));
        let tolerances = Tolerances {
            change_flip,
            change_rmse,
            quality_rel,
            quality_abs,
            ..Tolerances::default()
        };
        run(&ReplayArgs {
            traces: &traces,
            baseline: &baseline,
            frames: opts.frames,
            out: render.out,
            render,
            update: update_baseline,
            reference_spp,
            rings,
            tolerances,
        })
    }
}
