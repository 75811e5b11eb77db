//! `fovea sweep plan`: the studies of a command and its axes, and their jobs.

use super::files::{
    commit, eye_key, Axes, DeviceRequirement, Job, Parse, Part, Study, StudyEntry, SweepFile,
    FORMAT, JOBS_FILE, SWEEP_FILE,
};
use crate::commands::quality::{self, QualityArgs};
use crate::output::{write_json, write_text};
use crate::reference_sum::{batch_count, blocks, BATCH_SPP};
use anyhow::{bail, Context, Result};
use std::path::Path;

pub struct PlanArgs<'a> {
    pub out: &'a Path,
    /// The one-process command (after `fovea`): `quality …`, `reference …` or `replay …`.
    pub command: &'a [String],
    pub axes: Axes,
    pub batches_per_job: u32,
}

/// The value of `--flag` in `args` (`--flag V` or `--flag=V`; the last one given).
pub(super) fn flag_value(args: &[String], flag: &str) -> Option<String> {
    let prefix = format!("{flag}=");
    let mut found = None;
    for (i, a) in args.iter().enumerate() {
        if a == flag {
            found = args.get(i + 1).cloned();
        } else if let Some(v) = a.strip_prefix(&prefix) {
            found = Some(v.to_string());
        }
    }
    found
}

/// `args` with every `--flag V` / `--flag=V` taken out and `--flag value` appended.
pub(super) fn set_flag(args: &[String], flag: &str, value: &str) -> Vec<String> {
    let prefix = format!("{flag}=");
    let mut out = Vec::with_capacity(args.len() + 2);
    let mut skip = false;
    for a in args {
        if std::mem::take(&mut skip) {
            continue;
        }
        if a == flag {
            skip = true;
        } else if !a.starts_with(&prefix) {
            out.push(a.clone());
        }
    }
    out.extend([flag.to_string(), value.to_string()]);
    out
}

/// A file-name-safe form of a scene, headset or gaze for study names.
fn slug(value: &str) -> String {
    let stem = Path::new(value)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .filter(|_| value.ends_with(".gltf") || value.ends_with(".glb") || value.ends_with(".toml"))
        .unwrap_or_else(|| value.to_string());
    stem.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' || c == '.' {
                c
            } else {
                '-'
            }
        })
        .collect()
}

/// One study per scene × headset × gaze of the axes (an empty axis: the command's own value).
pub(super) fn studies(command: &[String], axes: &Axes) -> Result<Vec<StudyEntry>> {
    let kind = command.first().map(String::as_str).unwrap_or("");
    if !["quality", "reference", "replay"].contains(&kind) {
        bail!(
            "fovea sweep splits `fovea quality …`, `fovea reference …` or `fovea replay …`; `{}` \
             is none of them",
            command.join(" ")
        );
    }
    if flag_value(command, "--out").is_some() {
        bail!(
            "leave --out out of the command: the merged output goes to DIR/merged/<study> inside \
             the sweep folder"
        );
    }
    let axis_flags = [
        ("--scenes", "--scene", &axes.scenes),
        ("--headsets", "--headset", &axes.headsets),
        ("--gazes", "--gaze", &axes.gazes),
    ];
    for (axis, flag, values) in axis_flags {
        if values.is_empty() {
            continue;
        }
        if kind == "replay" {
            bail!(
                "{axis}: a replay sweep has no axes (its traces are its jobs, each against its \
                 baseline)"
            );
        }
        if flag_value(command, flag).is_some() {
            bail!("{flag} in the command and {axis}: give one of them");
        }
        if kind == "reference" && flag == "--gaze" {
            bail!("{axis}: a reference has no gaze (the axis is for quality sweeps)");
        }
        if let Some(v) = values.iter().find(|v| v.is_empty() || v.starts_with('-')) {
            bail!("{axis}: '{v}' is not a value");
        }
    }
    let or_own = |values: &Vec<String>| -> Vec<Option<String>> {
        if values.is_empty() {
            vec![None]
        } else {
            values.iter().cloned().map(Some).collect()
        }
    };
    let scene_of = |s: &Option<String>| {
        s.clone()
            .or_else(|| flag_value(command, "--scene"))
            .unwrap_or_else(|| fovea_stage::scenes::DEFAULT_SCENE.to_string())
    };
    let mut studies: Vec<StudyEntry> = Vec::new();
    for scene in or_own(&axes.scenes) {
        for headset in or_own(&axes.headsets) {
            for gaze in or_own(&axes.gazes) {
                let mut name = slug(&scene_of(&scene));
                let mut args = command.to_vec();
                for (flag, value) in [
                    ("--scene", &scene),
                    ("--headset", &headset),
                    ("--gaze", &gaze),
                ] {
                    if let Some(v) = value {
                        args = set_flag(&args, flag, v);
                        if flag != "--scene" {
                            name = format!("{name}_{}", slug(v));
                        }
                    }
                }
                let merged = format!("merged/{name}");
                let out = if kind == "reference" {
                    format!("{merged}/reference.exr")
                } else {
                    merged.clone()
                };
                args = set_flag(&args, "--out", &out);
                if let Some(other) = studies.iter().find(|s| s.name == name) {
                    bail!(
                        "two studies are named {name} (`{}` and `{}`): give the scenes distinct \
                         file names",
                        other.args.join(" "),
                        args.join(" ")
                    );
                }
                studies.push(StudyEntry { name, args, merged });
            }
        }
    }
    Ok(studies)
}

