//! `fovea sweep`: a `fovea quality` or `fovea reference` run split into independent jobs that a
//! batch scheduler (Slurm job arrays, `scripts/sweep-slurm`) or a shell loop runs, and merged into
//! the files the one-process command writes.
//!
//! A sweep folder holds:
//! - `sweep.json`: the command split, the axes, the commit of the fovea that planned it, the
//!   working folder its relative paths resolve from, the device requirement, the studies (one
//!   one-process command each) and the job count;
//! - `jobs.jsonl`: one job per line (index, stage, the `fovea` arguments whose piece it computes,
//!   which piece, its folder, the jobs it needs). It is derived from `sweep.json`, and every
//!   command checks it line by line against the plan;
//! - `jobs/NNNN/`: what each job writes (`result/` appears whole, by a rename, or not at all;
//!   `failed.json` says why the last attempt failed);
//! - `merged/<study>/`: the one-process command's files, written by `fovea sweep merge`.

mod job;
mod merge;
mod plan;
mod status;

pub use job::run;
pub use merge::merge;
pub use plan::{plan, PlanArgs};
pub use status::{list, status, ListArgs};

use crate::commands::quality::QualityArgs;
use crate::commands::reference::ReferenceArgs;
use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A one-process command parsed by the binary's command line (the parser lives in the binary).
pub enum Study<'a> {
    Quality(&'a QualityArgs<'a>),
    Reference(&'a ReferenceArgs<'a>),
}

