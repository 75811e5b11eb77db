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
    // Frames are written into the run's hidden staging folder until the run completes.
    let staged_frame = || {
        std::fs::read_dir(&out)
            .unwrap()
            .filter_map(|e| e.ok())
            .any(|e| {
                e.file_name().to_string_lossy().starts_with(".fovea-run.")
                    && e.path().join("frame_0002.png").exists()
            })
    };
    while !staged_frame() {
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
        .filter(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            name.ends_with(".tmp") || name.starts_with(".fovea-run.")
        })
        .collect();
    assert!(
        leftovers.is_empty(),
        "temporaries or staging left: {leftovers:?}"
    );
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

/// `fovea render` into a folder holding an earlier run, failing midway as on a full disk (a
/// 32 KiB file-size limit (64 blocks): the PNG frames fit, the first EXR does not). The new frame 0 was
/// written beside the old report and frames; the earlier run must stay exactly as it was, with
/// no staging folder left.
#[test]
fn a_rerun_that_fails_midway_leaves_the_earlier_run_whole() {
    let out = temp_dir("rerun-full");
    let fovea = env!("CARGO_BIN_EXE_fovea");
    let render = |extra: &str| {
        format!(
            "exec '{fovea}' render --scene '{}' --method cartesian --width 64 --height 72 --frames 2 --gaze center --validation --out '{}' {extra}",
            cornell(),
            out.display()
        )
    };
    let first = Command::new("sh")
        .args(["-c", &render("--seed 1")])
        .output()
        .unwrap();
    assert!(
        first.status.success(),
        "{}",
        String::from_utf8_lossy(&first.stderr)
    );
    let snapshot = || {
        let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap())
            .filter(|e| e.file_name() != ".fovea.lock")
            .map(|e| {
                let name = e.file_name().to_string_lossy().into_owned();
                let bytes = std::fs::read(e.path()).unwrap_or_default();
                (name, bytes)
            })
            .collect();
        files.sort();
        files
    };
    let before = snapshot();
    assert_eq!(
        before.iter().map(|f| f.0.as_str()).collect::<Vec<_>>(),
        [
            "frame_0000.png",
            "frame_0001.png",
            "overview.png",
            "report.json"
        ]
    );
    let full = Command::new("sh")
        .args([
            "-c",
            &format!("trap '' XFSZ; ulimit -f 64; {}", render("--seed 2 --exr")),
        ])
        .env("MESA_SHADER_CACHE_DISABLE", "true")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&full.stderr);
    assert!(!full.status.success(), "the EXR write must fail: {stderr}");
    assert!(stderr.contains("File too large"), "{stderr}");
    assert!(
        snapshot() == before,
        "the earlier run changed: {:?}",
        snapshot().iter().map(|f| &f.0).collect::<Vec<_>>()
    );
}

/// A FIFO, a device or a huge file as the OpenXR runtime manifest: the loader blocked in open()
/// (swallowing the first SIGTERM) or read /dev/zero into 13.7 GB. Refused before it looks.
#[test]
fn the_runtime_manifest_is_a_regular_file_of_sane_size() {
    let dir = temp_dir("xr-manifest");
    let fifo = dir.join("runtime.json");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let big = dir.join("big.json");
    std::fs::write(&big, vec![b' '; 1 << 20]).unwrap();
    for (manifest, needle) in [
        (fifo.as_path(), "FIFO"),
        (Path::new("/dev/zero"), "a device"),
        (big.as_path(), "byte limit"),
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_fovea"))
            .args(["xr", "--scene", &cornell(), "--frames", "1", "--out"])
            .arg(dir.join("out"))
            .env("XR_RUNTIME_JSON", manifest)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let status = wait_with_timeout(&mut child, Duration::from_secs(60));
        let mut stderr = String::new();
        std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut stderr).unwrap();
        assert!(!status.success());
        assert!(
            stderr.contains("XR_RUNTIME_JSON") && stderr.contains(needle),
            "{manifest:?}: {stderr}"
        );
    }
}

