//! `fovea sweep run`: one job, written into a temporary folder inside its own job folder and
//! renamed to `result/` when whole. Under the job's lock: a finished job is left as it is, a
//! killed attempt's folder is removed, and a failed attempt leaves only `failed.json`.

use super::files::{
    commit, eye_key, host_name, Failure, Job, JobRecord, Parse, Part, Study, ATTEMPT_PREFIX,
    FAILURE, JOBS_FILE, LOCK, RECORD,
};
use super::open::Sweep;
use super::status::{done, State};
use crate::commands::quality::{self, Combination, Outcome, QualityArgs};
use crate::commands::setup::Eyes;
use crate::output::write_json;
use crate::reference_sum::{self, SampleSum};
use anyhow::{anyhow, bail, Context, Result};
use fovea_hal::Eye;
use fovea_renderer::frame::StereoNoise;
use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::Path;

/// A reference part's sum inside its result folder.
pub(super) const SUM_FILE: &str = "sum.bin";
/// A run's outcome (metrics or refusal) inside its result folder.
pub(super) const OUTCOME_FILE: &str = "outcome.json";

/// Runs job `index` (or the Slurm array task's: `SLURM_ARRAY_TASK_ID`), plus `offset`.
pub fn run(dir: &Path, index: Option<u32>, offset: u32, parse: Parse) -> Result<()> {
    let task = match index {
        Some(i) => i,
        None => {
            let id = std::env::var("SLURM_ARRAY_TASK_ID").map_err(|_| {
                anyhow!("give --index K, or run as a Slurm array task (SLURM_ARRAY_TASK_ID)")
            })?;
            id.parse()
                .with_context(|| format!("SLURM_ARRAY_TASK_ID '{id}' is not a job index"))?
        }
    };
    let index = task
        .checked_add(offset)
        .context("--index + --offset overflows")?;
    let sweep = Sweep::open(dir, parse, true)?;
    let Some(job) = sweep.jobs.get(index as usize) else {
        bail!(
            "{} plans jobs 0..{}; there is no job {index}",
            sweep.dir.join(JOBS_FILE).display(),
            sweep.jobs.len()
        );
    };
    let job_dir = sweep.job_dir(job);
    std::fs::create_dir_all(&job_dir).with_context(|| format!("creating {}", job_dir.display()))?;
    let _lock = lock(&job_dir)?;
    if done(&sweep, job)?.is_some() {
        println!(
            "job {index} ({}) is done: {}; nothing to do",
            job.name,
            sweep.result_dir(job).display()
        );
        return Ok(());
    }
    remove_dead_attempts(&job_dir)?;
    // A failure record speaks of an earlier attempt; this one writes its own if it fails.
    let failure = job_dir.join(FAILURE);
    if failure.exists() {
        std::fs::remove_file(&failure)
            .with_context(|| format!("removing {}", failure.display()))?;
    }
    let attempt = job_dir.join(format!(
        "{ATTEMPT_PREFIX}{}-{}",
        host_name(),
        std::process::id()
    ));
    let started = std::time::Instant::now();
    let outcome = (|| -> Result<()> {
        check_dependencies(&sweep, job)?;
        std::fs::create_dir(&attempt).with_context(|| format!("creating {}", attempt.display()))?;
        // From here a signal is a request: the job stops at its next check (a render's next
        // frame, a reference's next batch), removes its attempt and records why, also while it is
        // still loading the scene or opening the device.
        crate::interrupt::running();
        stop_requested()?;
        let device = execute(&sweep, job, &attempt, parse)?;
        // A signal that came while the last piece was measured: cancelled, not done.
        stop_requested()?;
        write_json(
            &attempt.join(RECORD),
            &JobRecord {
                index,
                name: job.name.clone(),
                commit: commit().to_string(),
                device,
                host: host_name(),
                seconds: started.elapsed().as_secs_f64(),
            },
        )?;
        let result = sweep.result_dir(job);
        std::fs::rename(&attempt, &result).with_context(|| {
            format!(
                "moving {} into place as {}",
                attempt.display(),
                result.display()
            )
        })?;
        sync_dir(&job_dir);
        Ok(())
    })();
    match outcome {
        Ok(()) => {
            println!(
                "job {index} ({}) done in {:.1} s: {}",
                job.name,
                started.elapsed().as_secs_f64(),
                sweep.result_dir(job).display()
            );
            Ok(())
        }
        Err(e) => {
            let _ = std::fs::remove_dir_all(&attempt);
            let exit_code = e
                .downcast_ref::<crate::interrupt::Interrupted>()
                .map_or(1, |i| i.exit_code());
            let record = Failure {
                index,
                reason: format!("{e:#}"),
                exit_code,
                host: host_name(),
                pid: std::process::id(),
            };
            write_json(&job_dir.join(FAILURE), &record).with_context(|| {
                format!("job {index} failed ({e:#}), and recording the failure failed")
            })?;
            Err(e.context(format!("job {index} ({}) failed", job.name)))
        }
    }
}

