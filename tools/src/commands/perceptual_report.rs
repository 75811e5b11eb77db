//! `fovea perceptual-report`: perceived quality against cost. Reads `fovea quality` folders that
//! the offline FovVideoVDP scorer (`scripts/perceptual`) has judged (`perceptual.json` beside
//! `quality.json`) and writes one table and two plots per scene, size, gaze and camera: JOD
//! against samples per frame and against GPU time per frame, one line per method + filters over
//! the folders (e.g. one folder per sample budget) → `DIR/perceptual.md`, `DIR/jod_*.png`.

use crate::eval::plot::{line_plot, Series};
use crate::output::{prepare_output_dir, write_text};
use anyhow::{bail, Context, Result};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

pub struct PerceptualReportArgs<'a> {
    /// `fovea quality` folders, each with `perceptual.json`.
    pub folders: &'a [PathBuf],
    pub out: &'a Path,
}

#[derive(Deserialize)]
struct Perceptual {
    metric: String,
    scene: String,
    width: u32,
    height: u32,
    gaze_source: String,
    frames_per_second: f64,
    pixels_per_degree: f64,
    runs: Vec<PerceptualRun>,
}

#[derive(Deserialize)]
struct PerceptualRun {
    run_dir: String,
    jod: f64,
    #[serde(default)]
    jod_true_gaze: Option<f64>,
}

#[derive(Deserialize)]
struct Quality {
    scene: String,
    width: u32,
    height: u32,
    gaze_source: String,
    runs: Vec<QualityRun>,
}

#[derive(Deserialize)]
struct QualityRun {
    run_dir: String,
    camera: String,
    method: String,
    denoiser: String,
    taa: String,
    frame_gpu_ms: f64,
    samples_traced: u64,
    frames: Vec<u32>,
    rings: Vec<Ring>,
}

#[derive(Deserialize)]
struct Ring {
    flip: Option<f64>,
}

/// Rings averaged into the foveal FLIP of the table (as `fovea quality`'s `foveal_flip`).
const FOVEAL_RINGS: usize = 2;

/// One judged run with what the table and plots show of it.
struct Row {
    folder: String,
    method: String,
    samples: u64,
    share_of_pixels: f64,
    gpu_ms: f64,
    jod: f64,
    jod_true_gaze: Option<f64>,
    foveal_flip: Option<f64>,
    frames: usize,
}

/// Scene, size, gaze source, camera: the runs one plot compares.
type GroupKey = (String, u32, u32, String, String);

struct Group {
    pixels_per_degree: f64,
    frames_per_second: f64,
    metric: String,
    rows: Vec<Row>,
}

fn read_json<T: for<'de> Deserialize<'de>>(path: &Path) -> Result<T> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let de = &mut serde_json::Deserializer::from_str(&text);
    serde_path_to_error::deserialize(de).with_context(|| format!("{}", path.display()))
}

fn folder_rows(folder: &Path, groups: &mut BTreeMap<GroupKey, Group>) -> Result<()> {
    let quality_path = folder.join("quality.json");
    let perceptual_path = folder.join("perceptual.json");
    if !perceptual_path.exists() {
        bail!(
            "{}: no perceptual.json (score the folder first: scripts/perceptual {})",
            folder.display(),
            folder.display()
        );
    }
    let quality: Quality = read_json(&quality_path)?;
    let perceptual: Perceptual = read_json(&perceptual_path)?;
    if (
        &quality.scene,
        quality.width,
        quality.height,
        &quality.gaze_source,
    ) != (
        &perceptual.scene,
        perceptual.width,
        perceptual.height,
        &perceptual.gaze_source,
    ) {
        bail!(
            "{}: scores another quality run than quality.json (scene, size or gaze differ); score it again",
            perceptual_path.display()
        );
    }
    let name = folder
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| folder.display().to_string());
    let pixels = f64::from(quality.width) * f64::from(quality.height);
    for scored in &perceptual.runs {
        let Some(run) = quality.runs.iter().find(|r| r.run_dir == scored.run_dir) else {
            bail!(
                "{}: run {} is not in quality.json; score the folder again",
                perceptual_path.display(),
                scored.run_dir
            );
        };
        let inner: Vec<f64> = run
            .rings
            .iter()
            .take(FOVEAL_RINGS)
            .filter_map(|r| r.flip)
            .collect();
        let key = (
            quality.scene.clone(),
            quality.width,
            quality.height,
            quality.gaze_source.clone(),
            run.camera.clone(),
        );
        let group = groups.entry(key).or_insert_with(|| Group {
            pixels_per_degree: perceptual.pixels_per_degree,
            frames_per_second: perceptual.frames_per_second,
            metric: perceptual.metric.clone(),
            rows: Vec::new(),
        });
        group.rows.push(Row {
            folder: name.clone(),
            method: format!("{} + {}, taa {}", run.method, run.denoiser, run.taa),
            samples: run.samples_traced,
            share_of_pixels: run.samples_traced as f64 / pixels,
            gpu_ms: run.frame_gpu_ms,
            jod: scored.jod,
            jod_true_gaze: scored.jod_true_gaze,
            foveal_flip: (inner.len() == FOVEAL_RINGS)
                .then(|| inner.iter().sum::<f64>() / inner.len() as f64),
            frames: run.frames.len(),
        });
    }
    if perceptual.runs.len() != quality.runs.len() {
        bail!(
            "{}: {} runs scored of quality.json's {}; score the folder again",
            perceptual_path.display(),
            perceptual.runs.len(),
            quality.runs.len()
        );
    }
    Ok(())
}

