//! The `fovea` binary as a process: signals and failing writes, which a library call cannot show
//! (the handler is installed by `main`, and a file-size limit must apply to the whole process).
//! These live in the tools package because only its own tests get the binary built
//! (`CARGO_BIN_EXE_fovea`). Validation is on (`--validation`; debug builds force it anyway).

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fovea-process-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn cornell() -> String {
    repo().join("scenes/cornell-box.gltf").display().to_string()
}

fn wait_with_timeout(child: &mut Child, limit: Duration) -> std::process::ExitStatus {
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("fovea did not exit within {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

fn frames_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("frame_"))
        .collect();
    v.sort();
    v
}

/// Starts a long render, sends `signal` once a few frames exist, and checks the run stopped after
/// a complete frame with an honest report and exit status 128 + signal.
fn interrupt_render(signal: &str, number: i32) {
    let out = temp_dir(&format!("signal-{signal}"));
    let mut child = Command::new(env!("CARGO_BIN_EXE_fovea"))
        .args([
            "render",
            "--scene",
            &cornell(),
            "--method",
            "cartesian",
            "--width",
            "16",
            "--height",
            "16",
        ])
        .args([
            "--frames",
            "100000",
            "--gaze",
            "center",
            "--validation",
            "--out",
        ])
        .arg(&out)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !out.join("frame_0002.png").exists() {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no frames after 2 minutes"
        );
        assert!(child.try_wait().unwrap().is_none(), "fovea exited early");
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .unwrap()
        .success());
    let status = wait_with_timeout(&mut child, Duration::from_secs(60));
    let mut stderr = String::new();
    std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut stderr).unwrap();
    assert_eq!(
        status.code(),
        Some(128 + number),
        "exit status; stderr: {stderr}"
    );
    assert!(
        stderr.contains(&format!("interrupted by SIG{signal}")),
        "{stderr}"
    );

    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["interrupted"], true);
    let frames = frames_in(&out);
    let reported = report["frames"].as_u64().unwrap() as usize;
    assert!((3..100_000).contains(&reported), "{reported}");
    assert_eq!(
        frames.len(),
        reported,
        "every reported frame is on disk, nothing more: {frames:?}"
    );
    assert_eq!(report["gaze"].as_array().unwrap().len(), reported);
    let last = out.join(frames.last().unwrap());
    assert_eq!(
        image::open(&last).unwrap().width(),
        16,
        "the last frame is complete"
    );
    let leftovers: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporaries left: {leftovers:?}");
}

#[test]
fn sigint_finishes_the_frame_writes_an_interrupted_report_and_exits_130() {
    interrupt_render("INT", 2);
}

#[test]
fn sigterm_does_the_same_with_exit_143() {
    interrupt_render("TERM", 15);
}

/// `fovea reference --force` whose write fails midway (a 4 KiB file-size limit; SIGXFSZ ignored
/// so the write returns EFBIG): the old file is untouched and no temporary is left behind.
#[test]
fn a_failing_forced_write_keeps_the_old_reference() {
    let dir = temp_dir("efbig");
    let target = dir.join("ref.exr");
    std::fs::write(&target, "OLD REFERENCE").unwrap();
    let fovea = env!("CARGO_BIN_EXE_fovea");
    let script = format!(
        "trap '' XFSZ; ulimit -f 4; exec '{fovea}' reference --scene '{}' --width 64 --height 64 --spp 1 --validation --force --out '{}'",
        cornell(),
        target.display()
    );
    let output = Command::new("sh")
        .args(["-c", &script])
        .env("MESA_SHADER_CACHE_DISABLE", "true") // nothing else in the process writes files
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        !output.status.success(),
        "the write must fail under the limit: {stderr}"
    );
    assert!(
        stderr.contains("writing")
            && stderr.contains("ref.exr")
            && stderr.contains("File too large"),
        "the EXR write itself failed: {stderr}"
    );
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "OLD REFERENCE");
    let names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, vec!["ref.exr"], "no temporary left behind");
    // Without the limit the same command replaces it.
    let status = Command::new(fovea)
        .args([
            "reference",
            "--scene",
            &cornell(),
            "--width",
            "64",
            "--height",
            "64",
            "--spp",
            "1",
            "--validation",
            "--force",
            "--out",
        ])
        .arg(&target)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success());
    assert_ne!(std::fs::read(&target).unwrap(), b"OLD REFERENCE");
}
