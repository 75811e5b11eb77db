//! `fovea sweep` without a scheduler: a small quality sweep run job by job (as a shell loop would)
//! merges into what one `fovea quality` process writes (a stereo one with two stereo noises too);
//! a reference split into sample batches merges into the same EXR bytes as `fovea reference`;
//! failed, killed and repeated jobs leave no partial result and never reach the merge; bad plans
//! are refused naming the file and field.
//! Then the same through a real Slurm (`scripts/sweep-slurm`, sbatch job arrays on the one-node
//! cluster of scripts/slurm/setup): two scenes merged equal to one process's output, and a stage
//! cancelled mid-run (scancel) rerun cleanly. Without a cluster that test says "skipped"; with
//! FOVEA_REQUIRE_SLURM=1 (scripts/test) it fails.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fovea-sweep-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn fovea(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fovea"))
        .args(args)
        .output()
        .unwrap()
}

/// Runs fovea, expecting success; its stdout.
fn fovea_ok(args: &[&str]) -> String {
    let out = fovea(args);
    assert!(
        out.status.success(),
        "fovea {} failed: {}\n{}",
        args.join(" "),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Runs fovea, expecting failure; its stderr.
fn fovea_err(args: &[&str]) -> String {
    let out = fovea(args);
    assert!(!out.status.success(), "fovea {} succeeded", args.join(" "));
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn read_jobs(sweep: &Path) -> Vec<serde_json::Value> {
    std::fs::read_to_string(sweep.join("jobs.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

fn status_json(sweep: &Path) -> serde_json::Value {
    serde_json::from_str(&fovea_ok(&[
        "sweep",
        "status",
        sweep.to_str().unwrap(),
        "--json",
    ]))
    .unwrap()
}

/// Every job of a stage, one after the other (a shell loop).
fn run_stage(sweep: &Path, stage: &str) {
    let dir = sweep.to_str().unwrap();
    for index in fovea_ok(&["sweep", "list", dir, "--stage", stage]).lines() {
        fovea_ok(&["sweep", "run", dir, "--index", index]);
    }
}

fn assert_no_attempts(job_dir: &Path) {
    let left: Vec<String> = std::fs::read_dir(job_dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".attempt-"))
        .collect();
    assert!(left.is_empty(), "{}: {left:?}", job_dir.display());
}

/// quality.json without the measured GPU times (they differ between any two runs).
fn quality_json(dir: &Path) -> serde_json::Value {
    let path = dir.join("quality.json");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    for run in v["runs"].as_array_mut().unwrap() {
        assert!(run["frame_gpu_ms"].as_f64().unwrap() > 0.0);
        run["frame_gpu_ms"] = serde_json::Value::Null;
    }
    v
}

/// quality.md without the GPU ms column (the last cell of the metric rows).
fn quality_md(dir: &Path) -> String {
    let text = std::fs::read_to_string(dir.join("quality.md")).unwrap();
    text.lines()
        .map(|l| {
            if l.starts_with("| ") && l.contains(" / ") {
                let cut = l.trim_end_matches(" |").rfind(" | ").unwrap();
                format!("{} | ms |", &l[..cut])
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// A merged study equals one process's output: quality.json and quality.md but for the timings,
/// the reference EXRs and the runs' frames byte for byte.
fn assert_same_quality(one: &Path, merged: &Path) {
    assert_eq!(
        quality_json(merged),
        quality_json(one),
        "{} and {}",
        merged.display(),
        one.display()
    );
    assert_eq!(quality_md(merged), quality_md(one));
    let mut compared = 0;
    for entry in std::fs::read_dir(one).unwrap() {
        let entry = entry.unwrap();
        let name = entry.file_name().to_string_lossy().into_owned();
        let files: Vec<PathBuf> = if name.starts_with("reference_") {
            vec![entry.path()]
        } else if name.starts_with("run_") {
            std::fs::read_dir(entry.path())
                .unwrap()
                .map(|e| e.unwrap().path())
                .filter(|p| p.to_string_lossy().contains("frame_"))
                .collect()
        } else {
            continue;
        };
        for file in files {
            let relative = file.strip_prefix(one).unwrap();
            assert!(
                std::fs::read(&file).unwrap() == std::fs::read(merged.join(relative)).unwrap(),
                "{} differs between {} and {}",
                relative.display(),
                one.display(),
                merged.display()
            );
            compared += 1;
        }
    }
    assert!(compared > 4, "only {compared} files compared");
}

/// 1 scene × 2 methods × 2 denoisers, still camera, 64×72, 32-spp references in 2 batches.
const QUALITY: &[&str] = &[
    "quality",
    "--width",
    "64",
    "--height",
    "72",
    "--frames",
    "3",
    "--eval-frames",
    "2",
    "--methods",
    "vp,cartesian",
    "--denoisers",
    "none,svgf",
    "--cameras",
    "still",
    "--reference-spp",
    "32",
    "--rings",
    "4",
];

#[test]
fn a_sweep_run_job_by_job_merges_into_the_one_process_quality_output() {
    let dir = temp_dir("quality");
    let sweep = dir.join("sweep");
    let mut plan = vec!["sweep", "plan", "--out"];
    let sweep_arg = sweep.to_str().unwrap().to_string();
    plan.push(&sweep_arg);
    plan.extend(["--batches-per-job", "1", "--scenes", "cornell-box"]);
    plan.extend(QUALITY);
    fovea_ok(&plan);
    let jobs = read_jobs(&sweep);
    assert_eq!(jobs.len(), 2 + 4, "2 reference parts, 4 combinations");

    // A combination run before its references fails, says why, and leaves no result.
    let run_job = jobs.iter().find(|j| j["stage"] == "run").unwrap()["index"]
        .as_u64()
        .unwrap();
    let out = fovea(&["sweep", "run", &sweep_arg, "--index", &run_job.to_string()]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("needs job 0"), "{stderr}");
    let job_dir = sweep.join(format!("jobs/{run_job:04}"));
    assert!(!job_dir.join("result").exists());
    assert!(job_dir.join("failed.json").exists());
    assert_no_attempts(&job_dir);
    let status = status_json(&sweep);
    assert_eq!(status["jobs"][run_job as usize]["state"], "failed");
    assert!(status["jobs"][run_job as usize]["reason"]
        .as_str()
        .unwrap()
        .contains("needs job 0"));
    // The merge refuses while a job is not done.
    let out = fovea(&["sweep", "merge", &sweep_arg]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("6 of 6 jobs are not done"), "{stderr}");
    assert!(!sweep.join("merged").join("cornell-box").exists());

    run_stage(&sweep, "reference");
    run_stage(&sweep, "run");
    assert!(!job_dir.join("failed.json").exists());
    let status = status_json(&sweep);
    assert_eq!(status["done"], 6, "{status}");

    // A finished job is left as it is.
    let record = std::fs::read(job_dir.join("result/job.json")).unwrap();
    let again = fovea_ok(&["sweep", "run", &sweep_arg, "--index", &run_job.to_string()]);
    assert!(again.contains("nothing to do"), "{again}");
    assert_eq!(
        std::fs::read(job_dir.join("result/job.json")).unwrap(),
        record
    );

    fovea_ok(&["sweep", "merge", &sweep_arg]);
    let one = dir.join("one");
    let mut one_process: Vec<&str> = QUALITY.to_vec();
    let one_arg = one.to_str().unwrap().to_string();
    one_process.extend(["--scene", "cornell-box", "--out", &one_arg]);
    fovea_ok(&one_process);
    assert_same_quality(&one, &sweep.join("merged/cornell-box"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A stereo study: both eyes, two stereo noises, moving camera (a reference per evaluated frame
/// and eye), 40×36, 32-spp references in one job each.
const STEREO: &[&str] = &[
    "quality",
    "--width",
    "40",
    "--height",
    "36",
    "--frames",
    "3",
    "--eval-frames",
    "2",
    "--methods",
    "cartesian",
    "--denoisers",
    "none",
    "--cameras",
    "moving",
    "--reference-spp",
    "32",
    "--rings",
    "4",
    "--eyes",
    "both",
    "--stereo-noise",
    "independent,surface",
];

#[test]
fn a_stereo_quality_sweep_merges_into_the_one_process_output() {
    let dir = temp_dir("stereo");
    let sweep = dir.join("sweep");
    let sweep_arg = sweep.to_str().unwrap().to_string();
    let mut plan = vec![
        "sweep",
        "plan",
        "--out",
        &sweep_arg,
        "--batches-per-job",
        "2",
    ];
    plan.extend(["--scenes", "cornell-box"]);
    plan.extend(STEREO);
    fovea_ok(&plan);
    let jobs = read_jobs(&sweep);
    let (references, runs): (Vec<_>, Vec<_>) = jobs.iter().partition(|j| j["stage"] == "reference");
    assert_eq!(references.len(), 2 * 2, "2 frames × 2 eyes: {references:?}");
    let eyes: Vec<&str> = references
        .iter()
        .map(|j| j["part"]["eye"].as_str().unwrap())
        .collect();
    assert_eq!(eyes, ["left", "right", "left", "right"]);
    let noises: Vec<&str> = runs
        .iter()
        .map(|j| j["part"]["noise"].as_str().unwrap())
        .collect();
    assert_eq!(noises, ["independent", "surface"]);
    for run in &runs {
        assert_eq!(run["after"].as_array().unwrap().len(), 4, "{run}");
    }
    run_stage(&sweep, "reference");
    run_stage(&sweep, "run");
    fovea_ok(&["sweep", "merge", &sweep_arg]);

    let one = dir.join("one");
    let one_arg = one.to_str().unwrap().to_string();
    let mut one_process: Vec<&str> = STEREO.to_vec();
    one_process.extend(["--scene", "cornell-box", "--out", &one_arg]);
    fovea_ok(&one_process);
    let merged = sweep.join("merged/cornell-box");
    assert_same_quality(&one, &merged);
    for name in [
        "reference_moving_right_0002.exr",
        "run_moving_cartesian_none_taa-off_noise-surface/frame_0002_right.png",
        "run_moving_cartesian_none_taa-off_noise-surface/binocular_0002.png",
    ] {
        assert!(
            std::fs::read(one.join(name)).unwrap() == std::fs::read(merged.join(name)).unwrap(),
            "{name} differs"
        );
    }
    let report = quality_json(&merged);
    assert_eq!(report["eyes"], "both");
    for run in report["runs"].as_array().unwrap() {
        assert!(run["binocular"]["frame"]["difference"].is_f64(), "{run}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// One long combination (24 frames) so a signal lands mid-run.
const LONG: &[&str] = &[
    "quality",
    "--width",
    "64",
    "--height",
    "72",
    "--frames",
    "24",
    "--eval-frames",
    "1",
    "--methods",
    "cartesian",
    "--denoisers",
    "none",
    "--cameras",
    "still",
    "--reference-spp",
    "16",
    "--rings",
    "4",
];

/// Starts job `index` and returns it once its attempt has written a frame.
fn start_job(sweep: &str, index: u64, job_dir: &Path) -> std::process::Child {
    let mut child = Command::new(env!("CARGO_BIN_EXE_fovea"))
        .args(["sweep", "run", sweep, "--index", &index.to_string()])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = Instant::now();
    while !attempt_has_frame(job_dir, child.id()) {
        assert!(
            child.try_wait().unwrap().is_none(),
            "the job ended before a frame was seen"
        );
        assert!(started.elapsed() < Duration::from_secs(120));
        std::thread::sleep(Duration::from_millis(20));
    }
    child
}

#[test]
fn killed_and_stopped_jobs_leave_no_result_and_run_again_cleanly() {
    let dir = temp_dir("kill");
    let sweep = dir.join("sweep");
    let sweep_arg = sweep.to_str().unwrap().to_string();
    let mut plan = vec!["sweep", "plan", "--out", &sweep_arg];
    plan.extend(LONG);
    fovea_ok(&plan);
    run_stage(&sweep, "reference");
    let run_job = 1;
    let job_dir = sweep.join("jobs/0001");

    // SIGKILL: no chance to clean up; the job is missing, its dead attempt named.
    let mut child = start_job(&sweep_arg, run_job, &job_dir);
    child.kill().unwrap();
    child.wait().unwrap();
    let status = status_json(&sweep);
    let killed = &status["jobs"][run_job as usize];
    assert_eq!(killed["state"], "missing", "{killed}");
    assert!(
        killed["reason"]
            .as_str()
            .unwrap()
            .contains("attempt stopped"),
        "{killed}"
    );
    assert!(!job_dir.join("result").exists());
    let err = fovea_err(&["sweep", "merge", &sweep_arg]);
    assert!(err.contains("1 of 2 jobs are not done"), "{err}");

    // SIGTERM (what scancel sends): the job stops after the frame in flight, removes its attempt
    // (and the dead one) and records why.
    let child = start_job(&sweep_arg, run_job, &job_dir);
    let kill = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let end = child.wait_with_output().unwrap();
    assert_eq!(end.status.code(), Some(128 + 15), "{end:?}");
    assert!(!job_dir.join("result").exists());
    assert_no_attempts(&job_dir);
    let status = status_json(&sweep);
    let stopped = &status["jobs"][run_job as usize];
    assert_eq!(stopped["state"], "failed", "{stopped}");
    assert!(
        stopped["reason"].as_str().unwrap().contains("SIGTERM"),
        "{stopped}"
    );

    // Run again: done, the failure record gone, and the merge has all it needs.
    run_stage(&sweep, "run");
    assert!(job_dir.join("result/job.json").exists());
    assert!(!job_dir.join("failed.json").exists());
    assert_no_attempts(&job_dir);
    fovea_ok(&["sweep", "merge", &sweep_arg]);
    let merged = sweep.join("merged/cornell-box");
    assert!(merged.join("quality.json").exists());
    assert!(merged
        .join("run_still_cartesian_none_taa-off/frame_0023.png")
        .exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Whether process `pid`'s attempt (`.attempt-<host>-<pid>`) holds a rendered frame.
fn attempt_has_frame(job_dir: &Path, pid: u32) -> bool {
    let Ok(entries) = std::fs::read_dir(job_dir) else {
        return false;
    };
    entries.filter_map(|e| e.ok()).any(|e| {
        let name = e.file_name().to_string_lossy().into_owned();
        name.starts_with(".attempt-")
            && name.ends_with(&format!("-{pid}"))
            && holds_frame(&e.path(), 2)
    })
}

/// Whether `dir` or a folder up to `depth` levels below it holds a rendered frame: a run folder
/// in an attempt, and the staging folder inside it where `fovea render` writes until it ends.
fn holds_frame(dir: &Path, depth: u32) -> bool {
    dir.join("frame_0000.png").exists()
        || (depth > 0
            && std::fs::read_dir(dir).is_ok_and(|entries| {
                entries
                    .filter_map(|e| e.ok())
                    .any(|e| e.path().is_dir() && holds_frame(&e.path(), depth - 1))
            }))
}

#[test]
fn a_reference_split_into_sample_batches_merges_into_the_same_bytes() {
    let dir = temp_dir("reference");
    let sweep = dir.join("sweep");
    let sweep_arg = sweep.to_str().unwrap().to_string();
    // 48 samples: three batches, summed (0 + 1) + 2 by both.
    let reference = [
        "reference",
        "--width",
        "64",
        "--height",
        "72",
        "--spp",
        "48",
        "--preview",
    ];
    let mut plan = vec![
        "sweep",
        "plan",
        "--out",
        &sweep_arg,
        "--batches-per-job",
        "1",
    ];
    plan.extend(reference);
    fovea_ok(&plan);
    assert_eq!(read_jobs(&sweep).len(), 3);
    for i in [2, 0, 1] {
        fovea_ok(&["sweep", "run", &sweep_arg, "--index", &i.to_string()]);
    }
    fovea_ok(&["sweep", "merge", &sweep_arg]);
    let one = dir.join("one.exr");
    let one_arg = one.to_str().unwrap().to_string();
    let mut one_process = reference.to_vec();
    one_process.extend(["--out", &one_arg]);
    fovea_ok(&one_process);
    let merged = sweep.join("merged/cornell-box/reference.exr");
    assert!(
        std::fs::read(&merged).unwrap() == std::fs::read(&one).unwrap(),
        "{} and {} differ",
        merged.display(),
        one.display()
    );
    assert!(
        std::fs::read(merged.with_extension("png")).unwrap()
            == std::fs::read(one.with_extension("png")).unwrap(),
        "the previews differ"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// fovea in the repository root (where the committed replay traces and baselines are named from).
fn fovea_in_repo(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fovea"))
        .current_dir(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(".."))
        .args(args)
        .output()
        .unwrap()
}

/// A JSON file without the fields measured from GPU times (`cost_ratio`).
fn without_costs(path: &Path) -> serde_json::Value {
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    for trace in v["traces"].as_array_mut().unwrap() {
        trace["cost_ratio"] = serde_json::Value::Null;
    }
    v
}

#[test]
fn a_replay_sweep_merges_into_the_one_process_report_and_exit_status() {
    let dir = temp_dir("replay");
    let sweep = dir.join("sweep");
    let sweep_arg = sweep.to_str().unwrap().to_string();
    // Two committed baselines and a planted regression (as tools/tests/replay.rs): failing frames,
    // their baseline and FLIP pictures, exit status 1.
    let replay = [
        "replay",
        "sim:1",
        "config/gaze/example_trace.csv",
        "--baseline",
        "tests/replay/baseline",
        "--max-depth",
        "2",
        "--validation",
    ];
    let mut plan = vec!["sweep", "plan", "--out", &sweep_arg];
    plan.extend(replay);
    let planned = fovea_in_repo(&plan);
    assert!(planned.status.success(), "{planned:?}");
    assert_eq!(read_jobs(&sweep).len(), 2, "one job per trace");
    // The jobs run from any folder: the plan records where its paths resolve from.
    for index in ["1", "0"] {
        fovea_ok(&["sweep", "run", &sweep_arg, "--index", index]);
    }
    let merged = fovea(&["sweep", "merge", &sweep_arg]);
    assert_eq!(merged.status.code(), Some(1), "{merged:?}");
    let stderr = String::from_utf8_lossy(&merged.stderr);
    assert!(stderr.contains("outside the tolerances"), "{stderr}");

    let one = dir.join("one");
    let one_arg = one.to_str().unwrap().to_string();
    let mut one_process = replay.to_vec();
    one_process.extend(["--out", &one_arg]);
    let ran = fovea_in_repo(&one_process);
    assert_eq!(ran.status.code(), Some(1), "{ran:?}");

    let merged = sweep.join("merged/cornell-box");
    assert_eq!(
        without_costs(&merged.join("replay.json")),
        without_costs(&one.join("replay.json"))
    );
    let no_costs = |dir: &Path| -> String {
        std::fs::read_to_string(dir.join("replay.md"))
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with("Cost now / baseline"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    let report = no_costs(&merged);
    assert!(report.contains("REGRESSION"), "{report}");
    assert_eq!(report, no_costs(&one));
    let mut compared = 0;
    // Run folders are named by the baseline folder: `run_<stem>-<SHA-256 prefix>`.
    let runs: Vec<String> = std::fs::read_dir(&one)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("run_sim-1-") || n.starts_with("run_example_trace-"))
        .collect();
    assert_eq!(runs.len(), 2, "{runs:?}");
    for run in &runs {
        for entry in std::fs::read_dir(one.join(run)).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if !name.starts_with("frame_") {
                continue;
            }
            assert!(
                std::fs::read(&path).unwrap()
                    == std::fs::read(merged.join(run).join(&name)).unwrap(),
                "{run}/{name} differs"
            );
            compared += 1;
        }
    }
    assert!(compared > 16, "only {compared} files compared");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_plans_are_refused_naming_the_file_and_field() {
    let dir = temp_dir("bad");
    let missing = dir.join("nowhere");
    let err = fovea_err(&["sweep", "status", missing.to_str().unwrap()]);
    assert!(
        err.contains("sweep folder") && err.contains("does not exist"),
        "{err}"
    );
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let err = fovea_err(&["sweep", "run", empty.to_str().unwrap(), "--index", "0"]);
    assert!(err.contains("sweep.json"), "{err}");

    let sweep = dir.join("sweep");
    let sweep_arg = sweep.to_str().unwrap().to_string();
    let mut plan = vec!["sweep", "plan", "--out", &sweep_arg];
    plan.extend(QUALITY);
    fovea_ok(&plan);
    // Planning again into the same folder is refused.
    let err = fovea_err(&plan);
    assert!(err.contains("not empty"), "{err}");
    // The command is checked when planned.
    let bad_method = fovea_err(&[
        "sweep",
        "plan",
        "--out",
        dir.join("other").to_str().unwrap(),
        "quality",
        "--methods",
        "nonsense",
    ]);
    assert!(bad_method.contains("--methods nonsense"), "{bad_method}");
    let not_quality = fovea_err(&[
        "sweep",
        "plan",
        "--out",
        dir.join("other").to_str().unwrap(),
        "render",
        "--frames",
        "2",
    ]);
    assert!(not_quality.contains("is none of them"), "{not_quality}");
    let update = fovea_err(&[
        "sweep",
        "plan",
        "--out",
        dir.join("other").to_str().unwrap(),
        "replay",
        "sim:1",
        "--baseline",
        "tests/replay/baseline",
        "--update-baseline",
    ]);
    assert!(
        update.contains("--update-baseline: a sweep compares"),
        "{update}"
    );
    assert!(!dir.join("other").exists());

    // An edited jobs file: the line and the field.
    let jobs_path = sweep.join("jobs.jsonl");
    let original = std::fs::read_to_string(&jobs_path).unwrap();
    let mut lines: Vec<String> = original.lines().map(str::to_string).collect();
    let last = lines.len() - 1;
    lines[last] = lines[last].replace("\"svgf\"", "\"bmfr\"");
    std::fs::write(&jobs_path, lines.join("\n") + "\n").unwrap();
    let err = fovea_err(&["sweep", "status", &sweep_arg]);
    assert!(
        err.contains(&format!(
            "jobs.jsonl line {} (job {last}): field `args`",
            last + 1
        )),
        "{err}"
    );
    std::fs::write(&jobs_path, &original).unwrap();

    // Another build's plan: run and merge refuse, status says so.
    let plan_path = sweep.join("sweep.json");
    let text = std::fs::read_to_string(&plan_path).unwrap();
    let mut value: serde_json::Value = serde_json::from_str(&text).unwrap();
    value["commit"] = "0123456789abcdef".into();
    std::fs::write(&plan_path, serde_json::to_string_pretty(&value).unwrap()).unwrap();
    let err = fovea_err(&["sweep", "run", &sweep_arg, "--index", "0"]);
    assert!(
        err.contains("sweep.json: field `commit` is 0123456789abcdef"),
        "{err}"
    );
    let err = fovea_err(&["sweep", "merge", &sweep_arg]);
    assert!(err.contains("field `commit`"), "{err}");
    let status = fovea_ok(&["sweep", "status", &sweep_arg]);
    assert!(
        status.contains("planned by the fovea of commit 0123456789abcdef"),
        "{status}"
    );

    // A plan whose studies do not follow from its command, and one missing a field.
    value["commit"] = serde_json::from_str::<serde_json::Value>(&text).unwrap()["commit"].clone();
    value["studies"][0]["args"][1] = "--width=65".into();
    std::fs::write(&plan_path, serde_json::to_string_pretty(&value).unwrap()).unwrap();
    let err = fovea_err(&["sweep", "status", &sweep_arg]);
    assert!(err.contains("sweep.json: field `studies`"), "{err}");
    value.as_object_mut().unwrap().remove("workdir");
    std::fs::write(&plan_path, serde_json::to_string_pretty(&value).unwrap()).unwrap();
    let err = fovea_err(&["sweep", "status", &sweep_arg]);
    assert!(
        err.contains("sweep.json") && err.contains("missing field `workdir`"),
        "{err}"
    );

    // No such job.
    std::fs::write(&plan_path, &text).unwrap();
    let err = fovea_err(&["sweep", "run", &sweep_arg, "--index", "99"]);
    assert!(err.contains("there is no job 99"), "{err}");
    let err = fovea_err(&["sweep", "run", &sweep_arg]);
    assert!(err.contains("SLURM_ARRAY_TASK_ID"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

// ---- Slurm -------------------------------------------------------------------------------------

/// 2 scenes × 2 methods × 2 denoisers at 64×72, still camera, 32-spp references in 2 jobs each.
const SLURM_QUALITY: &[&str] = &[
    "quality",
    "--width",
    "64",
    "--height",
    "72",
    "--frames",
    "4",
    "--eval-frames",
    "2",
    "--methods",
    "vp,cartesian",
    "--denoisers",
    "none,svgf",
    "--cameras",
    "still",
    "--reference-spp",
    "32",
    "--rings",
    "4",
];

/// Where Slurm is installed but not the cluster: scripts/slurm/setup's exit status.
const SLURM_MISSING: i32 = 3;

/// The one-node cluster of scripts/slurm/setup, started if it is not running: its SLURM_CONF,
/// or why there is none (Slurm or root missing).
fn slurm_cluster() -> Result<String, String> {
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scripts/slurm/setup");
    let out = Command::new(&script)
        .arg("--print-env")
        .output()
        .map_err(|e| format!("{}: {e}", script.display()))?;
    let stderr = String::from_utf8_lossy(&out.stderr).trim().to_string();
    if out.status.code() == Some(SLURM_MISSING) {
        return Err(stderr);
    }
    assert!(
        out.status.success(),
        "{} failed ({}): {stderr}",
        script.display(),
        out.status
    );
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let conf = stdout
        .lines()
        .find_map(|l| l.strip_prefix("export SLURM_CONF="))
        .unwrap_or_else(|| panic!("{} printed no SLURM_CONF: {stdout}", script.display()));
    Ok(conf.trim_matches('\'').to_string())
}

/// A Slurm client command against the test's cluster.
fn slurm(tool: &str, conf: &str) -> Command {
    let mut command = Command::new(tool);
    command.env("SLURM_CONF", conf);
    command
}

/// Runs scripts/sweep-slurm; returns the job array ids per stage it printed.
fn sweep_slurm(conf: &str, sweep: &Path, extra: &[&str]) -> Vec<(String, String)> {
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scripts/sweep-slurm");
    let out = slurm(script.to_str().unwrap(), conf)
        .arg(sweep)
        .args(extra)
        .env("FOVEA", env!("CARGO_BIN_EXE_fovea"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(
        out.status.success(),
        "scripts/sweep-slurm {} {extra:?}: {stderr}\n{}",
        sweep.display(),
        String::from_utf8_lossy(&out.stdout)
    );
    stderr
        .lines()
        .filter_map(|l| {
            let rest = l.strip_prefix("sweep-slurm: stage ")?;
            let (stage, rest) = rest.split_once(": job array ")?;
            Some((stage.to_string(), rest.split(' ').next()?.to_string()))
        })
        .collect()
}

/// Waits until Slurm lists none of `jobs` as pending or running.
fn wait_for_slurm(conf: &str, jobs: &[String], limit: Duration) {
    let started = Instant::now();
    loop {
        let out = slurm("squeue", conf)
            .args(["-h", "-o", "%i %T", "-j", &jobs.join(",")])
            .output()
            .unwrap();
        let listed = String::from_utf8_lossy(&out.stdout).trim().to_string();
        if !out.status.success() || listed.is_empty() {
            return;
        }
        assert!(
            started.elapsed() < limit,
            "Slurm jobs still queued after {limit:?}: {listed}"
        );
        std::thread::sleep(Duration::from_millis(200));
    }
}

#[test]
fn a_sweep_through_slurm_is_cancelled_mid_run_rerun_and_merges_into_one_process_output() {
    let conf = match slurm_cluster() {
        Ok(conf) => conf,
        Err(why) => {
            assert!(
                std::env::var("FOVEA_REQUIRE_SLURM").as_deref() != Ok("1"),
                "FOVEA_REQUIRE_SLURM=1 but scripts/slurm/setup starts no cluster: {why}"
            );
            eprintln!("skipped: no Slurm cluster ({why})");
            return;
        }
    };
    let dir = temp_dir("slurm");
    let sweep = dir.join("sweep");
    let sweep_arg = sweep.to_str().unwrap().to_string();
    let mut plan = vec![
        "sweep",
        "plan",
        "--out",
        &sweep_arg,
        "--batches-per-job",
        "1",
    ];
    plan.extend(["--scenes", "cornell-box,stress"]);
    plan.extend(SLURM_QUALITY);
    fovea_ok(&plan);
    let jobs = read_jobs(&sweep);
    assert_eq!(jobs.len(), 2 * 2 + 2 * 4);

    // Submitted whole; the run stage cancelled once one of its jobs is mid-run.
    let arrays = sweep_slurm(&conf, &sweep, &[]);
    let run_arrays: Vec<String> = arrays
        .iter()
        .filter(|(stage, _)| stage == "run")
        .map(|(_, id)| id.clone())
        .collect();
    assert_eq!(arrays.len(), 2, "{arrays:?}");
    let run_dirs: Vec<PathBuf> = jobs
        .iter()
        .filter(|j| j["stage"] == "run")
        .map(|j| sweep.join(j["out"].as_str().unwrap()))
        .collect();
    let started = Instant::now();
    let mid_run = loop {
        let found = run_dirs.iter().find(|d| {
            std::fs::read_dir(d).is_ok_and(|entries| {
                entries.filter_map(|e| e.ok()).any(|e| {
                    e.file_name().to_string_lossy().starts_with(".attempt-")
                        && holds_frame(&e.path(), 2)
                })
            })
        });
        if let Some(d) = found {
            break d.clone();
        }
        assert!(
            started.elapsed() < Duration::from_secs(300),
            "no run job started within 300 s (logs: {})",
            sweep.join("slurm").display()
        );
        std::thread::sleep(Duration::from_millis(20));
    };
    let cancel = slurm("scancel", &conf).args(&run_arrays).status().unwrap();
    assert!(cancel.success());
    let all: Vec<String> = arrays.iter().map(|(_, id)| id.clone()).collect();
    wait_for_slurm(&conf, &all, Duration::from_secs(120));
    // The merge depended on the cancelled stage: it never ran.
    std::thread::sleep(Duration::from_secs(1));
    assert!(!sweep.join("merged").exists());
    let status = status_json(&sweep);
    assert_eq!(status["running"], 0, "{status}");
    assert!(status["done"].as_u64().unwrap() < 12, "{status}");
    // scancel sends SIGTERM: a running job stops at its next check (also while still starting
    // up), removes its attempt and records the signal.
    let stopped =
        status["jobs"].as_array().unwrap().iter().any(|j| {
            j["state"] == "failed" && j["reason"].as_str().unwrap_or("").contains("SIGTERM")
        });
    assert!(
        stopped,
        "no job was stopped mid-run by the scancel ({} was seen mid-run): {status}",
        mid_run.display()
    );
    for dir in &run_dirs {
        // Whole or absent: a result holds its record; no attempt is left behind.
        if dir.join("result").exists() {
            assert!(dir.join("result/job.json").exists(), "{}", dir.display());
        }
        if dir.exists() {
            assert_no_attempts(dir);
        }
    }

    // Submitted again: only what is missing runs, then the merge.
    let again = sweep_slurm(&conf, &sweep, &["--wait"]);
    assert!(
        again.iter().all(|(stage, _)| stage == "run"),
        "the references were done: {again:?}"
    );
    assert_eq!(status_json(&sweep)["done"], 12);
    for scene in ["cornell-box", "stress"] {
        let one = dir.join(format!("one-{scene}"));
        let one_arg = one.to_str().unwrap().to_string();
        let mut one_process: Vec<&str> = SLURM_QUALITY.to_vec();
        one_process.extend(["--scene", scene, "--out", &one_arg]);
        fovea_ok(&one_process);
        assert_same_quality(&one, &sweep.join("merged").join(scene));
    }
    let _ = std::fs::remove_dir_all(&dir);
}
