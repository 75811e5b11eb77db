//! A sweep folder opened: its plan read and checked against the jobs it makes, the jobs file line
//! by line, and the working folder entered.

use super::files::{commit, Job, Parse, SweepFile, FORMAT, JOBS_FILE, RESULT, SWEEP_FILE};
use super::plan;
use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};

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

/// Each line of the jobs file must be the job the plan makes: a difference is named by line and
/// field (the first in alphabetical order).
pub(super) fn check_jobs_file(path: &Path, jobs: &[Job]) -> Result<()> {
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
