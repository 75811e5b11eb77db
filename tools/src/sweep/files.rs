//! What a sweep folder holds, as types: `sweep.json`, the lines of `jobs.jsonl`, a finished job's
//! record and a failed one's, and the names of the files inside a job's folder.

use crate::commands::quality::QualityArgs;
use crate::commands::reference::ReferenceArgs;
use crate::commands::replay::ReplayArgs;
use crate::commands::setup::{eye_name, Eyes};
use anyhow::Result;
use fovea_hal::Eye;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// A one-process command parsed by the binary's command line (the parser lives in the binary).
pub enum Study<'a> {
    Quality(&'a QualityArgs<'a>),
    Reference(&'a ReferenceArgs<'a>),
    Replay(&'a ReplayArgs<'a>),
}

/// Parses `fovea ARGS…` and hands the command to the callback; errors for any other command.
pub type Parse<'p> = &'p dyn Fn(&[String], &mut dyn FnMut(Study<'_>) -> Result<()>) -> Result<()>;

/// `sweep.json` `format`.
pub const FORMAT: u32 = 1;
pub const SWEEP_FILE: &str = "sweep.json";
pub const JOBS_FILE: &str = "jobs.jsonl";
/// A job's finished output inside its folder, and the record in it.
pub const RESULT: &str = "result";
pub const RECORD: &str = "job.json";
pub const FAILURE: &str = "failed.json";
pub const LOCK: &str = ".lock";
/// Attempts in progress (or killed): `.attempt-<host>-<pid>` inside the job's folder.
pub const ATTEMPT_PREFIX: &str = ".attempt-";

/// The commit this fovea was built from (tools/build.rs).
pub fn commit() -> &'static str {
    option_env!("FOVEA_COMMIT").unwrap_or("unknown")
}

#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SweepFile {
    pub format: u32,
    /// The one-process command split, as given to `fovea sweep plan` (after `fovea`).
    pub command: Vec<String>,
    pub axes: Axes,
    /// Reference batches per reference job (a power of two).
    pub batches_per_job: u32,
    /// Samples per reference batch (`reference_sum::BATCH_SPP` of the planning fovea).
    pub reference_batch_spp: u32,
    /// The commit of the fovea that planned the sweep: every job must run the same build.
    pub commit: String,
    pub fovea_version: String,
    /// Where the command's relative paths resolve from (the planning folder).
    pub workdir: PathBuf,
    pub device: DeviceRequirement,
    /// Stages in the order they must run; a job needs only jobs of earlier stages.
    pub stages: Vec<String>,
    pub studies: Vec<StudyEntry>,
    /// Lines of `jobs.jsonl`.
    pub jobs: u32,
}

/// Values that make one study each (empty: the command's own value).
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Default)]
#[serde(deny_unknown_fields)]
pub struct Axes {
    pub scenes: Vec<String>,
    pub headsets: Vec<String>,
    pub gazes: Vec<String>,
}

#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DeviceRequirement {
    /// `--device` of the command (null: each node's best device).
    pub selector: Option<String>,
    /// Every job must run on a device of this name for the merge to equal one process's output
    /// (bit for bit); `fovea sweep merge` checks the name each job recorded.
    pub one_device_for_all_jobs: bool,
}

/// One one-process command of the sweep and where its merged output goes.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct StudyEntry {
    pub name: String,
    /// The one-process command (after `fovea`); its `--out` names the merged output inside the
    /// sweep folder.
    pub args: Vec<String>,
    /// The merged output folder, relative to the sweep folder.
    pub merged: String,
}

#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Job {
    pub index: u32,
    pub stage: String,
    pub name: String,
    /// Index into `sweep.json` `studies`.
    pub study: u32,
    /// The one-process `fovea` command whose piece the job computes (a quality job's restricted
    /// to its camera and combination): run alone it computes the same piece and more.
    pub args: Vec<String>,
    pub part: Part,
    /// The job's folder, relative to the sweep folder.
    pub out: String,
    /// Jobs whose results this one reads.
    pub after: Vec<u32>,
}

#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Part {
    /// Batches `batches[0]..batches[1]` of a reference: of the camera's pose at `frame` for a
    /// quality study (and of `eye`, `left` or `right`, in a stereo one: `--eyes both`), of the one
    /// reference for a reference study.
    Reference {
        camera: Option<String>,
        frame: Option<u32>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        eye: Option<String>,
        batches: [u32; 2],
    },
    /// One combination of a quality study: rendered, measured against its references. `noise`:
    /// its `--stereo-noise`, where the command gives that flag.
    Run {
        camera: String,
        method: String,
        denoiser: String,
        taa: String,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        noise: Option<String>,
    },
    /// One trace of a replay study: rendered and checked against its baseline.
    Trace { trace: String },
}

/// How a quality study's reference parts name `eye`: by name in a stereo study (`--eyes both`),
/// not at all in a one-eye study.
pub(super) fn eye_key(q: &QualityArgs, eye: Eye) -> Option<String> {
    (q.eyes == Eyes::Both).then(|| eye_name(eye).to_string())
}

/// What a finished job recorded (`result/job.json`).
#[derive(Serialize, Deserialize, Clone, Debug)]
#[serde(deny_unknown_fields)]
pub struct JobRecord {
    pub index: u32,
    pub name: String,
    pub commit: String,
    /// The Vulkan device it rendered on (null when it rendered nothing: a refused combination).
    pub device: Option<String>,
    pub host: String,
    pub seconds: f64,
}

/// Why the last attempt of a job failed (`failed.json`).
#[derive(Serialize, Deserialize, Clone, Debug)]
pub struct Failure {
    pub index: u32,
    pub reason: String,
    pub exit_code: u8,
    pub host: String,
    pub pid: u32,
}

/// The machine's name for records and messages.
pub fn host_name() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|h| h.trim().to_string())
        .ok()
        .filter(|h| !h.is_empty())
        .or_else(|| std::env::var("HOSTNAME").ok())
        .unwrap_or_else(|| "unknown-host".into())
}
