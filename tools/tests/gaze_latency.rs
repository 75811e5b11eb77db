//! `fovea quality` and `fovea replay` with the latency model: frames rendered for a gaze a latency
//! old are judged also where the eye is when they are shown (new JSON keys; the old ones keep
//! their meaning). Lavapipe, validation on.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fovea-latency-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn fovea(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fovea"))
        .args(args)
        .arg("--validation")
        .output()
        .unwrap()
}

/// The eye fixates 20° left, jumps to 20° right at 0.15 s (30 ms), fixates there (1 kHz).
fn jump(dir: &Path) -> PathBuf {
    let mut text = String::from("t_s,x_deg,y_deg,valid\n");
    for i in 0..400 {
        let t = i as f64 * 1e-3;
        let tau = ((t - 0.15) / 0.03).clamp(0.0, 1.0);
        let x = -20.0 + 40.0 * tau.powi(3) * (10.0 - 15.0 * tau + 6.0 * tau * tau);
        text += &format!("{t:.3},{x:.3},0,1\n");
    }
    let path = dir.join("jump.csv");
    std::fs::write(&path, text).unwrap();
    path
}

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// 150 ms of latency, no prediction: the frames after the jump are foveated 40° from where the
/// eye is, so the innermost rings around the true gaze are worse than in a run without latency
/// (whose frames are foveated there); without latency the true and rendered gaze are one.
#[test]
fn quality_judges_frames_around_the_true_gaze() {
    let dir = temp_dir("quality");
    let rec = jump(&dir);
    let run = |latency: &str, out: &Path| {
        let o = fovea(&[
            "quality",
            "--scene",
            "cornell-box",
            "--width",
            "64",
            "--height",
            "72",
            "--gaze",
            rec.to_str().unwrap(),
            "--latency-ms",
            latency,
            "--tracker-hz",
            "1000",
            "--gaze-predict",
            "off",
            "--methods",
            "vp",
            "--denoisers",
            "svgf",
            "--cameras",
            "still",
            "--frames",
            "20",
            "--eval-frames",
            "8",
            "--reference-spp",
            "16",
            "--rings",
            "10",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        json(&out.join("quality.json"))
    };
    let late = run("150", &dir.join("late"));
    let r = &late["runs"][0];
    // Frames 12..19 are shown 0.171..0.271 s (70 Hz): the eye is right of the centre (pixel
    // 31.5), the gaze rendered from samples before 0.122 s still left.
    let (gaze, truth) = (
        r["gaze"].as_array().unwrap(),
        r["gaze_true"].as_array().unwrap(),
    );
    assert_eq!(truth.len(), 8);
    for (g, t) in gaze.iter().zip(truth) {
        let (gx, tx) = (g[0].as_f64().unwrap(), t[0].as_f64().unwrap());
        assert!(gx < 32.0 && tx > 32.0, "rendered {g}, true {t}");
    }
    assert_eq!(r["rings_true_gaze"].as_array().unwrap().len(), 10);
    assert!(late["latency"].as_str().unwrap().starts_with("150 ms"));
    let seen_late = r["foveal_flip_true_gaze"].as_f64().unwrap();

    // Without latency the gaze rendered is the newest 1 kHz sample: where the eye is, to a
    // pixel even on the way.
    let now = run("0", &dir.join("now"));
    let n = &now["runs"][0];
    let pairs = n["gaze"]
        .as_array()
        .unwrap()
        .iter()
        .zip(n["gaze_true"].as_array().unwrap());
    for (g, t) in pairs {
        let d = (g[0].as_f64().unwrap() - t[0].as_f64().unwrap()).abs();
        assert!(d < 1.5, "rendered {g}, true {t}");
    }
    // The old keys keep their meaning: rings around the rendered gaze.
    assert_ne!(r["rings"][0]["flip"], r["rings_true_gaze"][0]["flip"]);
    let seen_now = n["foveal_flip_true_gaze"].as_f64().unwrap();
    assert!(
        seen_late > 1.1 * seen_now,
        "fovea where the eye is: {seen_now}; 150 ms late: {seen_late}"
    );
}

/// `fovea replay` with the latency model reports each frame's true gaze and its rings, records
/// the flags in the baseline, and names them when a run differs.
#[test]
fn replay_reports_the_true_gaze_and_records_the_flags() {
    let dir = temp_dir("replay");
    let rec = jump(&dir);
    let baseline = dir.join("baseline");
    let args = |out: &Path, update: bool, latency: &[&'static str]| {
        let mut a = vec![
            "replay".to_string(),
            rec.display().to_string(),
            "--baseline".into(),
            baseline.display().to_string(),
            "--out".into(),
            out.display().to_string(),
            "--frames".into(),
            "20".into(),
            "--reference-spp".into(),
            "8".into(),
            "--denoiser".into(),
            "svgf".into(),
        ];
        if update {
            a.push("--update-baseline".into());
        }
        a.extend(latency.iter().map(|s| s.to_string()));
        a
    };
    let run = |a: Vec<String>| {
        let refs: Vec<&str> = a.iter().map(String::as_str).collect();
        fovea(&refs)
    };
    let latency = ["--latency-ms", "150", "--gaze-predict", "off"];
    let o = run(args(&dir.join("u"), true, &latency));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The baseline folder is named by the trace's identity (stem and SHA-256).
    let folder = fovea_tools::replay::baseline::TraceId::of(&rec.display().to_string())
        .unwrap()
        .key;
    assert!(folder.starts_with("jump-"), "{folder}");
    let stored = json(&baseline.join(folder).join("baseline.json"));
    assert_eq!(
        stored["params"]["gaze_timing"],
        "--latency-ms 150 --gaze-predict off"
    );
    let o = run(args(&dir.join("same"), false, &latency));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report = json(&dir.join("same").join("replay.json"));
    let t = &report["traces"][0];
    let frame = &t["frames"][19];
    assert!(frame["gaze_true"][0].as_f64().unwrap() > 32.0, "{frame}");
    assert_eq!(frame["quality_flip_true_gaze"].as_array().unwrap().len(), 4);
    assert!(
        t["foveal_flip_true_gaze"].is_f64() && t["foveal_flip"].is_f64(),
        "{t}"
    );
    // Without the flags the gaze differs from the baseline's, and the report says why.
    let o = run(args(&dir.join("plain"), false, &[]));
    assert_eq!(o.status.code(), Some(1));
    let md = std::fs::read_to_string(dir.join("plain").join("replay.md")).unwrap();
    assert!(md.contains("setting `gaze_timing`"), "{md}");
}
