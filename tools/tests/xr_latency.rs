//! `fovea xr`'s per-frame latency accounting in frames.jsonl: the sample behind each frame's gaze,
//! the prediction and its mode, and the latency parts the runtime and the profile give. Needs an
//! OpenXR runtime (XR_RUNTIME_JSON; scripts/test builds Monado with a simulated eye tracker).

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

fn runtime() -> bool {
    let present = std::env::var_os("XR_RUNTIME_JSON").is_some_and(|p| Path::new(&p).is_file());
    if !present {
        assert!(
            std::env::var_os("FOVEA_REQUIRE_OPENXR").is_none(),
            "FOVEA_REQUIRE_OPENXR is set but XR_RUNTIME_JSON names no runtime"
        );
        eprintln!("skipped: no OpenXR runtime (XR_RUNTIME_JSON); scripts/test builds Monado and runs these tests");
    }
    present
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fovea-xr-latency-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `fovea xr` with Monado's test settings and its simulated eye tracker; the rows of frames.jsonl.
fn xr(args: &[&str], out: &Path) -> Vec<Value> {
    let o = Command::new(env!("CARGO_BIN_EXE_fovea"))
        .arg("xr")
        .args(args)
        .arg("--out")
        .arg(out)
        .env("XRT_COMPOSITOR_NULL", "1")
        .env("SIMULATED_ENABLE", "1")
        .env("SIMULATED_EYE_TRACKER", "on")
        .env("XRT_LOG", "error")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::read_to_string(out.join("frames.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

#[test]
fn frames_account_for_the_gaze_latency() {
    if !runtime() {
        return;
    }
    let rendered = |rows: Vec<Value>| -> Vec<Value> {
        rows.into_iter().filter(|r| r["rendered"] == true).collect()
    };
    // The runtime's eye tracker, no prediction: the profile's parts, the runtime's period.
    let rows = rendered(xr(&["--frames", "8"], &temp_dir("plain")));
    assert_eq!(rows.len(), 8);
    for r in &rows {
        assert!(
            r["predicted_display_period_ns"].as_i64().unwrap() > 0,
            "{r}"
        );
        let l = &r["gaze"]["latency"];
        assert_eq!(l["gaze_predict"], "off");
        assert!(l["predicted"].is_null() && l["motion"].is_null(), "{l}");
        // FOVE 0's profile: tracker 20 ms, render 14.3, display 10.7.
        assert_eq!(l["profile_tracker_ms"], 20.0);
        assert!((l["profile_render_ms"].as_f64().unwrap() - 14.3).abs() < 1e-4);
        assert!((l["profile_display_ms"].as_f64().unwrap() - 10.7).abs() < 1e-4);
        assert!(l["model_total_ms"].is_null());
    }
    // With a predictor on the runtime's gaze: its mode, the predicted gaze and what it saw.
    let rows = rendered(xr(
        &["--frames", "8", "--gaze-predict", "saccade"],
        &temp_dir("live"),
    ));
    for r in &rows {
        let l = &r["gaze"]["latency"];
        assert_eq!(l["gaze_predict"], "saccade");
        assert!(l["motion"].is_string(), "{l}");
        if r["gaze"]["origin"] == "live" {
            let p = l["predicted"].as_array().unwrap();
            let used = r["gaze"]["direction"].as_array().unwrap();
            for (a, b) in p.iter().zip(used) {
                let d = a.as_f64().unwrap() - b.as_f64().unwrap();
                assert!(d.abs() < 1e-5, "the predicted gaze is the one used: {l}");
            }
        }
    }
    // A recorded gaze through the latency model: its total and the sample a latency back.
    let rows = rendered(xr(
        &["--frames", "8", "--gaze", "sim:4", "--latency-ms", "50"],
        &temp_dir("model"),
    ));
    for r in &rows {
        let l = &r["gaze"]["latency"];
        assert_eq!(l["model_total_ms"], 50.0);
        assert_eq!(l["gaze_predict"], "saccade");
        assert!(l["horizon_ms"].as_f64().unwrap() >= 50.0, "{l}");
        assert!(l["runtime_sample_age_ms"].is_null());
    }
}