/// A file-name-safe form of a group's key.
fn slug(key: &GroupKey) -> String {
    let scene = Path::new(&key.0)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let gaze = Path::new(&key.3)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    format!("{scene}_{}x{}_{gaze}_{}", key.1, key.2, key.4)
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c.to_ascii_lowercase()
            } else {
                '-'
            }
        })
        .collect()
}

/// One line per method + filters, its points in the order of cost.
fn series(rows: &[Row], cost: impl Fn(&Row) -> f64) -> Vec<Series> {
    let mut lines: BTreeMap<&str, Vec<(f64, f64)>> = BTreeMap::new();
    for row in rows {
        lines
            .entry(&row.method)
            .or_default()
            .push((cost(row), row.jod));
    }
    lines
        .into_iter()
        .map(|(label, mut points)| {
            points.sort_by(|a, b| a.0.total_cmp(&b.0));
            Series {
                label: label.to_string(),
                points,
            }
        })
        .collect()
}

pub fn run(args: &PerceptualReportArgs) -> Result<()> {
    if args.folders.is_empty() {
        bail!("give at least one `fovea quality` folder scored by scripts/perceptual");
    }
    let mut groups = BTreeMap::new();
    for folder in args.folders {
        folder_rows(folder, &mut groups)?;
    }
    let _out = prepare_output_dir(args.out)?;
    let mut md = String::new();
    for (key, group) in &mut groups {
        group
            .rows
            .sort_by(|a, b| a.method.cmp(&b.method).then(a.samples.cmp(&b.samples)));
        let (scene, width, height, gaze, camera) = key;
        let slug = slug(key);
        let _ = writeln!(
            md,
            "### {scene}, {width}×{height} ({:.1} px/° at the centre), gaze {gaze}, {camera} camera\n",
            group.pixels_per_degree
        );
        let _ = writeln!(
            md,
            "{} (foveated on each frame's gaze), {:.0} frames/s. GPU ms: the runs' mean frame, per-pass timestamps on the device that rendered them.\n",
            group.metric, group.frames_per_second
        );
        let true_gaze = group.rows.iter().any(|r| r.jod_true_gaze.is_some());
        let _ = writeln!(
            md,
            "| folder | method + filters | samples / frame | of the pixels | GPU ms / frame | frames judged | JOD |{} foveal FLIP |",
            if true_gaze { " JOD at the true gaze |" } else { "" }
        );
        let _ = writeln!(
            md,
            "|---|---|---|---|---|---|---|{}---|",
            if true_gaze { "---|" } else { "" }
        );
        for r in &group.rows {
            let _ = write!(
                md,
                "| {} | {} | {} | {:.3} | {:.1} | {} | {:.3} |",
                r.folder, r.method, r.samples, r.share_of_pixels, r.gpu_ms, r.frames, r.jod
            );
            if true_gaze {
                let _ = write!(
                    md,
                    " {} |",
                    r.jod_true_gaze.map_or("—".into(), |j| format!("{j:.3}"))
                );
            }
            let _ = writeln!(
                md,
                " {} |",
                r.foveal_flip.map_or("—".into(), |f| format!("{f:.4}"))
            );
        }
        let title = format!("{scene}, {width}×{height}, {camera}");
        let samples_png = format!("jod_samples_{slug}.png");
        let gpu_png = format!("jod_gpu_ms_{slug}.png");
        line_plot(
            &args.out.join(&samples_png),
            &title,
            "samples per frame",
            "JOD (10 = as the reference)",
            &series(&group.rows, |r| r.samples as f64),
            false,
        )?;
        line_plot(
            &args.out.join(&gpu_png),
            &title,
            "GPU ms per frame",
            "JOD (10 = as the reference)",
            &series(&group.rows, |r| r.gpu_ms),
            false,
        )?;
        let _ = writeln!(
            md,
            "\n![JOD against samples]({samples_png}) ![JOD against GPU time]({gpu_png})\n"
        );
    }
    write_text(&args.out.join("perceptual.md"), &md)?;
    print!("{md}");
    Ok(())
}

// `fovea perceptual-report` (its help is the variant's in `crate::cli::Command`).
#[derive(clap::Args)]
pub struct PerceptualReportCommand {
    /// `fovea quality` folders, each with the perceptual.json of scripts/perceptual.
    #[arg(required = true)]
    pub folders: Vec<PathBuf>,
    #[arg(long, default_value = "out/perceptual")]
    pub out: PathBuf,
}

impl PerceptualReportCommand {
    pub fn run(self) -> Result<()> {
        run(&PerceptualReportArgs {
            folders: &self.folders,
            out: &self.out,
        })
    }
}
