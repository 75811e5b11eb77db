//! What a new user sees first: `fovea render` with no flag beyond `--scene` (and a small size and
//! a few frames, to keep the test short) shows the Cornell box and the three real glTF scenes
//! exposed to a mid-grey mean — neither nearly black nor blown out — and says so in its report.

use std::path::{Path, PathBuf};
use std::process::Command;

fn mean_luma(png: &Path) -> f64 {
    let image = image::open(png)
        .unwrap_or_else(|e| panic!("{}: {e}", png.display()))
        .to_rgb8();
    let sum: f64 = image
        .pixels()
        .map(|p| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64)
        .sum();
    sum / (image.width() * image.height()) as f64
}

fn render_defaults(scene: &Path, out: &Path) -> serde_json::Value {
    let frames = 6;
    let output = Command::new(env!("CARGO_BIN_EXE_fovea"))
        .arg("render")
        .arg("--scene")
        .arg(scene)
        .args(["--width", "160", "--height", "180", "--frames"])
        .arg(frames.to_string())
        .arg("--validation")
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}: {}",
        scene.display(),
        String::from_utf8_lossy(&output.stderr)
    );
    let report = std::fs::read_to_string(out.join("report.json")).unwrap();
    serde_json::from_str(&report).unwrap()
}

#[test]
fn every_scene_is_exposed_to_a_mid_grey_mean_by_default() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut scenes = vec![("cornell-box", root.join("scenes/cornell-box.gltf"))];
    for (name, file) in [
        ("sponza", "scenes/sponza/Sponza.gltf"),
        ("breakfast-room", "scenes/breakfast-room/BreakfastRoom.gltf"),
        ("flight-helmet", "scenes/flight-helmet/FlightHelmet.gltf"),
    ] {
        match fovea_test_kit::data::shared_data(file) {
            Some(path) => scenes.push((name, path)),
            None => return,
        }
    }
    let dir = std::env::temp_dir().join(format!("fovea-first-look-{}", std::process::id()));
    let mut failures = Vec::new();
    for (name, scene) in scenes {
        let out = dir.join(name);
        let report = render_defaults(&scene, &out);
        assert_eq!(
            report["exposure_mode"], "auto",
            "{name}: automatic exposure by default"
        );
        let frames = report["frames"].as_u64().unwrap();
        let luma = mean_luma(&out.join(format!("frame_{:04}.png", frames - 1)));
        println!(
            "{name}: mean 8-bit luma {luma:.1}, exposure {}",
            report["exposure"][frames as usize - 1]
        );
        if !(60.0..=160.0).contains(&luma) {
            failures.push(format!("{name}: mean luma {luma:.1} outside [60, 160]"));
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(failures.is_empty(), "{failures:#?}");
}
