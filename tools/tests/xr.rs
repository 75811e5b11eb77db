//! `fovea xr` against a real OpenXR runtime: Monado built by `scripts/build-monado` with fovea's
//! simulated eye tracker (scripts/monado/0002-simulated-eye-tracker.patch), its gaze a known
//! function of CLOCK_MONOTONIC time (`expected` mirrors the patch, as in hal/tests/openxr.rs).
//! `scripts/test` puts the runtime in the environment and sets FOVEA_REQUIRE_OPENXR; without a
//! runtime these tests say why and pass, unless that variable is set.

use fovea_hal::{Eye, HmdDescription};
use glam::{Vec2, Vec3};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

static LOCK: Mutex<()> = Mutex::new(());
const MS: i64 = 1_000_000;
const CYCLE: i64 = 5_000 * MS;

/// The patch's gaze at monotonic measurement time `s`: (direction, valid).
fn expected(s: i64) -> (Vec3, bool) {
    let phase = |p: i64| (s % p) as f64 / p as f64;
    let az = 20f64.to_radians() * (std::f64::consts::TAU * phase(2_000 * MS)).sin();
    let el = 10f64.to_radians() * (std::f64::consts::TAU * phase(3_000 * MS)).sin();
    let blink = (4_000 * MS..4_200 * MS).contains(&(s % CYCLE));
    (
        Vec3::new(
            (az.sin() * el.cos()) as f32,
            el.sin() as f32,
            (-az.cos() * el.cos()) as f32,
        ),
        !blink,
    )
}

fn angle_deg(a: Vec3, b: Vec3) -> f32 {
    let (a, b) = (a.as_dvec3(), b.as_dvec3());
    a.cross(b).length().atan2(a.dot(b)).to_degrees() as f32
}

/// The lock when a runtime is configured; `None` (after saying why) when there is none and none
/// is required.
fn runtime() -> Option<MutexGuard<'static, ()>> {
    let guard = LOCK.lock().unwrap_or_else(|p| p.into_inner());
    let present = std::env::var_os("XR_RUNTIME_JSON").is_some_and(|p| Path::new(&p).is_file());
    if !present {
        assert!(
            std::env::var_os("FOVEA_REQUIRE_OPENXR").is_none(),
            "FOVEA_REQUIRE_OPENXR is set but XR_RUNTIME_JSON names no runtime"
        );
        eprintln!("skipped: no OpenXR runtime (XR_RUNTIME_JSON); scripts/test builds Monado and runs these tests");
        return None;
    }
    Some(guard)
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fovea-xr-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `fovea` with Monado's test settings; `tracker`: the simulated eye tracker on or off.
fn fovea(args: &[&str], tracker: bool) -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_fovea"));
    cmd.args(args)
        .env("XRT_COMPOSITOR_NULL", "1")
        .env("SIMULATED_ENABLE", "1")
        .env("SIMULATED_EYE_TRACKER", if tracker { "on" } else { "off" })
        .env("XRT_LOG", "error")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    cmd
}

fn run(cmd: &mut Command) -> Output {
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "fovea failed: {}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn json(path: &Path) -> Value {
    serde_json::from_str(
        &std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())),
    )
    .unwrap()
}