/// The job's lock, held while it runs: a second run of the same job waits for the first and then
/// finds it done. The file says who holds it (`fovea sweep status`).
fn lock(job_dir: &Path) -> Result<File> {
    let path = job_dir.join(LOCK);
    let mut file = OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(&path)
        .with_context(|| format!("opening {}", path.display()))?;
    file.lock()
        .with_context(|| format!("locking {}", path.display()))?;
    file.set_len(0)?;
    writeln!(file, "pid {} on {}", std::process::id(), host_name())?;
    Ok(file)
}

/// Folders of attempts that stopped without cleaning up (a killed process): removed under the
/// lock, so none of them belongs to a live run.
fn remove_dead_attempts(job_dir: &Path) -> Result<()> {
    for entry in
        std::fs::read_dir(job_dir).with_context(|| format!("reading {}", job_dir.display()))?
    {
        let entry = entry?;
        if entry
            .file_name()
            .to_string_lossy()
            .starts_with(ATTEMPT_PREFIX)
        {
            std::fs::remove_dir_all(entry.path())
                .with_context(|| format!("removing the dead attempt {}", entry.path().display()))?;
        }
    }
    Ok(())
}

/// Best effort: the rename reaches the disk with the folder's entry.
fn sync_dir(dir: &Path) {
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
}

fn check_dependencies(sweep: &Sweep, job: &Job) -> Result<()> {
    for &d in &job.after {
        let dep = &sweep.jobs[d as usize];
        let state = super::status::state(sweep, dep)?;
        if !matches!(state, State::Done(_)) {
            bail!(
                "job {} needs job {d} ({}), which is {}: run the stages in order",
                job.index,
                dep.name,
                state.describe()
            );
        }
    }
    Ok(())
}

/// A signal asked the job to stop (Slurm's scancel sends SIGTERM).
fn stop_requested() -> Result<()> {
    match crate::interrupt::requested() {
        Some(i) => Err(i.into()),
        None => Ok(()),
    }
}

/// Computes the job's piece into `attempt`; returns the device it rendered on.
fn execute(sweep: &Sweep, job: &Job, attempt: &Path, parse: Parse) -> Result<Option<String>> {
    let mut device = None;
    parse(&job.args, &mut |study| {
        device = match (study, &job.part) {
            (
                Study::Quality(q),
                Part::Reference {
                    camera: Some(camera),
                    frame: Some(frame),
                    eye,
                    batches,
                },
            ) => {
                let prepared = quality::prepare(q)?;
                let eye = eye_of(q, eye.as_deref())?;
                let mut r = quality::reference_renderer(q, camera, &prepared.evaluated)?;
                let pose = r
                    .views
                    .pose(*frame, eye)
                    .with_context(|| format!("frame {frame} has no reference pose"))?;
                let sum = reference_sum::render_sum(
                    &mut r.renderer,
                    &pose,
                    q.reference_spp,
                    fovea_renderer::frame::REALTIME_MAX_DEPTH,
                    batches[0]..batches[1],
                    &mut |_| stop_requested(),
                )?;
                crate::commands::check_validation(&r.ctx)?;
                reference_sum::write(&attempt.join(SUM_FILE), &sum)?;
                Some(r.ctx.info.name.clone())
            }
            (
                Study::Reference(r),
                Part::Reference {
                    camera: None,
                    frame: None,
                    eye: None,
                    batches,
                },
            ) => {
                crate::commands::reference::check(r)?;
                let (ctx, mut renderer, pose) = crate::commands::reference::renderer(r)?;
                let sum = reference_sum::render_sum(
                    &mut renderer,
                    &pose,
                    r.spp,
                    r.max_depth,
                    batches[0]..batches[1],
                    &mut |_| stop_requested(),
                )?;
                crate::commands::check_validation(&ctx)?;
                reference_sum::write(&attempt.join(SUM_FILE), &sum)?;
                Some(ctx.info.name.clone())
            }
            (
                Study::Quality(q),
                Part::Run {
                    camera,
                    method,
                    denoiser,
                    taa,
                    noise,
                },
            ) => {
                let prepared = quality::prepare(q)?;
                let combination = Combination {
                    camera,
                    method,
                    denoiser,
                    taa,
                    noise: noise.as_deref().map(StereoNoise::parse).transpose()?,
                };
                if let Some(refused) = quality::refusal(q, &prepared, &combination)? {
                    write_json(&attempt.join(OUTCOME_FILE), &Outcome::Refused(refused))?;
                    None
                } else {
                    let evaluated = &prepared.evaluated;
                    let mut images = Vec::new();
                    for &eye in quality::reference_eyes(q) {
                        let key = eye_key(q, eye);
                        images.push(
                            quality::reference_frames(camera, evaluated)
                                .into_iter()
                                .map(|frame| {
                                    let sum = reference_of(
                                        sweep,
                                        job.study,
                                        Some(camera),
                                        Some(frame),
                                        key.as_deref(),
                                    )?;
                                    if (sum.width, sum.height) != (q.width, q.height) {
                                        bail!(
                                            "the reference parts are {}×{}, the command renders \
                                             {}×{}",
                                            sum.width,
                                            sum.height,
                                            q.width,
                                            q.height
                                        );
                                    }
                                    sum.mean()
                                })
                                .collect::<Result<Vec<_>>>()?,
                        );
                    }
                    // The warp between the eyes needs the scene (a stereo study only).
                    let views = match q.eyes {
                        Eyes::Both => Some(quality::reference_views(q, camera, evaluated)?),
                        Eyes::Left | Eyes::Right => None,
                    };
                    let references =
                        quality::References::new(q, camera, evaluated, images, views.as_ref())?;
                    let run_dir = attempt.join(combination.run_dir_name());
                    let measured = quality::run_combination(
                        q,
                        &prepared,
                        &combination,
                        &references,
                        &run_dir,
                    )?;
                    write_json(
                        &attempt.join(OUTCOME_FILE),
                        &Outcome::Run(Box::new(measured)),
                    )?;
                    Some(render_device(&run_dir)?)
                }
            }
            (Study::Replay(r), Part::Trace { trace }) => {
                use crate::commands::replay;
                replay::check(r)?;
                // A sweep only checks against baselines (the plan refuses --update-baseline).
                let store = crate::replay::baseline::Store::open_read(r.baseline)?;
                let result = replay::replay_trace(r, &store, trace, attempt)
                    .with_context(|| format!("trace {trace}"))?;
                write_json(&attempt.join(OUTCOME_FILE), &result)?;
                Some(render_device(&attempt.join(replay::run_dir_name(trace)?))?)
            }
            (_, part) => bail!(
                "job {}: its part {part:?} does not fit its command `fovea {}`",
                job.index,
                job.args.join(" ")
            ),
        };
        Ok(())
    })?;
    Ok(device)
}

