//! `fovea sweep merge`: every job's result gathered into the files the one-process command
//! writes, per study under `DIR/merged/<study>/`: `fovea quality`'s quality.json, quality.md,
//! reference EXRs and `run_*` folders; `fovea reference`'s EXR (and preview); `fovea replay`'s
//! replay.json, replay.md and `run_*` folders (exit status 1 on a regression, as `fovea replay`).
//! Each study's folder is built beside its place and renamed into it whole.

use super::files::{eye_key, Parse, Part, Study};
use super::job::{reference_of, OUTCOME_FILE};
use super::open::Sweep;
use super::status::{done, state, State};
use crate::commands::quality::{self, Combination, Outcome};
use crate::commands::replay::{self, Regression, ReplayArgs, TraceResult};
use anyhow::{bail, Context, Result};
use fovea_renderer::frame::StereoNoise;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

pub fn merge(dir: &Path, parse: Parse) -> Result<()> {
    let sweep = Sweep::open(dir, parse, true)?;
    let mut not_done = Vec::new();
    for job in &sweep.jobs {
        let s = state(&sweep, job)?;
        if !matches!(s, State::Done(_)) {
            not_done.push(format!(
                "job {} ({}): {}",
                job.index,
                job.name,
                s.describe()
            ));
        }
    }
    if !not_done.is_empty() {
        bail!(
            "{} of {} jobs are not done, and the merge needs them all (`fovea sweep status {}`):\n{}",
            not_done.len(),
            sweep.jobs.len(),
            sweep.dir.display(),
            not_done.join("\n")
        );
    }
    check_one_device(&sweep)?;
    // Replays whose frames left the tolerances: the merge is written, then exits as `fovea
    // replay` would (status 1).
    let mut regressions: Vec<Regression> = Vec::new();
    for (i, study) in sweep.file.studies.iter().enumerate() {
        let target = sweep.dir.join(&study.merged);
        let parent = target.parent().context("a merged folder has a parent")?;
        std::fs::create_dir_all(parent)
            .with_context(|| format!("creating {}", parent.display()))?;
        let temp = Building(parent.join(format!(".{}.merging-{}", study.name, std::process::id())));
        if temp.0.exists() {
            std::fs::remove_dir_all(&temp.0)
                .with_context(|| format!("removing {}", temp.0.display()))?;
        }
        std::fs::create_dir(&temp.0).with_context(|| format!("creating {}", temp.0.display()))?;
        parse(&study.args, &mut |s| match s {
            Study::Quality(q) => merge_quality(&sweep, i as u32, q, &temp.0),
            Study::Replay(r) => {
                if let Some(regression) = merge_replay(&sweep, i as u32, r, &temp.0)? {
                    regressions.push(Regression {
                        report: target.join("replay.md"),
                        ..regression
                    });
                }
                Ok(())
            }
            Study::Reference(r) => {
                let image = reference_of(&sweep, i as u32, None, None, None)?.mean()?;
                let name = r
                    .out
                    .file_name()
                    .context("the reference's --out names a file")?;
                crate::commands::reference::write(r, &temp.0.join(name), &image)?;
                crate::commands::reference::fireflies(r, &image);
                Ok(())
            }
        })
        .with_context(|| format!("merging study {}", study.name))?;
        replace(&temp.0, &target)?;
        println!("merged {}", target.display());
    }
    match regressions.len() {
        0 => Ok(()),
        1 => Err(regressions.remove(0).into()),
        _ => Err(Regression {
            failed_frames: regressions.iter().map(|r| r.failed_frames).sum(),
            report: sweep.dir.join("merged"),
        }
        .into()),
    }
}

/// A folder being built, removed unless it was moved into place.
struct Building(PathBuf);

