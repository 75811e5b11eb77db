//! `fovea gaze-eval TRACE… [--headset NAME] [--latency-ms L] [--tracker-hz R] [--display-hz F]
//! [--gaze-predict MODE] [--out DIR]`: no rendering. Each recording is played through the latency
//! model at the tracker rate and each predictor; every frame of the display rate is compared with
//! where the eye is at its display time (the recording itself): median, p95, p99, the share of
//! frames above 2.5° and 5°, the median over fixations, and per saccade the landing error →
//! `DIR/gaze_eval.json`, `DIR/gaze_eval.md` and the same table on stdout.

use crate::output::{prepare_output_dir, write_json, write_text};
use anyhow::{bail, Context, Result};
use fovea_hal::gaze_eval::{evaluate, EvalResult, EvalSettings, FloorResult};
use fovea_hal::predict::PredictorParams;
use fovea_hal::{GazeSpec, HmdDescription, LatencyModel, PredictMode};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

pub struct GazeEvalArgs<'a> {
    pub traces: &'a [String],
    pub headset: &'a str,
    pub latency_ms: Option<f64>,
    pub tracker_hz: Option<f64>,
    /// `None`: the headset's refresh rate.
    pub display_hz: Option<f64>,
    /// Empty: every predictor.
    pub predict: &'a [String],
    pub out: &'a Path,
}

#[derive(Serialize)]
struct SaccadeRow {
    onset_s: f64,
    end_s: f64,
    /// Degrees.
    amplitude: f64,
    /// Degrees: the first frame after the landing that a tracker sample of the saccade can have
    /// reached (displayed at least latency + two tracker periods after the onset).
    landing_error: f64,
    /// Frames from the onset to the end + latency + three tracker periods with error > 2.5°.
    frames_above_2_5: usize,
}

#[derive(Serialize)]
struct PredictorRow {
    gaze_predict: &'static str,
    frames: usize,
    evaluated_frames: usize,
    /// Degrees between the gaze a frame used and the eye at its display time.
    median: f64,
    p95: f64,
    p99: f64,
    share_above_2_5: f64,
    share_above_5: f64,
    /// Frames whose tracker samples and display time lie in one fixation, and their median.
    fixation_frames: usize,
    fixation_median: f64,
    /// Against `off` (holding the newest sample) on the same trace.
    share_above_2_5_vs_off: Option<f64>,
    p99_vs_off: Option<f64>,
    fixation_median_minus_off: Option<f64>,
    /// Median of the per-saccade landing errors.
    landing_error_median: Option<f64>,
    saccades: Vec<SaccadeRow>,
    saccades_near_blinks: usize,
    held_frames: usize,
    centre_frames: usize,
    outside_view_frames: usize,
}

#[derive(Serialize)]
struct Floor {
    median: f64,
    p95: f64,
    p99: f64,
    share_above_2_5: f64,
    share_above_5: f64,
}

#[derive(Serialize)]
struct TraceRow {
    trace: String,
    samples: usize,
    duration_s: f64,
    rate_hz: f32,
    /// What latency alone costs: a predictor that knows where the eye is except what no tracker
    /// sample can have shown yet (a saccade before a sample 1° along it, plus the latency; the
    /// eye during samples without gaze).
    causal_floor: Floor,
    predictors: Vec<PredictorRow>,
}

#[derive(Serialize)]
struct Report {
    headset: String,
    latency_ms: f64,
    /// How the latency is made up.
    latency: String,
    tracker_hz: f64,
    display_hz: f64,
    /// `--gaze-predict`'s default.
    default_gaze_predict: &'static str,
    traces: Vec<TraceRow>,
}

fn floor(f: &FloorResult) -> Floor {
    Floor {
        median: f.median_deg,
        p95: f.p95_deg,
        p99: f.p99_deg,
        share_above_2_5: f.share_above_2_5,
        share_above_5: f.share_above_5,
    }
}

