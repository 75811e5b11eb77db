//! `--gaze degrees:FILE`: recordings in degrees from the screen centre (`t_s,x_deg,y_deg,valid`)
//! placed on a headset eye's view; their checks name file and line.

use fovea_hal::trace::import::import_degrees_text;
use fovea_hal::{Eye, GazeOrigin, GazeSpec, HmdDescription, InvalidGazePolicy};
use glam::Vec2;
use std::path::{Path, PathBuf};

const MS: i64 = 1_000_000;

fn error(text: &str) -> String {
    let fov = HmdDescription::fove0().eye(Eye::Left).fov;
    import_degrees_text(text, Path::new("rec.csv"), &fov)
        .unwrap_err()
        .to_string()
}

#[test]
fn degrees_map_through_the_view_tangents_from_its_centre() {
    let text = "t_s,x_deg,y_deg,valid\n0.000,0,0,1\n0.002,10,-5,1\n0.004,nan,nan,0\n";
    for name in ["fove0", "vive_pro_eye", "varjo_aero"] {
        let hmd = HmdDescription::resolve(name).unwrap();
        let eye = hmd.eye(Eye::Left);
        let t = import_degrees_text(text, Path::new("rec.csv"), &eye.fov).unwrap();
        assert_eq!(t.header.rate_hz, 500.0, "{name}");
        assert_eq!(t.samples[1].time, 2 * MS);
        // (0, 0) is the image centre, also of asymmetric views (Vive, Aero).
        let centre =
            Vec2::new(eye.recommended_width as f32, eye.recommended_height as f32) / 2.0 - 0.5;
        let px = eye.direction_to_pixel(t.samples[0].gaze.direction).unwrap();
        assert!(px.distance(centre) < 0.05, "{name}: {px} vs {centre}");
        // 10° right and 5° down of it: tangents add to the centre's.
        let f = &eye.fov;
        let cx = (f.angle_left.tan() + f.angle_right.tan()) / 2.0;
        let cy = (f.angle_down.tan() + f.angle_up.tan()) / 2.0;
        let d = t.samples[1].gaze.direction;
        assert!(
            (d.x / -d.z - cx - 10f32.to_radians().tan()).abs() < 1e-5
                && (d.y / -d.z - cy + 5f32.to_radians().tan()).abs() < 1e-5,
            "{name}: {d}"
        );
        assert!(!t.samples[2].valid);
    }
    // On a symmetric view the angles are exact: 10° right of straight ahead.
    let fove = HmdDescription::fove0();
    let t = import_degrees_text(text, Path::new("r.csv"), &fove.eye(Eye::Left).fov).unwrap();
    let d = t.samples[1].gaze.direction;
    assert!((d.x.atan2(-d.z).to_degrees() - 10.0).abs() < 1e-4, "{d}");
}

#[test]
fn invalid_rows_follow_the_invalid_gaze_policy() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("blink.csv");
    let mut text = String::from("t_s,x_deg,y_deg,valid\n");
    for i in 0..200 {
        // 5° right, then a 300 ms blink from 100 ms.
        let valid = !(50..200).contains(&i);
        if valid {
            text += &format!("{:.3},5,0,1\n", i as f64 * 0.002);
        } else {
            text += &format!("{:.3},nan,nan,0\n", i as f64 * 0.002);
        }
    }
    std::fs::write(&file, text).unwrap();
    let spec: GazeSpec = format!("degrees:{}", file.display()).parse().unwrap();
    assert_eq!(spec, GazeSpec::Degrees(file.clone()));
    // A plain path with the degrees header is the same recording.
    let plain: GazeSpec = file.display().to_string().parse().unwrap();
    let hmd = HmdDescription::fove0();
    assert_eq!(
        plain.recording(&hmd).unwrap().samples,
        spec.recording(&hmd).unwrap().samples
    );
    let mut source = spec.open(HmdDescription::fove0()).unwrap();
    let mut policy = InvalidGazePolicy::new(250.0);
    let mut origin_at = |t: i64| {
        source.begin_frame(t).unwrap();
        let s = source.sample_at(t);
        policy.resolve(&s, t)
    };
    let live = origin_at(0);
    assert_eq!(live.source, GazeOrigin::Live);
    assert!((live.direction.x.atan2(-live.direction.z).to_degrees() - 5.0).abs() < 1e-4);
    // Inside the blink: the last valid direction is held for 250 ms, then the centre.
    let held = origin_at(150 * MS);
    assert_eq!(held.source, GazeOrigin::Held);
    assert_eq!(held.direction, live.direction);
    assert_eq!(origin_at(380 * MS).source, GazeOrigin::Centre);
}