/// Parses `fovea ARGS…` and hands the command to the callback; errors for any other command.
pub type Parse<'p> = &'p dyn Fn(&[String], &mut dyn FnMut(Study<'_>) -> Result<()>) -> Result<()>;

/// `sweep.json` `format`.
pub const FORMAT: u32 = 1;
pub const SWEEP_FILE: &str = "sweep.json";
pub const JOBS_FILE: &str = "jobs.jsonl";
/// A job's finished output inside its folder, and the record in it.
const RESULT: &str = "result";
const RECORD: &str = "job.json";
const FAILURE: &str = "failed.json";
const LOCK: &str = ".lock";
/// Attempts in progress (or killed): `.attempt-<host>-<pid>` inside the job's folder.
const ATTEMPT_PREFIX: &str = ".attempt-";

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
    /// The one-process `fovea` command restricted to this job's camera (and combination): run
    /// alone it computes the same piece and more.
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
    /// quality study, of the one reference for a reference study.
    Reference {
        camera: Option<String>,
        frame: Option<u32>,
        batches: [u32; 2],
    },
    /// One combination of a quality study: rendered, measured against its references.
    Run {
        camera: String,
        method: String,
        denoiser: String,
        taa: String,
    },
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

/// A sweep folder read and checked: the plan, the jobs as `sweep.json` plans them, and the
/// folder as an absolute path.
pub struct Sweep {
    pub dir: PathBuf,
    pub file: SweepFile,
    pub jobs: Vec<Job>,
}

impl Sweep {
    /// Reads `DIR/sweep.json` and `DIR/jobs.jsonl`, moves to the plan's working folder, and checks
    /// the jobs file line by line against the jobs the plan makes. With `same_commit`, a fovea
    /// built from another commit is refused.
    pub fn open(dir: &Path, parse: Parse, same_commit: bool) -> Result<Sweep> {
        if !dir.is_dir() {
            bail!(
                "sweep folder {} does not exist (make one with `fovea sweep plan --out {}`)",
                dir.display(),
                dir.display()
            );
        }
        let dir =
            std::fs::canonicalize(dir).with_context(|| format!("resolving {}", dir.display()))?;
        let sweep_path = dir.join(SWEEP_FILE);
        let text = std::fs::read_to_string(&sweep_path).with_context(|| {
            format!(
                "reading {} (is {} a folder written by `fovea sweep plan`?)",
                sweep_path.display(),
                dir.display()
            )
        })?;
        let file: SweepFile = serde_json::from_str(&text)
            .with_context(|| format!("{}: not a sweep plan", sweep_path.display()))?;
        if file.format != FORMAT {
            bail!(
                "{}: field `format` is {}, this fovea reads format {FORMAT}",
                sweep_path.display(),
                file.format
            );
        }
        if same_commit && file.commit != commit() {
            bail!(
                "{}: field `commit` is {} but this fovea was built from {}: results of two builds \
                 do not merge (run the jobs with the fovea built from {}, or plan again)",
                sweep_path.display(),
                file.commit,
                commit(),
                file.commit
            );
        }
        if file.reference_batch_spp != crate::reference_sum::BATCH_SPP {
            bail!(
                "{}: field `reference_batch_spp` is {}, this fovea sums references in batches of {}",
                sweep_path.display(),
                file.reference_batch_spp,
                crate::reference_sum::BATCH_SPP
            );
        }
        if !file.workdir.is_dir() {
            bail!(
                "{}: field `workdir`: {} is not a folder here; the command's relative paths resolve \
                 from it (plan from a folder every node sees, or give absolute paths)",
                sweep_path.display(),
                file.workdir.display()
            );
        }
        std::env::set_current_dir(&file.workdir)
            .with_context(|| format!("{}: field `workdir`", sweep_path.display()))?;
        let studies = plan::studies(&file.command, &file.axes)
            .with_context(|| format!("{}: field `command`", sweep_path.display()))?;
        if studies != file.studies {
            bail!(
                "{}: field `studies` is not what its `command` and `axes` make; the file was edited \
                 (plan again)",
                sweep_path.display()
            );
        }
        let (stages, jobs) = plan::jobs(&file.studies, file.batches_per_job, parse)
            .with_context(|| format!("{}: the plan's commands", sweep_path.display()))?;
        if stages != file.stages {
            bail!(
                "{}: field `stages` is {:?}, the plan makes {:?}; the file was edited (plan again)",
                sweep_path.display(),
                file.stages,
                stages
            );
        }
        if jobs.len() as u32 != file.jobs {
            bail!(
                "{}: field `jobs` is {}, the plan makes {}; the file was edited (plan again)",
                sweep_path.display(),
                file.jobs,
                jobs.len()
            );
        }
        check_jobs_file(&dir.join(JOBS_FILE), &jobs)?;
        Ok(Sweep { dir, file, jobs })
    }

    pub fn job_dir(&self, job: &Job) -> PathBuf {
        self.dir.join(&job.out)
    }

    pub fn result_dir(&self, job: &Job) -> PathBuf {
        self.job_dir(job).join(RESULT)
    }
}

/// Each line of the jobs file must be the job the plan makes: the first difference is named by
/// line and field.
fn check_jobs_file(path: &Path, jobs: &[Job]) -> Result<()> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let lines: Vec<&str> = text.lines().collect();
    for (i, (line, job)) in lines.iter().zip(jobs).enumerate() {
        let found: serde_json::Value = serde_json::from_str(line)
            .with_context(|| format!("{} line {}: not JSON", path.display(), i + 1))?;
        let planned = serde_json::to_value(job)?;
        if found == planned {
            continue;
        }
        let (Some(found_fields), Some(planned_fields)) = (found.as_object(), planned.as_object())
        else {
            bail!("{} line {}: not a job object", path.display(), i + 1);
        };
        let field = planned_fields
            .iter()
            .find(|(k, v)| found_fields.get(*k) != Some(v))
            .map(|(k, _)| k.clone())
            .or_else(|| {
                found_fields
                    .keys()
                    .find(|k| !planned_fields.contains_key(*k))
                    .cloned()
            })
            .unwrap_or_default();
        bail!(
            "{} line {} (job {}): field `{field}` is {}, the plan in {SWEEP_FILE} makes {}; the jobs \
             file was edited (plan again)",
            path.display(),
            i + 1,
            job.index,
            found_fields
                .get(&field)
                .map_or("missing".to_string(), |v| v.to_string()),
            planned_fields
                .get(&field)
                .map_or("no such field".to_string(), |v| v.to_string())
        );
    }
    if lines.len() != jobs.len() {
        bail!(
            "{}: {} lines, the plan in {SWEEP_FILE} makes {} jobs; the jobs file was edited (plan \
             again)",
            path.display(),
            lines.len(),
            jobs.len()
        );
    }
    Ok(())
}

/// The machine's name for records and messages.
fn host_name() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|h| h.trim().to_string())
        .ok()
        .filter(|h| !h.is_empty())
        .or_else(|| std::env::var("HOSTNAME").ok())
        .unwrap_or_else(|| "unknown-host".into())
}

#[cfg(test)]
#[path = "tests.rs"]
mod tests;