fn predictor_row(mode: PredictMode, r: &EvalResult, off: Option<&EvalResult>) -> PredictorRow {
    let ratio = |a: f64, b: f64| (b > 0.0).then(|| a / b);
    let mut landing: Vec<f64> = r.saccades.iter().map(|s| s.landing_error_deg).collect();
    landing.sort_by(f64::total_cmp);
    PredictorRow {
        gaze_predict: mode.name(),
        frames: r.frames,
        evaluated_frames: r.evaluated,
        median: r.median_deg,
        p95: r.p95_deg,
        p99: r.p99_deg,
        share_above_2_5: r.share_above_2_5,
        share_above_5: r.share_above_5,
        fixation_frames: r.fixation_frames,
        fixation_median: r.fixation_median_deg,
        share_above_2_5_vs_off: off.and_then(|o| ratio(r.share_above_2_5, o.share_above_2_5)),
        p99_vs_off: off.and_then(|o| ratio(r.p99_deg, o.p99_deg)),
        fixation_median_minus_off: off.map(|o| r.fixation_median_deg - o.fixation_median_deg),
        landing_error_median: (!landing.is_empty())
            .then(|| fovea_hal::gaze_eval::quantile(&landing, 0.5)),
        saccades: r
            .saccades
            .iter()
            .map(|s| SaccadeRow {
                onset_s: s.saccade.onset_s,
                end_s: s.saccade.end_s,
                amplitude: s.saccade.amplitude_deg,
                landing_error: s.landing_error_deg,
                frames_above_2_5: s.frames_above_2_5,
            })
            .collect(),
        saccades_near_blinks: r.saccades_near_blinks,
        held_frames: r.held_frames,
        centre_frames: r.centre_frames,
        outside_view_frames: r.outside_view_frames,
    }
}

/// `--gaze-predict` values (empty: all of them).
pub fn parse_modes(names: &[String]) -> Result<Vec<PredictMode>> {
    if names.is_empty() {
        return Ok(PredictMode::ALL.to_vec());
    }
    let mut modes = Vec::new();
    for name in names {
        let mode = PredictMode::parse(name)?;
        if !modes.contains(&mode) {
            modes.push(mode);
        }
    }
    Ok(modes)
}

pub fn run(args: &GazeEvalArgs) -> Result<()> {
    if args.traces.is_empty() {
        bail!("fovea gaze-eval needs at least one recording (a degrees CSV, a fovea gaze trace, degrees:FILE or gazebase:FILE)");
    }
    let hmd = HmdDescription::resolve(args.headset)
        .with_context(|| format!("--headset {}", args.headset))?;
    let model = LatencyModel::for_headset(&hmd, args.latency_ms, args.tracker_hz)?;
    let display_hz = args.display_hz.unwrap_or(hmd.refresh_hz as f64);
    if !(display_hz >= fovea_hal::hmd::MIN_RATE_HZ as f64 && display_hz <= 1000.0) {
        bail!("--display-hz {display_hz}: expected a rate in Hz, >= 1 and <= 1000");
    }
    let modes = parse_modes(args.predict)?;
    // Every recording loads before anything is written.
    let recordings = args
        .traces
        .iter()
        .map(|t| {
            let spec: GazeSpec = t.parse()?;
            let trace = spec
                .recording(&hmd)
                .with_context(|| format!("recording {t}"))?;
            Ok((t.clone(), trace))
        })
        .collect::<Result<Vec<_>>>()?;
    let _out = prepare_output_dir(args.out)?;
    let mut traces = Vec::new();
    for (name, trace) in &recordings {
        let mut results: Vec<(PredictMode, EvalResult)> = Vec::new();
        // `off` always runs: the others are compared with it.
        let with_off = std::iter::once(PredictMode::Off).chain(modes.iter().copied());
        for mode in with_off {
            if results.iter().any(|r| r.0 == mode) {
                continue;
            }
            let settings = EvalSettings {
                model: model.clone(),
                display_hz,
                mode,
                params: PredictorParams::default(),
            };
            let r =
                evaluate(trace, &hmd, &settings).with_context(|| format!("recording {name}"))?;
            results.push((mode, r));
        }
        let off = results
            .iter()
            .find(|r| r.0 == PredictMode::Off)
            .map(|r| r.1.clone());
        let samples = &trace.samples;
        traces.push(TraceRow {
            trace: name.clone(),
            samples: samples.len(),
            duration_s: (samples[samples.len() - 1].time - samples[0].time) as f64 * 1e-9,
            rate_hz: trace.header.rate_hz,
            causal_floor: floor(&results[0].1.floor),
            predictors: results
                .iter()
                .filter(|(mode, _)| modes.contains(mode))
                .map(|(mode, r)| predictor_row(*mode, r, off.as_ref()))
                .collect(),
        });
    }
    let report = Report {
        headset: hmd.id.clone(),
        latency_ms: model.total_ms(),
        latency: model.describe(),
        tracker_hz: model.tracker_hz,
        display_hz,
        default_gaze_predict: PredictMode::DEFAULT.name(),
        traces,
    };
    write_json(&args.out.join("gaze_eval.json"), &report)?;
    let table = markdown(&report);
    write_text(&args.out.join("gaze_eval.md"), &table)?;
    print!("{table}");
    Ok(())
}

