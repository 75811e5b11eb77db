//! `fovea sweep status` (each job done, running, failed or missing, with the reason) and
//! `fovea sweep list` (job indices for a shell loop, GNU parallel or Slurm arrays).

use super::files::{commit, Failure, Job, JobRecord, Parse, ATTEMPT_PREFIX, FAILURE, LOCK, RECORD};
use super::open::Sweep;
use anyhow::{bail, Context, Result};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

pub enum State {
    Done(JobRecord),
    /// Its lock is held (what the lock file says of the holder).
    Running(String),
    Failed(Failure),
    /// Never run, or stopped without a word (a killed process leaves its attempt folder).
    Missing(Option<String>),
}

impl State {
    pub fn name(&self) -> &'static str {
        match self {
            State::Done(_) => "done",
            State::Running(_) => "running",
            State::Failed(_) => "failed",
            State::Missing(_) => "missing",
        }
    }

    pub fn reason(&self) -> Option<String> {
        match self {
            State::Done(_) | State::Missing(None) => None,
            State::Running(holder) => Some(holder.clone()),
            State::Failed(f) => Some(format!(
                "{} (exit status {}, pid {} on {})",
                f.reason, f.exit_code, f.pid, f.host
            )),
            State::Missing(Some(why)) => Some(why.clone()),
        }
    }

    /// "failed: why" for messages.
    pub fn describe(&self) -> String {
        match self.reason() {
            Some(r) => format!("{}: {r}", self.name()),
            None => self.name().to_string(),
        }
    }
}

/// The job's record when its result is in place; an error when a result folder is there but
/// unreadable or not this plan's (it is never overwritten: the user removes it).
pub(super) fn done(sweep: &Sweep, job: &Job) -> Result<Option<JobRecord>> {
    let result = sweep.result_dir(job);
    if !result.exists() {
        return Ok(None);
    }
    let path = result.join(RECORD);
    let remove = || format!("remove {} to run the job again", result.display());
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("{}: unreadable; {}", path.display(), remove()))?;
    let record: JobRecord = serde_json::from_str(&text)
        .with_context(|| format!("{}: not a job record; {}", path.display(), remove()))?;
    if record.index != job.index {
        bail!(
            "{}: field `index` is {}, the folder is job {}'s; {}",
            path.display(),
            record.index,
            job.index,
            remove()
        );
    }
    if record.commit != sweep.file.commit {
        bail!(
            "{}: field `commit` is {}, the plan's is {}; {}",
            path.display(),
            record.commit,
            sweep.file.commit,
            remove()
        );
    }
    Ok(Some(record))
}

pub(super) fn state(sweep: &Sweep, job: &Job) -> Result<State> {
    if let Some(record) = done(sweep, job)? {
        return Ok(State::Done(record));
    }
    let job_dir = sweep.job_dir(job);
    if !job_dir.exists() {
        return Ok(State::Missing(None));
    }
    if let Some(holder) = lock_holder(&job_dir)? {
        return Ok(State::Running(holder));
    }
    let failure = job_dir.join(FAILURE);
    if failure.exists() {
        let text = std::fs::read_to_string(&failure)
            .with_context(|| format!("reading {}", failure.display()))?;
        let f: Failure = serde_json::from_str(&text)
            .with_context(|| format!("{}: not a failure record", failure.display()))?;
        return Ok(State::Failed(f));
    }
    let dead: Vec<String> = std::fs::read_dir(&job_dir)
        .with_context(|| format!("reading {}", job_dir.display()))?
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(ATTEMPT_PREFIX))
        .collect();
    Ok(State::Missing((!dead.is_empty()).then(|| {
        format!(
            "an attempt stopped without finishing or reporting (killed?): {}",
            dead.join(", ")
        )
    })))
}

/// Who holds the job's lock, if anyone (a shared lock taken and dropped at once: a run waits
/// for it rather than failing).
fn lock_holder(job_dir: &Path) -> Result<Option<String>> {
    let path = job_dir.join(LOCK);
    let Ok(file) = std::fs::File::open(&path) else {
        return Ok(None);
    };
    match file.try_lock_shared() {
        Ok(()) => Ok(None),
        Err(std::fs::TryLockError::WouldBlock) => {
            let holder = std::fs::read_to_string(&path).unwrap_or_default();
            Ok(Some(format!("running: {}", holder.trim())))
        }
        Err(std::fs::TryLockError::Error(e)) => {
            Err(e).with_context(|| format!("checking the lock {}", path.display()))
        }
    }
}

#[derive(Serialize)]
struct JobStatus<'a> {
    index: u32,
    stage: &'a str,
    name: &'a str,
    state: &'static str,
    reason: Option<String>,
    /// The device a finished job rendered on.
    device: Option<String>,
}

#[derive(Serialize)]
struct StatusReport<'a> {
    dir: String,
    plan_commit: &'a str,
    fovea_commit: &'a str,
    done: usize,
    running: usize,
    failed: usize,
    missing: usize,
    jobs: Vec<JobStatus<'a>>,
}