#[test]
fn bad_recordings_name_file_and_line() {
    let cases = [
        ("", "rec.csv:1:", "empty"),
        (
            "t_s,x,y,valid\n0,0,0,1\n0.1,0,0,1\n",
            "rec.csv:1:",
            "t_s,x_deg,y_deg,valid",
        ),
        (
            "t_s,x_deg,y_deg,valid\n0,0,0,1\n",
            "rec.csv:2:",
            "two samples",
        ),
        (
            "t_s,x_deg,y_deg,valid\n0,0,0,1\n0.1,0,0\n",
            "rec.csv:3:",
            "expected 4 fields",
        ),
        (
            "t_s,x_deg,y_deg,valid\n0,0,0,1\n0.1,0,0,2\n",
            "rec.csv:3:",
            "valid `2`",
        ),
        (
            "t_s,x_deg,y_deg,valid\n0,0,0,1\n0.1,nan,0,1\n",
            "rec.csv:3:",
            "x_deg NaN",
        ),
        (
            "t_s,x_deg,y_deg,valid\n0,0,0,1\n0.1,0,95,1\n",
            "rec.csv:3:",
            "y_deg 95",
        ),
        (
            "t_s,x_deg,y_deg,valid\n0,0,0,1\n0.1,0,inf,1\n",
            "rec.csv:3:",
            "infinite",
        ),
        (
            "t_s,x_deg,y_deg,valid\n0,0,0,1\nabc,0,0,1\n",
            "rec.csv:3:",
            "`abc`",
        ),
        (
            "t_s,x_deg,y_deg,valid\n0,0,0,1\nnan,0,0,1\n",
            "rec.csv:3:",
            "t_s NaN",
        ),
        (
            "t_s,x_deg,y_deg,valid\n0.1,0,0,1\n0.1,0,0,1\n",
            "rec.csv:3:",
            "duplicate",
        ),
        (
            "t_s,x_deg,y_deg,valid\n0.2,0,0,1\n0.1,0,0,1\n",
            "rec.csv:3:",
            "out-of-order",
        ),
    ];
    for (text, at, reason) in cases {
        let e = error(text);
        assert!(e.starts_with(at) && e.contains(reason), "{text:?}: {e}");
    }
    // Invalid rows need no angles; a byte-order mark is no content.
    let fov = HmdDescription::fove0().eye(Eye::Left).fov;
    let ok = "\u{FEFF}t_s,x_deg,y_deg,valid\n0,0,0,1\n0.1,,,0\n0.2,999,0,0\n";
    assert_eq!(
        import_degrees_text(ok, Path::new("rec.csv"), &fov)
            .unwrap()
            .samples
            .len(),
        3
    );
    // A missing file is named.
    let e = GazeSpec::Degrees(PathBuf::from("/nonexistent/rec.csv"))
        .open(HmdDescription::fove0())
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("/nonexistent/rec.csv"), "{e}");
    assert!("degrees:".parse::<GazeSpec>().is_err());
}

/// The shared real recordings load as they are (skipped without the data folder).
#[test]
fn shared_recordings_load() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/gaze");
    if !dir.is_dir() {
        if std::env::var("FOVEA_REQUIRE_DATA").as_deref() == Ok("1") {
            panic!("missing {}", dir.display());
        }
        eprintln!("skipped: no recordings at {}", dir.display());
        return;
    }
    let fov = HmdDescription::fove0().eye(Eye::Left).fov;
    for (name, rate, invalid) in [
        ("syelink_both_eyes_block2_R_500hz.csv", 500.0, 0.011),
        // 4.3 % lost samples and a 1.9 s pause without gaze.
        ("gazeparser_test01_400hz.csv", 400.0, 0.122),
    ] {
        let path = dir.join(name);
        let t = fovea_hal::trace::import::import_degrees(&path, &fov).unwrap();
        assert!(
            (t.header.rate_hz - rate).abs() < 1.0,
            "{name}: {}",
            t.header.rate_hz
        );
        let share = t.samples.iter().filter(|s| !s.valid).count() as f64 / t.samples.len() as f64;
        assert!((share - invalid).abs() < 0.003, "{name}: {share}");
    }
}