/// The device a `fovea render` folder's report names.
fn render_device(run_dir: &Path) -> Result<String> {
    let path = run_dir.join("report.json");
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let report: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("reading {}", path.display()))?;
    report["device"]
        .as_str()
        .map(str::to_string)
        .with_context(|| format!("{}: no field `device`", path.display()))
}

/// The eye a reference part names (none: the left eye of a one-eye study).
fn eye_of(q: &QualityArgs, key: Option<&str>) -> Result<Eye> {
    let eye = match key {
        None | Some("left") => Eye::Left,
        Some("right") => Eye::Right,
        Some(other) => bail!("reference part eye '{other}': expected left or right"),
    };
    if eye_key(q, eye).as_deref() != key {
        bail!(
            "a reference part of eye {} in a study of --eyes {}",
            key.unwrap_or("(none)"),
            q.eyes.name()
        );
    }
    Ok(eye)
}

/// The whole reference of a study's camera pose and eye (quality) or of the study (reference),
/// from the sums of its finished reference jobs.
pub(super) fn reference_of(
    sweep: &Sweep,
    study: u32,
    camera: Option<&str>,
    frame: Option<u32>,
    eye: Option<&str>,
) -> Result<SampleSum> {
    let mut parts = Vec::new();
    for job in &sweep.jobs {
        let Part::Reference {
            camera: c,
            frame: f,
            eye: e,
            ..
        } = &job.part
        else {
            continue;
        };
        if job.study != study || c.as_deref() != camera || *f != frame || e.as_deref() != eye {
            continue;
        }
        let path = sweep.result_dir(job).join(SUM_FILE);
        parts.push(
            reference_sum::read(&path)
                .with_context(|| format!("job {} ({})", job.index, job.name))?,
        );
    }
    let sum = reference_sum::merge(&parts).with_context(|| {
        format!(
            "the reference of study {}{}{}{}",
            sweep.file.studies[study as usize].name,
            camera.map_or(String::new(), |c| format!(", {c} camera")),
            frame.map_or(String::new(), |f| format!(", frame {f}")),
            eye.map_or(String::new(), |e| format!(", {e} eye"))
        )
    })?;
    if sum.batches != (0..reference_sum::batch_count(sum.spp)) {
        bail!("the reference parts do not cover every batch");
    }
    Ok(sum)
}