fn rows(dir: &Path) -> Vec<Value> {
    std::fs::read_to_string(dir.join("frames.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

fn vec3(v: &Value) -> Vec3 {
    let a: Vec<f32> = v
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap() as f32)
        .collect();
    Vec3::new(a[0], a[1], a[2])
}

/// 60 rendered frames, both eyes, the runtime's views and gaze at the predicted display time,
/// validation on; the recorded gaze replays through `fovea render`.
#[test]
fn sixty_frames_on_the_runtime_with_gaze_at_display_time() {
    let Some(_lock) = runtime() else { return };
    let (out, side) = (temp_dir("sixty"), temp_dir("sixty-side"));
    let (trace, shot) = (side.join("gaze.csv"), side.join("shot.png"));
    let started = Instant::now();
    run(fovea(
        &[
            "xr",
            "--frames",
            "60",
            "--scale",
            "0.25",
            "--validation",
            "--out",
        ],
        true,
    )
    .arg(&out)
    .arg("--record")
    .arg(&trace)
    .arg("--screenshot")
    .arg(&shot));
    eprintln!(
        "fovea xr --frames 60: {:.0} s",
        started.elapsed().as_secs_f64()
    );
    let report = json(&out.join("report.json"));
    assert!(
        report["runtime"]["name"]
            .as_str()
            .unwrap()
            .contains("Monado"),
        "{report}"
    );
    assert_eq!(report["frames_rendered"], 60);
    assert_eq!(report["session_end"], "exiting");
    assert_eq!(report["interrupted"], false);
    assert_eq!(report["gaze_source"], "openxr");
    for figure in ["recommended_size", "fov", "eye_offsets", "refresh_hz"] {
        assert_eq!(report["figure_sources"][figure], "runtime", "{figure}");
    }
    let rows = rows(&out);
    assert_eq!(
        rows.len() as u64,
        report["frames"].as_u64().unwrap(),
        "one row per frame of the loop"
    );
    assert_eq!(report["frames_logged"], report["frames"]);
    let offset = report["monotonic_minus_xr_time_ns"]
        .as_i64()
        .expect("Monado converts timespecs");
    let mut last_time = i64::MIN;
    let (mut rendered, mut live, mut orientations) = (0, 0, Vec::new());
    for (i, row) in rows.iter().enumerate() {
        assert_eq!(row["frame"], i as u64);
        let t = row["predicted_display_time_ns"].as_i64().unwrap();
        assert!(t > last_time, "display times increase");
        last_time = t;
        if row["rendered"] != true {
            continue;
        }
        rendered += 1;
        let views = row["views"].as_array().unwrap();
        assert_eq!(views.len(), 2);
        for v in views {
            // Monado's simulated HMD: ±42.5° × ±44.6° per eye.
            let fov = &v["fov"];
            let tangents = [
                fov["left"].as_f64().unwrap(),
                fov["right"].as_f64().unwrap(),
                fov["down"].as_f64().unwrap(),
                fov["up"].as_f64().unwrap(),
            ];
            let want = [-42.5f64, 42.5, -44.6, 44.6].map(|d| d.to_radians().tan());
            assert!(
                tangents.iter().zip(want).all(|(a, b)| (a - b).abs() < 2e-3),
                "{tangents:?}"
            );
        }
        orientations.push(views[0]["pose"]["orientation"].to_string());
        let gpu = row["gpu_ms"]
            .as_array()
            .expect("GPU times of every rendered frame");
        assert!(gpu.iter().all(|ms| ms.as_f64().unwrap() > 0.0), "{gpu:?}");
        let gaze = &row["gaze"];
        if gaze["origin"] == "live" {
            live += 1;
            let measured = gaze["sample_time_ns"]
                .as_i64()
                .expect("the eye tracker gives sample times");
            let (want, valid) = expected(measured + offset);
            assert!(valid, "a live sample measured inside a blink");
            let dir = vec3(&gaze["direction"]);
            assert!(
                angle_deg(dir, want) < 0.01,
                "frame {i}: gaze {dir} vs the pattern's {want}"
            );
            let age = gaze["age_ns"].as_i64().unwrap();
            assert!(
                (0..100 * MS).contains(&age) && measured + age == t,
                "age {age} ns"
            );
        }
    }
    assert_eq!(rendered, 60);
    orientations.dedup();
    assert!(
        orientations.len() > 10,
        "the simulated head moves: each frame's own views are used"
    );
    assert!(live >= 40, "live gaze in {live} of 60 frames");
    assert_eq!(report["gaze_recorded"], 60);
    assert!(report["gaze_age"]["median_ms"].as_f64().unwrap() > 0.0);

    // The screenshot: both eyes side by side, lit, and different (the eyes are 63 mm apart).
    let image = image::open(&shot).unwrap().to_rgba8();
    let (w, h) = (
        report["width"].as_u64().unwrap() as u32,
        report["height"].as_u64().unwrap() as u32,
    );
    assert_eq!(image.dimensions(), (2 * w, h));
    let half = |x0: u32| {
        (0..h)
            .flat_map(|y| (0..w).map(move |x| (x0 + x, y)))
            .map(|(x, y)| image.get_pixel(x, y).0)
            .collect::<Vec<_>>()
    };
    let (left, right) = (half(0), half(w));
    let lit = |p: &[[u8; 4]]| {
        p.iter()
            .filter(|c| c[0] as u32 + c[1] as u32 + c[2] as u32 > 30)
            .count()
    };
    // Monado's ±42° × ±45° eyes see the Cornell box small, in the middle, black around it.
    let (lit_left, lit_right) = (lit(&left), lit(&right));
    assert!(
        lit_left > (w * h / 20) as usize && lit_right > (w * h / 20) as usize,
        "both eyes show the lit scene: {lit_left}, {lit_right} of {} pixels",
        w * h
    );
    assert_ne!(left, right, "the eyes see from different positions");

    replay_matches(&out, &rows, &trace);
}

/// `fovea render --gaze TRACE.csv` (same --headset) uses per frame the gaze `fovea xr` used.
fn replay_matches(xr_out: &Path, rows: &[Value], trace: &Path) {
    let out = temp_dir("replay");
    run(fovea(
        &[
            "render",
            "--method",
            "cartesian",
            "--scale",
            "0.1",
            "--frames",
            "60",
            "--out",
        ],
        true,
    )
    .arg(&out)
    .arg("--gaze")
    .arg(trace));
    let report = json(&out.join("report.json"));
    let hmd = HmdDescription::fove0();
    let eye = hmd.eye(Eye::Left);
    let (w, h) = (
        report["width"].as_f64().unwrap() as f32,
        report["height"].as_f64().unwrap() as f32,
    );
    let scale = Vec2::new(
        w / eye.recommended_width as f32,
        h / eye.recommended_height as f32,
    );
    let used: Vec<&Value> = rows
        .iter()
        .filter(|r| r["rendered"] == true)
        .map(|r| &r["gaze"])
        .collect();
    let replayed = report["gaze"].as_array().unwrap();
    assert_eq!(replayed.len(), used.len());
    let mut compared = 0;
    for (k, (xr, px)) in used.iter().zip(replayed).enumerate() {
        // Without gaze the replay's policy decides again on its own frame times (held or centre).
        if xr["origin"] == "centre" {
            continue;
        }
        let p = Vec2::new(
            px[0].as_f64().unwrap() as f32,
            px[1].as_f64().unwrap() as f32,
        );
        let want = hmd
            .direction_to_pixel(Eye::Left, vec3(&xr["direction"]))
            .unwrap()
            * scale;
        assert!(
            (p - want).length() < 1e-2,
            "frame {k}: replayed at {p}, fovea xr used {want} ({})",
            xr_out.display()
        );
        compared += 1;
    }
    assert!(compared >= 40, "{compared} frames compared");
}

/// A runtime without an eye tracker: one line says so and the fovea stays at the view centre;
/// `--gaze openxr` there is an error naming why.
#[test]
fn without_an_eye_tracker_the_centre_is_used_and_said_once() {
    let Some(_lock) = runtime() else { return };
    let out = temp_dir("no-tracker");
    let done = run(fovea(
        &[
            "xr",
            "--frames",
            "3",
            "--method",
            "cartesian",
            "--scale",
            "0.1",
            "--out",
        ],
        false,
    )
    .arg(&out));
    let stderr = String::from_utf8_lossy(&done.stderr);
    assert_eq!(
        stderr
            .lines()
            .filter(|l| l.starts_with("fovea xr: no eye tracker"))
            .count(),
        1,
        "{stderr}"
    );
    let report = json(&out.join("report.json"));
    assert_eq!(report["gaze_source"], "openxr");
    assert_eq!(
        report["gaze_centre"], 3,
        "no gaze: the invalid-gaze policy's centre, said as such"
    );
    assert!(report["gaze_notice"]
        .as_str()
        .unwrap()
        .contains("no eye tracker"));
    let refused = fovea(
        &[
            "xr", "--frames", "1", "--scale", "0.25", "--gaze", "openxr", "--out",
        ],
        false,
    )
    .arg(temp_dir("no-tracker-openxr"))
    .output()
    .unwrap();
    assert!(!refused.status.success());
    assert!(
        String::from_utf8_lossy(&refused.stderr).contains("--gaze openxr"),
        "{}",
        String::from_utf8_lossy(&refused.stderr)
    );
}

/// Ctrl-C on an unbounded session: the session ends through STOPPING → EXITING, the log and
/// report are written (marked interrupted), exit status 130.
#[test]
fn sigint_ends_the_session_cleanly() {
    let Some(_lock) = runtime() else { return };
    let out = temp_dir("sigint");
    let mut child = fovea(
        &[
            "xr",
            "--method",
            "cartesian",
            "--scale",
            "0.1",
            "--gaze",
            "center",
            "--out",
        ],
        true,
    )
    .arg(&out)
    .spawn()
    .unwrap();
    // The log's temporary grows once frames are rendered.
    let start = Instant::now();
    let temp_has_rows = |dir: &Path| {
        std::fs::read_dir(dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .any(|e| {
                e.file_name().to_string_lossy().starts_with(".frames.jsonl")
                    && e.metadata().is_ok_and(|m| m.len() > 0)
            })
    };
    while !temp_has_rows(&out) {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no frames after 2 minutes"
        );
        assert!(child.try_wait().unwrap().is_none(), "fovea xr exited early");
        std::thread::sleep(Duration::from_millis(50));
    }
    assert!(Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap()
        .success());
    let done = child.wait_with_output().unwrap();
    assert_eq!(
        done.status.code(),
        Some(130),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let report = json(&out.join("report.json"));
    assert_eq!(report["interrupted"], true);
    assert_eq!(report["session_end"], "exiting");
    assert_eq!(rows(&out).len() as u64, report["frames"].as_u64().unwrap());
}