/// What the jobs of a study need to know of its parsed command.
enum Shape {
    Quality {
        cameras: Vec<String>,
        methods: Vec<String>,
        denoisers: Vec<String>,
        taa: Vec<String>,
        /// `--stereo-noise`'s names (one `None`: the flag not given).
        noises: Vec<Option<String>>,
        /// The eyes with references, as the reference parts name them (`None`: a one-eye run).
        eyes: Vec<Option<String>>,
        evaluated: Vec<u32>,
        spp: u32,
    },
    Reference {
        spp: u32,
    },
    Replay {
        traces: Vec<String>,
    },
}

fn shape(args: &[String], parse: Parse) -> Result<Shape> {
    let mut shape = None;
    parse(args, &mut |study| {
        shape = Some(match study {
            Study::Quality(q) => quality_shape(q)?,
            Study::Reference(r) => {
                crate::commands::reference::check(r)?;
                Shape::Reference { spp: r.spp }
            }
            Study::Replay(r) => {
                crate::commands::replay::check(r)?;
                if r.update {
                    bail!(
                        "--update-baseline: a sweep compares with baselines; write them with one \
                         `fovea replay --update-baseline` process"
                    );
                }
                Shape::Replay {
                    traces: r.traces.to_vec(),
                }
            }
        });
        Ok(())
    })?;
    shape.context("the command gave no study")
}

fn quality_shape(q: &QualityArgs) -> Result<Shape> {
    if let Some(from) = q.references {
        bail!(
            "quality --references {}: a sweep renders its references as jobs of their own; plan it without --references",
            from.display()
        );
    }
    let prepared = quality::prepare(q)?;
    Ok(Shape::Quality {
        cameras: q.cameras.to_vec(),
        methods: q.methods.to_vec(),
        denoisers: q.denoisers.to_vec(),
        taa: q.taa.to_vec(),
        noises: quality::stereo_noises(q)
            .into_iter()
            .map(|n| n.map(|n| n.name().to_string()))
            .collect(),
        eyes: quality::reference_eyes(q)
            .iter()
            .map(|&eye| eye_key(q, eye))
            .collect(),
        evaluated: prepared.evaluated,
        spp: q.reference_spp,
    })
}