/// A SIGTERM while start-up is blocked (here the OpenXR loader opening a runtime library that is a
/// FIFO) ends the process at once with 143; it was taken as a request to stop cleanly that
/// nothing looked at, and the process stayed blocked.
#[test]
fn a_signal_during_start_up_ends_the_process() {
    let dir = temp_dir("xr-startup");
    let library = dir.join("libruntime.so");
    assert!(Command::new("mkfifo")
        .arg(&library)
        .status()
        .unwrap()
        .success());
    let manifest = dir.join("runtime.json");
    std::fs::write(
        &manifest,
        format!(
            "{{\"file_format_version\": \"1.0.0\", \"runtime\": {{\"library_path\": \"{}\"}}}}",
            library.display()
        ),
    )
    .unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_fovea"))
        .args(["xr", "--scene", &cornell(), "--frames", "1", "--out"])
        .arg(dir.join("out"))
        .env("XR_RUNTIME_JSON", &manifest)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Start-up reaches the loader within seconds; the child then waits for a writer forever.
    std::thread::sleep(Duration::from_secs(3));
    assert!(
        child.try_wait().unwrap().is_none(),
        "fovea exited before blocking"
    );
    assert!(Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap()
        .success());
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > Duration::from_secs(10) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("SIGTERM did not end fovea blocked in start-up");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    assert_eq!(status.code(), Some(143));
}

/// `fovea view --screenshot FILE` replaced an existing file without `--force`; it is refused
/// before a window opens (so no display is needed to see it).
#[test]
fn a_view_screenshot_does_not_replace_a_file_without_force() {
    let dir = temp_dir("screenshot");
    let shot = dir.join("shot.png");
    std::fs::write(&shot, "MY PICTURE").unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_fovea"))
        .args([
            "view",
            "--scene",
            &cornell(),
            "--frames",
            "1",
            "--screenshot",
        ])
        .arg(&shot)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success());
    assert!(
        stderr.contains("shot.png already exists; pass --force"),
        "{stderr}"
    );
    assert_eq!(std::fs::read_to_string(&shot).unwrap(), "MY PICTURE");
}

/// `gen-scene large --min-triangles 1e11` took 18.8 GB and wrote a file fovea could not load:
/// the count is bounded by the loader's triangle budget, checked before anything is built.
#[test]
fn gen_scene_triangles_are_bounded_by_the_loader_budget() {
    let dir = temp_dir("gen-scene");
    let out = dir.join("large.gltf");
    let output = Command::new("sh")
        .args([
            "-c",
            &format!(
                "ulimit -v 4000000; exec '{}' gen-scene large --min-triangles 100000000000 --out '{}'",
                env!("CARGO_BIN_EXE_fovea"),
                out.display()
            ),
        ])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("--min-triangles 100000000000 must be in 1..=4000000")
            && stderr.contains("FOVEA_MAX_TRIANGLES"),
        "{stderr}"
    );
    assert!(!out.exists());
}

/// A camera path file was parsed whole: the TOML parser took up to 75 × its size (a 64 MiB file
/// of tiny values, 5 GB) before the key count was checked. Under a 1 GB address-space limit a
/// 16 MiB file of that kind is refused with the file and line named, not aborted.
#[test]
fn a_camera_path_file_is_parsed_within_bounded_memory() {
    let dir = temp_dir("camera-path");
    let path = dir.join("tiny_values.toml");
    let mut text = String::from("[[key]]\ntime = 0\nposition = [0, 1, 2]\nlook = [0, 0, 0]\n");
    text += "[[key]]\ntime = 1\nposition = [0, 1, 2]\nlook = [0, 0, 0]\nfov = [";
    text += &"0,".repeat(8 << 20);
    text += "0]\n";
    std::fs::write(&path, text).unwrap();
    let output = Command::new("sh")
        .args([
            "-c",
            &format!(
                "ulimit -v 1000000; exec '{}' render --scene '{}' --camera-path '{}' --frames 1 --out '{}'",
                env!("CARGO_BIN_EXE_fovea"),
                cornell(),
                path.display(),
                dir.join("out").display()
            ),
        ])
        .output()
        .unwrap();
    let _ = std::fs::remove_dir_all(&dir); // 16 MiB
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("tiny_values.toml: invalid camera path at line 5")
            && stderr.contains("at most 65536"),
        "{stderr}"
    );
}
