use fovea_hal::{
    Eye, GazeOrigin, GazeSample, GazeSource, GazeSpec, HmdDescription, InvalidGazePolicy,
};
use glam::{Vec2, Vec3};
use std::path::PathBuf;

const MS: i64 = 1_000_000;

#[test]
fn policy_uses_live_gaze_when_valid() {
    let mut p = InvalidGazePolicy::new(200.0);
    let dir = Vec3::new(0.3, 0.0, -1.0).normalize();
    let r = p.resolve(&GazeSample::looking(100 * MS, 1, dir), 120 * MS);
    assert_eq!(r.source, GazeOrigin::Live);
    assert_eq!(r.direction, dir);
    assert_eq!(r.age_ns, 20 * MS);
}

#[test]
fn policy_holds_last_valid_for_the_hold_time_then_centres() {
    let mut p = InvalidGazePolicy::new(200.0);
    let dir = Vec3::new(0.0, 0.2, -1.0).normalize();
    p.resolve(&GazeSample::looking(100 * MS, 1, dir), 100 * MS);
    let blink = GazeSample::no_gaze(150 * MS, 2);
    let held = p.resolve(&blink, 300 * MS);
    assert_eq!(
        (held.source, held.direction, held.age_ns),
        (GazeOrigin::Held, dir, 200 * MS)
    );
    let centre = p.resolve(&blink, 301 * MS);
    assert_eq!(
        (centre.source, centre.direction),
        (GazeOrigin::Centre, Vec3::NEG_Z)
    );
    // Gaze comes back: live again immediately.
    assert_eq!(
        p.resolve(&GazeSample::looking(310 * MS, 3, dir), 310 * MS)
            .source,
        GazeOrigin::Live
    );
}

#[test]
fn policy_without_any_valid_sample_uses_the_centre() {
    let mut p = InvalidGazePolicy::default();
    let r = p.resolve(&GazeSample::no_gaze(0, 0), 5 * MS);
    assert_eq!(r.source, GazeOrigin::Centre);
}

#[test]
fn policy_treats_degraded_samples_as_live_and_rejects_garbage_directions() {
    let mut p = InvalidGazePolicy::new(100.0);
    let degraded = GazeSample {
        tracked: false,
        ..GazeSample::looking(10 * MS, 1, Vec3::X - Vec3::Z)
    };
    assert_eq!(p.resolve(&degraded, 10 * MS).source, GazeOrigin::Live);
    let mut nan = GazeSample::looking(20 * MS, 2, Vec3::NEG_Z);
    nan.gaze.direction = Vec3::NAN;
    assert_eq!(p.resolve(&nan, 20 * MS).source, GazeOrigin::Held);
}

#[test]
fn gaze_spec_parses_every_form() {
    assert_eq!("center".parse::<GazeSpec>().unwrap(), GazeSpec::Center);
    assert_eq!("centre".parse::<GazeSpec>().unwrap(), GazeSpec::Center);
    assert_eq!(
        "640,720".parse::<GazeSpec>().unwrap(),
        GazeSpec::Fixed { x: 640.0, y: 720.0 }
    );
    assert_eq!(
        "sim".parse::<GazeSpec>().unwrap(),
        GazeSpec::Simulated { seed: 1 }
    );
    assert_eq!(
        "sim:42".parse::<GazeSpec>().unwrap(),
        GazeSpec::Simulated { seed: 42 }
    );
    assert_eq!(
        "traces/a,b.csv".parse::<GazeSpec>().unwrap(),
        GazeSpec::Trace(PathBuf::from("traces/a,b.csv"))
    );
    assert_eq!(
        "run.csv".parse::<GazeSpec>().unwrap(),
        GazeSpec::Trace(PathBuf::from("run.csv"))
    );
}

#[test]
fn gaze_spec_errors_are_clear() {
    for (input, needle) in [
        ("", "empty"),
        ("sim:x", "seed"),
        ("12,abc", "X,Y"),
        ("1,inf", "X,Y"),
    ] {
        let e = input.parse::<GazeSpec>().unwrap_err().to_string();
        assert!(e.contains(needle), "`{input}` -> {e}");
    }
}

#[test]
fn gaze_spec_opens_sources() {
    let hmd = HmdDescription::fove0();
    let mut fixed = GazeSpec::Fixed { x: 100.0, y: 200.0 }
        .open(hmd.clone())
        .unwrap();
    let dir = fixed.sample_at(5).gaze.direction;
    let px = hmd.direction_to_pixel(Eye::Left, dir).unwrap();
    assert!(px.distance(Vec2::new(100.0, 200.0)) < 0.01);
    let mut centre = GazeSpec::Center.open(hmd.clone()).unwrap();
    assert_eq!(centre.sample_at(0).gaze.direction, Vec3::NEG_Z);
    let mut sim = GazeSpec::Simulated { seed: 3 }.open(hmd.clone()).unwrap();
    sim.begin_frame(100 * MS).unwrap();
    assert_eq!(sim.describe().id, "fove0");
    let e = GazeSpec::Trace("/nonexistent/t.csv".into())
        .open(hmd)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("/nonexistent/t.csv"), "{e}");
}

#[test]
fn gazebase_files_are_a_gaze_spec() {
    assert_eq!(
        "gazebase:d/s.csv".parse::<GazeSpec>().unwrap(),
        GazeSpec::GazeBase(PathBuf::from("d/s.csv"))
    );
    assert!("gazebase:".parse::<GazeSpec>().is_err());
    let dir = std::env::temp_dir().join(format!("fovea-gazebase-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("s.csv");
    std::fs::write(&file, "n,x,y,val\n100,10,0,0\n101,10,0,0\n102,NaN,NaN,1\n").unwrap();
    let mut source = GazeSpec::GazeBase(file)
        .open(HmdDescription::fove0())
        .unwrap();
    source.begin_frame(0).unwrap();
    // Frame 0 shows the dataset's first sample (10° right), whatever its own time.
    let s = source.sample_at(0);
    assert!(
        s.valid
            && (s.gaze.direction.x / -s.gaze.direction.z - 10f32.to_radians().tan()).abs() < 1e-5,
        "{s:?}"
    );
}
