//! A replay baseline, one folder per trace: `baseline.json` (what made it and, per frame, the gaze
//! used, the error against the converged reference per ring and the pass times), the frames as
//! displayed (`frame_NNNN.png`) and the reference (`reference.exr`).

use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

pub const FORMAT: &str = "fovea-replay-baseline 1";

/// The settings a baseline was made with (a replay with other settings is compared all the same:
/// that is how a changed parameter is judged; the report lists the differences).
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct Params {
    pub scene: String,
    pub method: String,
    pub denoiser: String,
    pub taa: String,
    pub headset: String,
    pub width: u32,
    pub height: u32,
    pub frames: u32,
    pub seed: u32,
    pub max_depth: u32,
    pub blur_sigma_at_30: f32,
    pub reference_spp: u32,
    pub rings: usize,
    /// The camera and environment flags as given (older baselines: empty).
    #[serde(default)]
    pub camera: String,
    #[serde(default)]
    pub environment: String,
    /// The latency model's flags (`--latency-ms`, `--tracker-hz`, `--gaze-predict`); empty
    /// without one (and in older baselines).
    #[serde(default)]
    pub gaze_timing: String,
}

#[derive(Serialize, Deserialize, Clone, Debug)]
pub struct FrameRecord {
    pub frame: u32,
    /// Gaze pixel (left eye's render pixels) and where it came from (live, held, centre).
    pub gaze: [f32; 2],
    pub origin: String,
    /// Mean FLIP against the reference (tonemapped like the frame), per ring of distance from
    /// the gaze (inner first).
    pub quality_flip: Vec<Option<f64>>,
}

#[derive(Serialize, Deserialize, Clone, Debug)]
pub struct Baseline {
    pub format: String,
    /// The trace (or gaze source) as given on the command line.
    pub trace: String,
    pub commit: String,
    pub device: String,
    pub params: Params,
    pub frames: Vec<FrameRecord>,
    /// Mean GPU ms per pass of the run.
    pub passes: BTreeMap<String, f64>,
}

impl Baseline {
    pub fn load(dir: &Path) -> Result<Baseline> {
        let path = dir.join("baseline.json");
        if !path.exists() {
            bail!(
                "no baseline at {} (make one with --update-baseline)",
                dir.display()
            );
        }
        let text = fovea_hal::file::read_text(&path, 16 << 20, "replay baseline")?;
        let baseline: Baseline = serde_json::from_str(&text)
            .with_context(|| format!("{}: not a replay baseline", path.display()))?;
        if baseline.format != FORMAT {
            bail!(
                "{}: format '{}', expected '{FORMAT}'",
                path.display(),
                baseline.format
            );
        }
        for (i, f) in baseline.frames.iter().enumerate() {
            if f.frame != i as u32 || f.quality_flip.len() != baseline.params.rings {
                bail!(
                    "{}: frames[{i}] is frame {} with {} rings; expected frame {i} with {} rings",
                    path.display(),
                    f.frame,
                    f.quality_flip.len(),
                    baseline.params.rings
                );
            }
        }
        Ok(baseline)
    }

    pub fn frame_png(dir: &Path, frame: u32) -> PathBuf {
        dir.join(format!("frame_{frame:04}.png"))
    }

    pub fn reference_exr(dir: &Path) -> PathBuf {
        dir.join("reference.exr")
    }
}

/// The folder name of a trace's baseline: its file stem, or the gaze spec with anything but
/// [A-Za-z0-9_-] replaced (`sim:1` → `sim-1`).
pub fn trace_name(trace: &str) -> String {
    let path = Path::new(trace);
    let stem = if path.extension().is_some() {
        path.file_stem().map(|s| s.to_string_lossy().into_owned())
    } else {
        None
    };
    let raw = stem.unwrap_or_else(|| trace.to_string());
    raw.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '-'
            }
        })
        .collect()
}

/// The commit of the working tree the tool runs in, if it is a git checkout.
pub fn current_commit() -> String {
    std::process::Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "unknown".into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trace_names_are_file_stems_or_sanitised_specs() {
        assert_eq!(trace_name("config/gaze/example_trace.csv"), "example_trace");
        assert_eq!(trace_name("sim:1"), "sim-1");
    }
}