fn markdown(r: &Report) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Gaze error at display time: headset {}, latency {}, display {} Hz. Degrees between the \
         gaze each frame used and the eye when it was shown.\n",
        r.headset, r.latency, r.display_hz
    );
    let _ = writeln!(
        s,
        "| recording | predictor | median | p95 | p99 | > 2.5° | > 5° | fixation median | > 2.5° vs off | p99 vs off | landing error (median, saccades) |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|");
    let ratio = |v: Option<f64>| v.map_or("–".to_string(), |v| format!("{v:.2}×"));
    for t in &r.traces {
        let name = Path::new(&t.trace)
            .file_name()
            .map_or(t.trace.clone(), |n| n.to_string_lossy().into_owned());
        for p in &t.predictors {
            let _ = writeln!(
                s,
                "| {name} | {} | {:.3} | {:.2} | {:.2} | {:.2} % | {:.2} % | {:.3} | {} | {} | {} |",
                p.gaze_predict,
                p.median,
                p.p95,
                p.p99,
                100.0 * p.share_above_2_5,
                100.0 * p.share_above_5,
                p.fixation_median,
                ratio(p.share_above_2_5_vs_off),
                ratio(p.p99_vs_off),
                p.landing_error_median
                    .map_or("–".to_string(), |m| format!("{m:.2}, {}", p.saccades.len())),
            );
        }
        let f = &t.causal_floor;
        let _ = writeln!(
            s,
            "| {name} | causal floor | {:.3} | {:.2} | {:.2} | {:.2} % | {:.2} % | | | | |",
            f.median,
            f.p95,
            f.p99,
            100.0 * f.share_above_2_5,
            100.0 * f.share_above_5
        );
    }
    s
}

// `fovea gaze-eval` (its help is the variant's in `crate::cli::Command`).
#[derive(clap::Args)]
pub struct GazeEvalCommand {
    /// Recordings: degrees CSVs (t_s,x_deg,y_deg,valid), fovea gaze traces, degrees:FILE or
    /// gazebase:FILE.
    #[arg(required = true)]
    pub traces: Vec<String>,
    /// Headset profile (its left eye's view, tracker and latency).
    #[arg(long, default_value = "fove0")]
    pub headset: String,
    /// Sample-to-photon latency in ms (default: the profile's tracker + render + display).
    #[arg(long, allow_hyphen_values = true)]
    pub latency_ms: Option<f64>,
    /// Tracker rate in Hz (default: the profile's).
    #[arg(long, allow_hyphen_values = true)]
    pub tracker_hz: Option<f64>,
    /// Display rate in Hz (default: the profile's refresh).
    #[arg(long, allow_hyphen_values = true)]
    pub display_hz: Option<f64>,
    /// Predictors, comma-separated: off, hold, linear, saccade (default: all).
    #[arg(long, value_delimiter = ',')]
    pub gaze_predict: Vec<String>,
    #[arg(long, default_value = "out/gaze-eval")]
    pub out: PathBuf,
}

impl GazeEvalCommand {
    pub fn run(self) -> Result<()> {
        run(&GazeEvalArgs {
            traces: &self.traces,
            headset: &self.headset,
            latency_ms: self.latency_ms,
            tracker_hz: self.tracker_hz,
            display_hz: self.display_hz,
            predict: &self.gaze_predict,
            out: &self.out,
        })
    }
}
