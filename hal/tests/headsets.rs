use fovea_hal::{builtin_names, Eye, HalError, HmdDescription};
use glam::{Vec2, Vec3};
use std::path::Path;

const GOOD: &str = r#"
id = "test"
display_name = "Test"
refresh_hz = 90.0
[left_eye]
recommended_width = 1000
recommended_height = 1000
fov_deg = { left = -50.0, right = 40.0, down = -45.0, up = 45.0 }
offset_m = [-0.0315, 0.0, 0.0]
[right_eye]
recommended_width = 1000
recommended_height = 1000
fov_deg = { left = -40.0, right = 50.0, down = -45.0, up = 45.0 }
offset_m = [0.0315, 0.0, 0.0]
[tracker]
rate_hz = 120.0
latency_ms = 20.0
accuracy_deg = 1.0
precision_deg = 0.3
"#;

fn parse(text: &str) -> Result<HmdDescription, HalError> {
    HmdDescription::parse(text, Path::new("bad.toml"))
}

fn expect_err(text: &str, needles: &[&str]) {
    let e = parse(text).expect_err("must be rejected").to_string();
    assert!(e.contains("bad.toml"), "error must name the file: {e}");
    for n in needles {
        assert!(e.contains(n), "error `{e}` should mention `{n}`");
    }
}

#[test]
fn every_builtin_profile_parses_and_fove0_is_first() {
    let names = builtin_names();
    assert!(names.len() >= 5);
    assert_eq!(names[0], "fove0");
    let all = HmdDescription::list_builtin();
    assert_eq!(all.len(), names.len());
    for h in &all {
        assert!(
            h.capabilities.eye_gaze,
            "{} is an eye-tracked headset",
            h.id
        );
        assert!((h.ipd_m() - 0.063).abs() < 1e-6);
    }
}

#[test]
fn fove0_matches_hal_md() {
    let h = HmdDescription::fove0();
    assert_eq!(
        (h.eyes[0].recommended_width, h.eyes[0].recommended_height),
        (1280, 1440)
    );
    assert_eq!(h.refresh_hz, 70.0);
    assert_eq!(h.tracker.rate_hz, 120.0);
    assert_eq!(h.tracker.latency_ms, 20.0);
    assert_eq!(h.tracker.accuracy_deg, 1.15);
    let fov = h.eyes[0].fov.horizontal_deg();
    assert!((90.0..=100.0).contains(&fov), "{fov}");
}

#[test]
fn resolve_accepts_names_and_paths_and_lists_builtins_on_unknown() {
    assert_eq!(
        HmdDescription::resolve("varjo_aero").unwrap().id,
        "varjo_aero"
    );
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../config/headsets/psvr2.toml");
    assert_eq!(HmdDescription::resolve(path).unwrap().id, "psvr2");
    let e = HmdDescription::resolve("no_such_headset")
        .unwrap_err()
        .to_string();
    assert!(e.contains("no_such_headset") && e.contains("fove0"), "{e}");
}

#[test]
fn config_files_on_disk_equal_compiled_in_copies() {
    for name in builtin_names() {
        let path = format!(
            "{}/../config/headsets/{name}.toml",
            env!("CARGO_MANIFEST_DIR")
        );
        assert_eq!(
            HmdDescription::load(Path::new(&path)).unwrap(),
            HmdDescription::builtin(name).unwrap()
        );
    }
}

#[test]
fn good_profile_parses() {
    let h = parse(GOOD).unwrap();
    assert!((h.eyes[0].fov.angle_left.to_degrees() + 50.0).abs() < 1e-4);
}

#[test]
fn unknown_key_is_rejected() {
    expect_err(
        &GOOD.replace("refresh_hz = 90.0", "refresh_hz = 90.0\nrefresh_rate = 90"),
        &["refresh_rate"],
    );
}

#[test]
fn unknown_nested_key_is_rejected() {
    expect_err(
        &GOOD.replace("rate_hz = 120.0", "rate_hz = 120.0\nsmoothing = 1"),
        &["smoothing"],
    );
}

#[test]
fn missing_key_is_rejected() {
    expect_err(&GOOD.replace("latency_ms = 20.0\n", ""), &["latency_ms"]);
}

#[test]
fn fov_of_180_degrees_or_more_is_rejected() {
    expect_err(
        &GOOD.replace("left = -50.0", "left = -95.0"),
        &["left_eye.fov_deg.left", "-90"],
    );
    expect_err(
        &GOOD.replace("up = 45.0 }\noffset_m = [-", "up = 90.0 }\noffset_m = [-"),
        &["left_eye.fov_deg.up"],
    );
}

#[test]
fn inverted_fov_is_rejected() {
    expect_err(
        &GOOD.replace("right = 40.0", "right = -60.0"),
        &["left_eye.fov_deg.right"],
    );
}

#[test]
fn negative_rate_is_rejected() {
    expect_err(
        &GOOD.replace("rate_hz = 120.0", "rate_hz = -120.0"),
        &["tracker.rate_hz"],
    );
    expect_err(
        &GOOD.replace("refresh_hz = 90.0", "refresh_hz = 0.0"),
        &["refresh_hz"],
    );
}