/// The stages and jobs of the studies: every reference part first (stage `reference`; each eye's
/// in a stereo quality study), then every quality combination after the parts of its study's
/// camera and every replay trace (stage `run`).
pub(super) fn jobs(
    studies: &[StudyEntry],
    batches_per_job: u32,
    parse: Parse,
) -> Result<(Vec<String>, Vec<Job>)> {
    if !batches_per_job.is_power_of_two() {
        bail!("--batches-per-job {batches_per_job} must be a power of two (1, 2, 4, …)");
    }
    let shapes = studies
        .iter()
        .map(|s| shape(&s.args, parse).with_context(|| format!("`fovea {}`", s.args.join(" "))))
        .collect::<Result<Vec<_>>>()?;
    let mut jobs: Vec<Job> = Vec::new();
    let mut push = |stage: &str,
                    name: String,
                    study: usize,
                    args: Vec<String>,
                    part: Part,
                    after: Vec<u32>| {
        let index = jobs.len() as u32;
        jobs.push(Job {
            index,
            stage: stage.to_string(),
            name,
            study: study as u32,
            args,
            part,
            out: format!("jobs/{index:04}"),
            after,
        });
        index
    };
    // (study, camera) → its reference jobs.
    let mut parts_of: Vec<(usize, Option<String>, Vec<u32>)> = Vec::new();
    for (i, (study, shape)) in studies.iter().zip(&shapes).enumerate() {
        match shape {
            Shape::Quality {
                cameras,
                eyes,
                evaluated,
                spp,
                ..
            } => {
                for camera in cameras {
                    let args = set_flag(&study.args, "--cameras", camera);
                    let mut indices = Vec::new();
                    for frame in quality::reference_frames(camera, evaluated) {
                        for eye in eyes {
                            let eye_words =
                                eye.as_ref().map_or(String::new(), |e| format!(", {e} eye"));
                            for b in blocks(batch_count(*spp), batches_per_job) {
                                let name = format!(
                                    "{}: reference, {camera} camera, frame {frame}{eye_words}, \
                                     batches {}..{}",
                                    study.name, b.start, b.end
                                );
                                let part = Part::Reference {
                                    camera: Some(camera.clone()),
                                    frame: Some(frame),
                                    eye: eye.clone(),
                                    batches: [b.start, b.end],
                                };
                                indices.push(push(
                                    "reference",
                                    name,
                                    i,
                                    args.clone(),
                                    part,
                                    vec![],
                                ));
                            }
                        }
                    }
                    parts_of.push((i, Some(camera.clone()), indices));
                }
            }
            Shape::Reference { spp } => {
                for b in blocks(batch_count(*spp), batches_per_job) {
                    let name = format!("{}: reference, batches {}..{}", study.name, b.start, b.end);
                    let part = Part::Reference {
                        camera: None,
                        frame: None,
                        eye: None,
                        batches: [b.start, b.end],
                    };
                    push("reference", name, i, study.args.clone(), part, vec![]);
                }
            }
            Shape::Replay { .. } => {}
        }
    }
    for (i, (study, shape)) in studies.iter().zip(&shapes).enumerate() {
        if let Shape::Replay { traces } = shape {
            for trace in traces {
                let name = format!("{}: trace {trace}", study.name);
                let part = Part::Trace {
                    trace: trace.clone(),
                };
                push("run", name, i, study.args.clone(), part, vec![]);
            }
            continue;
        }
        let Shape::Quality {
            cameras,
            methods,
            denoisers,
            taa,
            noises,
            ..
        } = shape
        else {
            continue;
        };
        for camera in cameras {
            let after = parts_of
                .iter()
                .find(|(s, c, _)| *s == i && c.as_deref() == Some(camera))
                .map(|(_, _, indices)| indices.clone())
                .unwrap_or_default();
            for method in methods {
                for denoiser in denoisers {
                    for t in taa {
                        for noise in noises {
                            let mut args = set_flag(&study.args, "--cameras", camera);
                            for (flag, v) in [
                                ("--methods", method),
                                ("--denoisers", denoiser),
                                ("--taa", t),
                            ] {
                                args = set_flag(&args, flag, v);
                            }
                            let mut name = format!(
                                "{}: {camera} camera, {method} + {denoiser}, TAA {t}",
                                study.name
                            );
                            if let Some(noise) = noise {
                                args = set_flag(&args, "--stereo-noise", noise);
                                name = format!("{name}, stereo noise {noise}");
                            }
                            let part = Part::Run {
                                camera: camera.clone(),
                                method: method.clone(),
                                denoiser: denoiser.clone(),
                                taa: t.clone(),
                                noise: noise.clone(),
                            };
                            push("run", name, i, args, part, after.clone());
                        }
                    }
                }
            }
        }
    }
    let mut stages: Vec<String> = Vec::new();
    for job in &jobs {
        if !stages.contains(&job.stage) {
            stages.push(job.stage.clone());
        }
    }
    Ok((stages, jobs))
}

/// Writes `DIR/jobs.jsonl` and then `DIR/sweep.json` (a folder with both is a whole plan).
pub fn plan(args: &PlanArgs, parse: Parse) -> Result<()> {
    let dir = args.out;
    if dir.exists() {
        let empty = std::fs::read_dir(dir)
            .with_context(|| format!("--out {}", dir.display()))?
            .next()
            .is_none();
        if !empty {
            bail!(
                "--out {}: the folder exists and is not empty; a sweep is planned into a new or \
                 empty folder",
                dir.display()
            );
        }
    }
    let studies = studies(args.command, &args.axes)?;
    let (stages, jobs) = jobs(&studies, args.batches_per_job, parse)?;
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let workdir = std::env::current_dir().context("the working folder")?;
    let file = SweepFile {
        format: FORMAT,
        command: args.command.to_vec(),
        axes: args.axes.clone(),
        batches_per_job: args.batches_per_job,
        reference_batch_spp: BATCH_SPP,
        commit: commit().to_string(),
        fovea_version: env!("CARGO_PKG_VERSION").to_string(),
        workdir,
        device: DeviceRequirement {
            selector: flag_value(args.command, "--device"),
            one_device_for_all_jobs: true,
        },
        stages: stages.clone(),
        studies,
        jobs: jobs.len() as u32,
    };
    let mut lines = String::new();
    for job in &jobs {
        lines.push_str(&serde_json::to_string(job)?);
        lines.push('\n');
    }
    write_text(&dir.join(JOBS_FILE), &lines)?;
    write_json(&dir.join(SWEEP_FILE), &file)?;
    let per_stage: Vec<String> = stages
        .iter()
        .map(|s| format!("{} {s}", jobs.iter().filter(|j| &j.stage == s).count()))
        .collect();
    println!(
        "planned {} jobs ({}) for {} studies in {}; run them with `scripts/sweep-slurm {}` or \
         `fovea sweep run {} --index K` stage by stage, then `fovea sweep merge {}`",
        jobs.len(),
        per_stage.join(", "),
        file.studies.len(),
        dir.display(),
        dir.display(),
        dir.display(),
        dir.display()
    );
    Ok(())
}
