//! `fovea gaze-eval`: its JSON keys and table, bad recordings named by file and line, and the
//! shared recordings' figures behind the default predictor.

use std::path::{Path, PathBuf};
use std::process::Command;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fovea-gaze-eval-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn fovea(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_fovea"))
        .args(args)
        .output()
        .expect("fovea runs")
}

/// A 500 Hz degrees recording: fixations at 0° and 10° right with a 10° minimum-jerk saccade
/// between them at 1 s (40 ms), a blink from 2.0 to 2.2 s, 3 s in all.
fn synthetic(dir: &Path) -> PathBuf {
    let mut text = String::from("t_s,x_deg,y_deg,valid\n");
    for i in 0..1500 {
        let t = i as f64 * 0.002;
        let tau = ((t - 1.0) / 0.04).clamp(0.0, 1.0);
        let x = 10.0 * tau.powi(3) * (10.0 - 15.0 * tau + 6.0 * tau * tau);
        if (2.0..2.2).contains(&t) {
            text += &format!("{t:.3},nan,nan,0\n");
        } else {
            text += &format!("{t:.3},{x:.4},0.0000,1\n");
        }
    }
    let path = dir.join("step.csv");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn writes_the_issues_keys_and_a_table() {
    let dir = temp_dir("keys");
    let rec = synthetic(&dir);
    let out = dir.join("eval");
    let o = fovea(&[
        "gaze-eval",
        rec.to_str().unwrap(),
        "--latency-ms",
        "50",
        "--tracker-hz",
        "120",
        "--display-hz",
        "90",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(stdout.contains("| step.csv | saccade |"), "{stdout}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("gaze_eval.json")).unwrap())
            .unwrap();
    assert_eq!(json["latency_ms"], 50.0);
    let trace = &json["traces"][0];
    let predictors = trace["predictors"].as_array().unwrap();
    let names: Vec<&str> = predictors
        .iter()
        .map(|p| p["gaze_predict"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["off", "hold", "linear", "saccade"]);
    for p in predictors {
        for key in ["median", "p95", "p99", "share_above_2_5", "share_above_5"] {
            assert!(p[key].is_f64(), "{key} in {p}");
        }
        let saccades = p["saccades"].as_array().unwrap();
        assert_eq!(saccades.len(), 1, "the one 10° saccade: {p}");
        let amplitude = saccades[0]["amplitude"].as_f64().unwrap();
        assert!((amplitude - 10.0).abs() < 0.5, "{amplitude}");
        assert!(saccades[0]["landing_error"].is_f64());
    }
    // Holding the newest sample shows the old fixation for a latency after the landing: frames
    // 2.5° off; the step is clean, so nothing else is.
    let off = &predictors[0];
    let frames_off = off["saccades"][0]["frames_above_2_5"].as_u64().unwrap();
    assert!(frames_off >= 5, "{off}");
    let saccade = &predictors[3];
    assert!(
        saccade["saccades"][0]["landing_error"].as_f64().unwrap()
            < off["saccades"][0]["landing_error"].as_f64().unwrap(),
        "{saccade}"
    );
}

#[test]
fn bad_recordings_are_named_with_file_and_line() {
    let dir = temp_dir("bad");
    let bad = dir.join("bad.csv");
    std::fs::write(&bad, "t_s,x_deg,y_deg,valid\n0,0,0,1\n0.002,0,oops,1\n").unwrap();
    let out = dir.join("eval");
    let o = fovea(&[
        "gaze-eval",
        bad.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        stderr.contains(&format!("{}:3:", bad.display())) && stderr.contains("oops"),
        "{stderr}"
    );
    assert!(!out.exists(), "nothing is written for a bad recording");
    for (args, expected) in [
        (vec!["sim:1"], "not a recording"),
        (
            vec![bad.to_str().unwrap(), "--gaze-predict", "kalman"],
            "--gaze-predict",
        ),
        (
            vec![bad.to_str().unwrap(), "--latency-ms", "-5"],
            "--latency-ms",
        ),
    ] {
        let mut all = vec!["gaze-eval"];
        all.extend(args);
        all.extend(["--out", out.to_str().unwrap()]);
        let o = fovea(&all);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(
            !o.status.success() && stderr.contains(expected),
            "{all:?}: {stderr}"
        );
    }
}

/// The measurement the default predictor rests on: on both shared recordings (120 Hz tracker,
/// 90 Hz display, 50 ms) `saccade` is no worse than holding the newest sample in the share of
/// frames above 2.5° and in p99, and its fixation median lies within 0.05° of it.
#[test]
fn the_default_predictor_is_no_worse_on_the_shared_recordings() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/gaze");
    if !data.is_dir() {
        if std::env::var("FOVEA_REQUIRE_DATA").as_deref() == Ok("1") {
            panic!("missing {}", data.display());
        }
        eprintln!("skipped: no recordings at {}", data.display());
        return;
    }
    let dir = temp_dir("shared");
    let out = dir.join("eval");
    let recordings = [
        data.join("syelink_both_eyes_block2_R_500hz.csv"),
        data.join("gazeparser_test01_400hz.csv"),
    ];
    let mut args = vec!["gaze-eval"];
    args.extend(recordings.iter().map(|r| r.to_str().unwrap()));
    args.extend([
        "--tracker-hz",
        "120",
        "--display-hz",
        "90",
        "--latency-ms",
        "50",
        "--gaze-predict",
        "off,saccade",
        "--out",
    ]);
    args.push(out.to_str().unwrap());
    let o = fovea(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("gaze_eval.json")).unwrap())
            .unwrap();
    assert_eq!(json["default_gaze_predict"], "saccade");
    for trace in json["traces"].as_array().unwrap() {
        let p = &trace["predictors"][1];
        assert_eq!(p["gaze_predict"], "saccade");
        let (share, p99, fixation) = (
            p["share_above_2_5_vs_off"].as_f64().unwrap(),
            p["p99_vs_off"].as_f64().unwrap(),
            p["fixation_median_minus_off"].as_f64().unwrap(),
        );
        assert!(
            share <= 1.0 && p99 <= 1.0 && fixation.abs() <= 0.05,
            "{}: > 2.5° {share:.2}×, p99 {p99:.2}×, fixation {fixation:+.3}°",
            trace["trace"]
        );
    }
}