/// A refresh of 1e-30 Hz passed the range check and `fovea render` with the simulated gaze never
/// finished (frame k at k × 1e30 s); rates below 1 Hz are refused.
#[test]
fn rates_below_one_hertz_are_rejected() {
    for (key, from, to) in [
        ("refresh_hz", "refresh_hz = 90.0", "refresh_hz = 1e-30"),
        ("refresh_hz", "refresh_hz = 90.0", "refresh_hz = 0.5"),
        ("tracker.rate_hz", "rate_hz = 120.0", "rate_hz = 1e-30"),
    ] {
        expect_err(&GOOD.replace(from, to), &[key, "[1, "]);
    }
}

#[test]
fn zero_resolution_is_rejected() {
    expect_err(
        &GOOD.replacen("recommended_width = 1000", "recommended_width = 0", 1),
        &["left_eye.recommended_width"],
    );
}

#[test]
fn negative_resolution_is_a_type_error_with_line() {
    expect_err(
        &GOOD.replacen("recommended_height = 1000", "recommended_height = -5", 1),
        &["line", "-5"],
    );
}

#[test]
fn syntax_error_names_line() {
    expect_err(&GOOD.replace("[tracker]", "[tracker"), &["line"]);
}

#[test]
fn nan_value_is_rejected() {
    expect_err(
        &GOOD.replace("accuracy_deg = 1.0", "accuracy_deg = nan"),
        &["tracker.accuracy_deg"],
    );
}

/// Pixel → direction → pixel and direction → pixel → direction for every profile and both eyes,
/// including the asymmetric ones, over a grid that reaches the image corners.
#[test]
fn pixel_direction_round_trips_for_every_profile() {
    for h in HmdDescription::list_builtin() {
        for eye in Eye::BOTH {
            let v = h.eye(eye);
            let (w, hh) = (v.recommended_width as f32, v.recommended_height as f32);
            for i in 0..=10 {
                for j in 0..=10 {
                    let px = Vec2::new(i as f32 / 10.0 * (w - 1.0), j as f32 / 10.0 * (hh - 1.0));
                    let dir = h.pixel_to_direction(eye, px);
                    assert!((dir.length() - 1.0).abs() < 1e-5);
                    let back = h.direction_to_pixel(eye, dir).unwrap();
                    assert!(back.distance(px) < 0.05, "{} {eye:?} {px} -> {back}", h.id);
                    let again = h.pixel_to_direction(eye, back);
                    // From the chord: acos of a dot product one ulp below 1 is already 0.02°.
                    let angle = (2.0 * ((again - dir).length() * 0.5).asin()).to_degrees();
                    assert!(angle < 1e-3, "{} {eye:?} {px}: {angle}°", h.id);
                }
            }
        }
    }
}

#[test]
fn fov_edges_map_to_image_edges() {
    for h in HmdDescription::list_builtin() {
        for eye in Eye::BOTH {
            let v = h.eye(eye);
            let f = v.fov;
            let left_edge = Vec3::new(f.angle_left.tan(), 0.0, -1.0);
            let top_edge = Vec3::new(0.0, f.angle_up.tan(), -1.0);
            assert!(
                (v.direction_to_pixel(left_edge).unwrap().x + 0.5).abs() < 1e-2,
                "{}",
                h.id
            );
            assert!(
                (v.direction_to_pixel(top_edge).unwrap().y + 0.5).abs() < 1e-2,
                "{}",
                h.id
            );
        }
    }
}

#[test]
fn eccentricity_is_zero_at_gaze_and_matches_angles() {
    for h in HmdDescription::list_builtin() {
        let v = h.eye(Eye::Right);
        let gaze = Vec3::new(0.2, -0.1, -1.0).normalize();
        let px = v.direction_to_pixel(gaze).unwrap();
        assert!(v.eccentricity_deg(px, gaze) < 0.01);
        // Straight ahead vs. a point 20° right: the forward pixel has eccentricity 20°.
        let right20 = Vec3::new(20f32.to_radians().sin(), 0.0, -20f32.to_radians().cos());
        let fwd = v.forward_pixel();
        assert!(
            (h.eccentricity_deg(Eye::Right, fwd, right20) - 20.0).abs() < 0.01,
            "{}",
            h.id
        );
    }
}

#[test]
fn directions_behind_the_viewer_have_no_pixel() {
    let h = HmdDescription::fove0();
    assert!(h.direction_to_pixel(Eye::Left, Vec3::Z).is_none());
    assert!(h.direction_to_pixel(Eye::Left, Vec3::X).is_none());
    assert!(h
        .direction_to_pixel(Eye::Left, Vec3::new(f32::NAN, 0.0, -1.0))
        .is_none());
}

#[test]
fn asymmetric_fov_puts_forward_off_centre() {
    let h = HmdDescription::builtin("varjo_aero").unwrap();
    let left = h.eye(Eye::Left);
    // Left eye: wider on the temporal (left) side, so straight ahead lies right of centre.
    assert!(left.forward_pixel().x > left.recommended_width as f32 / 2.0);
    let right = h.eye(Eye::Right);
    assert!(right.forward_pixel().x < right.recommended_width as f32 / 2.0);
}