/// Prints every job's state (as JSON with `json`). A plan from another build is reported, not
/// refused.
pub fn status(dir: &Path, json: bool, parse: Parse) -> Result<()> {
    let sweep = Sweep::open(dir, parse, false)?;
    let states = sweep
        .jobs
        .iter()
        .map(|j| state(&sweep, j))
        .collect::<Result<Vec<_>>>()?;
    let count = |name: &str| states.iter().filter(|s| s.name() == name).count();
    let report = StatusReport {
        dir: sweep.dir.display().to_string(),
        plan_commit: &sweep.file.commit,
        fovea_commit: commit(),
        done: count("done"),
        running: count("running"),
        failed: count("failed"),
        missing: count("missing"),
        jobs: sweep
            .jobs
            .iter()
            .zip(&states)
            .map(|(j, s)| JobStatus {
                index: j.index,
                stage: &j.stage,
                name: &j.name,
                state: s.name(),
                reason: s.reason(),
                device: match s {
                    State::Done(r) => r.device.clone(),
                    _ => None,
                },
            })
            .collect(),
    };
    if json {
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    let mut s = String::new();
    let _ = writeln!(
        s,
        "sweep {}: {} jobs: {} done, {} running, {} failed, {} missing",
        report.dir,
        sweep.jobs.len(),
        report.done,
        report.running,
        report.failed,
        report.missing
    );
    if report.plan_commit != report.fovea_commit {
        let _ = writeln!(
            s,
            "planned by the fovea of commit {}, this one is {}: run and merge refuse to mix builds",
            report.plan_commit, report.fovea_commit
        );
    }
    for j in &report.jobs {
        let _ = write!(
            s,
            "{:>5}  {:<9}  {:<7}  {}",
            j.index, j.stage, j.state, j.name
        );
        if let Some(r) = &j.reason {
            let _ = write!(s, ": {r}");
        }
        s.push('\n');
    }
    print!("{s}");
    Ok(())
}

pub struct ListArgs<'a> {
    /// Only this stage's jobs.
    pub stage: Option<&'a str>,
    /// Only jobs not done.
    pub pending: bool,
    /// Print the stages in order instead of jobs.
    pub stages: bool,
    /// Print Slurm array chunks `OFFSET SPEC` whose task ids stay below this (MaxArraySize).
    pub arrays: Option<u32>,
}

/// Prints job indices, one per line (or stages, or Slurm array chunks).
pub fn list(dir: &Path, args: &ListArgs, parse: Parse) -> Result<()> {
    let sweep = Sweep::open(dir, parse, false)?;
    if args.stages {
        for stage in &sweep.file.stages {
            println!("{stage}");
        }
        return Ok(());
    }
    if let Some(stage) = args.stage {
        if !sweep.file.stages.iter().any(|s| s == stage) {
            bail!(
                "--stage {stage}: the sweep's stages are {}",
                sweep.file.stages.join(", ")
            );
        }
    }
    let mut indices = Vec::new();
    for job in &sweep.jobs {
        if args.stage.is_some_and(|s| s != job.stage) {
            continue;
        }
        if args.pending && matches!(state(&sweep, job)?, State::Done(_)) {
            continue;
        }
        indices.push(job.index);
    }
    match args.arrays {
        Some(max) => {
            for (offset, spec) in array_chunks(&indices, max)? {
                println!("{offset} {spec}");
            }
        }
        None => {
            for i in indices {
                println!("{i}");
            }
        }
    }
    Ok(())
}

/// Slurm array specifications of `indices` (ascending) as `(offset, "a-b,c,…")`, task ids being
/// index − offset and each below `max_array_size`.
pub(super) fn array_chunks(indices: &[u32], max_array_size: u32) -> Result<Vec<(u32, String)>> {
    if max_array_size < 2 {
        bail!("--arrays {max_array_size}: Slurm's MaxArraySize is at least 2");
    }
    let mut chunks: Vec<(u32, Vec<u32>)> = Vec::new();
    for &i in indices {
        match chunks.last_mut() {
            Some((offset, members)) if i - *offset < max_array_size => members.push(i),
            _ => chunks.push((i, vec![i])),
        }
    }
    Ok(chunks
        .into_iter()
        .map(|(offset, members)| {
            let mut runs: Vec<(u32, u32)> = Vec::new();
            for m in members {
                match runs.last_mut() {
                    Some((_, end)) if *end + 1 == m => *end = m,
                    _ => runs.push((m, m)),
                }
            }
            let spec: Vec<String> = runs
                .iter()
                .map(|&(a, b)| {
                    if a == b {
                        (a - offset).to_string()
                    } else {
                        format!("{}-{}", a - offset, b - offset)
                    }
                })
                .collect();
            (offset, spec.join(","))
        })
        .collect())
}