impl Drop for Building {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The merge equals one process's output only if every job rendered on the same device.
fn check_one_device(sweep: &Sweep) -> Result<()> {
    if !sweep.file.device.one_device_for_all_jobs {
        return Ok(());
    }
    let mut devices: BTreeMap<String, Vec<u32>> = BTreeMap::new();
    for job in &sweep.jobs {
        if let Some(record) = done(sweep, job)? {
            if let Some(device) = record.device {
                devices.entry(device).or_default().push(job.index);
            }
        }
    }
    if devices.len() > 1 {
        let list: Vec<String> = devices
            .iter()
            .map(|(d, jobs)| format!("{d}: jobs {jobs:?}"))
            .collect();
        bail!(
            "the jobs ran on {} devices ({}); results from different devices do not merge into \
             one process's output (`sweep.json` field `device`): remove the result folders of one \
             group and run those jobs on the other device",
            devices.len(),
            list.join("; ")
        );
    }
    Ok(())
}

fn merge_quality(sweep: &Sweep, study: u32, q: &quality::QualityArgs, out: &Path) -> Result<()> {
    let prepared = quality::prepare(q)?;
    for camera in q.cameras {
        let mut images = Vec::new();
        for &eye in quality::reference_eyes(q) {
            let key = eye_key(q, eye);
            let mut eye_images = Vec::new();
            for frame in quality::reference_frames(camera, &prepared.evaluated) {
                let image = reference_of(sweep, study, Some(camera), Some(frame), key.as_deref())?
                    .mean()?;
                quality::write_reference(out, q, camera, eye, frame, &image)?;
                eye_images.push(image);
            }
            images.push(eye_images);
        }
        quality::write_displayed_references(out, q, camera, &prepared.evaluated, &images)?;
    }
    let mut outcomes = Vec::new();
    for job in sweep.jobs.iter().filter(|j| j.study == study) {
        let Part::Run {
            camera,
            method,
            denoiser,
            taa,
            noise,
        } = &job.part
        else {
            continue;
        };
        let result = sweep.result_dir(job);
        let path = result.join(OUTCOME_FILE);
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("reading {}", path.display()))?;
        let outcome: Outcome = serde_json::from_str(&text)
            .with_context(|| format!("{}: not a quality outcome", path.display()))?;
        if let Outcome::Run(_) = outcome {
            let name = Combination {
                camera,
                method,
                denoiser,
                taa,
                noise: noise.as_deref().map(StereoNoise::parse).transpose()?,
            }
            .run_dir_name();
            link_tree(&result.join(&name), &out.join(&name))?;
        }
        outcomes.push(outcome);
    }
    quality::write_report(q, &prepared, outcomes, out)
}

/// A replay study: each trace's result and frames, and the report (with the regression, if any).
fn merge_replay(
    sweep: &Sweep,
    study: u32,
    r: &ReplayArgs,
    out: &Path,
) -> Result<Option<Regression>> {
    let mut results = Vec::new();
    for job in sweep.jobs.iter().filter(|j| j.study == study) {
        let Part::Trace { trace } = &job.part else {
            continue;
        };
        let result = sweep.result_dir(job);
        let path = result.join(OUTCOME_FILE);
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("reading {}", path.display()))?;
        let trace_result: TraceResult = serde_json::from_str(&text)
            .with_context(|| format!("{}: not a replay result", path.display()))?;
        let name = replay::run_dir_name(trace)?;
        link_tree(&result.join(&name), &out.join(&name))?;
        results.push(trace_result);
    }
    replay::write_report(r, results, out)
}

/// `dst` as a copy of `src` made of hard links (copies across file systems).
fn link_tree(src: &Path, dst: &Path) -> Result<()> {
    std::fs::create_dir(dst).with_context(|| format!("creating {}", dst.display()))?;
    for entry in std::fs::read_dir(src).with_context(|| format!("reading {}", src.display()))? {
        let entry = entry?;
        let (from, to) = (entry.path(), dst.join(entry.file_name()));
        let kind = entry.file_type()?;
        if kind.is_dir() {
            link_tree(&from, &to)?;
        } else if kind.is_file() {
            if std::fs::hard_link(&from, &to).is_err() {
                std::fs::copy(&from, &to)
                    .with_context(|| format!("copying {} to {}", from.display(), to.display()))?;
            }
        } else {
            bail!(
                "{} is neither a file nor a folder; a job's result holds only those",
                from.display()
            );
        }
    }
    Ok(())
}

/// Moves the built folder into place; an earlier merge there is replaced.
fn replace(built: &Path, target: &Path) -> Result<()> {
    let old = target.with_file_name(format!(
        ".{}.replaced-{}",
        target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default(),
        std::process::id()
    ));
    let had_old = target.exists();
    if had_old {
        std::fs::rename(target, &old)
            .with_context(|| format!("moving the earlier {} aside", target.display()))?;
    }
    std::fs::rename(built, target)
        .with_context(|| format!("moving the merge into {}", target.display()))?;
    if had_old {
        std::fs::remove_dir_all(&old).with_context(|| format!("removing {}", old.display()))?;
    }
    Ok(())
}
