use fovea_hal::trace::import::{
    import_gazebase_text, import_normalized_text, DegreesImport, NormalizedImport,
};
use fovea_hal::{
    Fov, GazeSample, GazeSource, HalError, HmdDescription, Playback, Recorder, SampleTimeKind,
    SimulatedFove, Trace,
};
use glam::Vec3;
use std::path::Path;

const HEAD: &str = "# fovea-gaze-trace 1\n# device: fove0\n# rate_hz: 100\n# coordinates: openxr-view\ntime_ns,valid,dir_x,dir_y,dir_z\n";

fn parse(body: &str) -> Result<Trace, HalError> {
    Trace::parse(&format!("{HEAD}{body}"), Path::new("t.csv"))
}

/// The error names the file and the line (header is 5 lines, so data starts at line 6).
fn expect_err(body: &str, line: usize, needle: &str) {
    let e = parse(body).expect_err("must be rejected").to_string();
    assert!(
        e.starts_with(&format!("t.csv:{line}: ")),
        "wrong file/line in `{e}`"
    );
    assert!(e.contains(needle), "`{e}` should mention `{needle}`");
}

#[test]
fn minimal_trace_parses_with_defaults() {
    let t = parse("0,1,0,0,-1\n10000000,0,0,0,0\n").unwrap();
    assert_eq!(t.samples.len(), 2);
    assert_eq!(t.samples[0].time_kind, SampleTimeKind::Measured);
    assert!(t.samples[0].valid && t.samples[0].tracked);
    assert_eq!(t.samples[1].sequence, 1);
    assert!(!t.samples[1].valid);
}

#[test]
fn example_trace_in_config_parses_and_plays() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../config/gaze/example_trace.csv"
    );
    let mut p = Playback::open(Path::new(path), HmdDescription::fove0()).unwrap();
    assert!(p.trace().samples.len() >= 20);
    assert!(
        p.trace().samples.iter().any(|s| !s.valid),
        "the example shows a blink"
    );
    p.begin_frame(50_000_000).unwrap();
    assert!(p.sample_at(50_000_000).time <= 50_000_000);
}

#[test]
fn nan_is_rejected() {
    expect_err("0,1,NaN,0,-1\n", 6, "NaN");
}

#[test]
fn infinity_is_rejected() {
    expect_err("0,1,0,0,-1\n1,1,0,inf,-1\n", 7, "inf");
}

#[test]
fn non_unit_direction_is_rejected() {
    expect_err("0,1,0,0,-2\n", 6, "not unit");
}

#[test]
fn almost_unit_direction_is_kept_unchanged() {
    let t = parse("0,1,0,0,-1.0004\n").unwrap();
    assert_eq!(t.samples[0].gaze.direction.z, -1.0004);
}

#[test]
fn out_of_order_time_is_rejected() {
    expect_err("20,1,0,0,-1\n10,1,0,0,-1\n", 7, "earlier than 20 on line 6");
}

#[test]
fn duplicate_time_is_rejected() {
    expect_err(
        "10,1,0,0,-1\n10,1,0,0,-1\n",
        7,
        "duplicate time stamp 10 (also on line 6)",
    );
}

#[test]
fn truncated_last_line_is_rejected() {
    expect_err("0,1,0,0,-1\n10,1,0,0,-0.9", 7, "truncated last line");
    expect_err("0,1,0,0,-1\n10,1,0", 7, "truncated");
}

#[test]
fn wrong_field_count_is_rejected() {
    expect_err("0,1,0,0,-1,5\n", 6, "expected 5 fields, found 6");
}

#[test]
fn unknown_column_is_rejected() {
    let text = HEAD.replace("dir_z\n", "dir_z,pupil_mm\n") + "0,1,0,0,-1,3\n";
    let e = Trace::parse(&text, Path::new("t.csv"))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("t.csv:5: ") && e.contains("unknown column `pupil_mm`"),
        "{e}"
    );
}

#[test]
fn missing_required_column_is_rejected() {
    let text = HEAD.replace(",dir_z\n", "\n") + "0,1,0,0\n";
    let e = Trace::parse(&text, Path::new("t.csv"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("t.csv:5:") && e.contains("dir_z"), "{e}");
}

#[test]
fn wrong_version_is_rejected() {
    let e = Trace::parse(&HEAD.replace("trace 1", "trace 2"), Path::new("t.csv"))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("t.csv:1: ") && e.contains("version 2"), "{e}");
}

#[test]
fn empty_file_is_rejected() {
    let e = Trace::parse("", Path::new("t.csv"))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("t.csv:1: ") && e.contains("empty"), "{e}");
}

#[test]
fn header_without_samples_is_rejected() {
    expect_err_full(HEAD, "no sample rows");
}

fn expect_err_full(text: &str, needle: &str) {
    let e = Trace::parse(text, Path::new("t.csv"))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("t.csv:") && e.contains(needle), "{e}");
}

#[test]
fn unknown_or_missing_metadata_is_rejected() {
    expect_err_full(
        &HEAD.replace("# device: fove0\n", "# device: fove0\n# colour: red\n"),
        "unknown metadata key `colour`",
    );
    expect_err_full(&HEAD.replace("# rate_hz: 100\n", ""), "rate_hz");
    expect_err_full(
        &HEAD.replace("openxr-view", "unity-left-handed"),
        "coordinates",
    );
}

#[test]
fn tracked_without_valid_is_rejected() {
    let text = HEAD.replace("valid,", "valid,tracked,") + "0,0,1,0,0,-1\n";
    expect_err_full(&text, "tracked=1 requires valid=1");
}

#[test]
fn half_filled_per_eye_rays_are_rejected() {
    let cols = "time_ns,valid,dir_x,dir_y,dir_z,left_dir_x,left_dir_y,left_dir_z,right_dir_x,right_dir_y,right_dir_z\n";
    let text = HEAD.replace("time_ns,valid,dir_x,dir_y,dir_z\n", cols) + "0,1,0,0,-1,0,0,-1,,,\n";
    expect_err_full(&text, "pairs");
}

fn playback(body: &str) -> Playback {
    Playback::new(parse(body).unwrap(), HmdDescription::fove0())
}

#[test]
fn playback_interpolates_between_valid_neighbours_and_reports_time() {
    let r = 0.5f32.sqrt();
    let mut p = playback(&format!("0,1,0,0,-1\n10000000,1,{r},0,-{r}\n"));
    let exact = p.sample_at(10_000_000);
    assert_eq!(exact.time_kind, SampleTimeKind::Measured);
    assert_eq!(exact.gaze.direction.x, r);
    let mid = p.sample_at(5_000_000);
    assert_eq!(mid.time, 5_000_000);
    assert_eq!(mid.time_kind, SampleTimeKind::Interpolated);
    assert!((mid.gaze.direction.length() - 1.0).abs() < 1e-6);
    assert!(mid.gaze.direction.x > 0.0 && mid.gaze.direction.x < r);
}

#[test]
fn playback_clamps_outside_the_recording_with_real_times() {
    let mut p = playback("100,1,0,0,-1\n10000100,1,0,0,-1\n");
    assert_eq!(p.sample_at(-5).time, 100);
    assert_eq!(p.sample_at(1 << 40).time, 10_000_100);
    assert_eq!(p.sample_at(1 << 40).time_kind, SampleTimeKind::Measured);
}

#[test]
fn playback_never_interpolates_across_invalid_samples() {
    let mut p = playback("0,1,0,0,-1\n10000000,0,0,0,0\n20000000,1,0,0,-1\n");
    let s = p.sample_at(5_000_000);
    assert_eq!((s.time, s.valid), (0, true));
    let s = p.sample_at(15_000_000);
    assert_eq!((s.time, s.valid), (10_000_000, false));
}

#[test]
fn gap_longer_than_the_tracker_period_is_not_interpolated() {
    // 100 Hz trace with a 200 ms hole: hold the last sample for 1.5 periods, then "no gaze".
    let mut p = playback("0,1,0,0,-1\n10000000,1,0,0,-1\n210000000,1,1,0,0\n");
    assert_eq!(p.max_gap_ns(), 15_000_000);
    assert_eq!(p.sample_at(20_000_000).time, 10_000_000);
    let gap = p.sample_at(100_000_000);
    assert!(!gap.valid);
    assert_eq!(gap.time, 100_000_000);
    assert_eq!(gap.time_kind, SampleTimeKind::Unknown);
}

#[test]
fn playback_time_offset_and_alignment() {
    let mut p = playback("0,1,0,0,-1\n10000000,1,0,0,-1\n").aligned_to_first_frame();
    p.begin_frame(5_000_000_000).unwrap();
    assert_eq!(p.latest().time, 5_000_000_000);
    assert_eq!(p.sample_at(5_010_000_000).time, 5_010_000_000);
}

fn temp() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

#[test]
fn record_then_play_back_is_bit_exact() {
    let dir = temp();
    let path = dir.path().join("rec.csv");
    let mut rec = Recorder::create(SimulatedFove::fove0(9), &path, false).unwrap();
    let mut seen: Vec<GazeSample> = Vec::new();
    for k in 0..3000i64 {
        let t = k * 8_333_333 + 21_000_000;
        rec.begin_frame(t).unwrap();
        let s = rec.sample_at(t);
        if seen.last().is_none_or(|l| s.time > l.time) {
            seen.push(s);
        }
    }
    assert!(
        seen.iter().any(|s| !s.valid),
        "a blink should have been recorded"
    );
    assert_eq!(rec.samples_written(), seen.len());
    rec.finish().unwrap();
    let trace = Trace::load(&path).unwrap();
    assert_eq!(trace.header.device, "fove0");
    assert_eq!(trace.samples.len(), seen.len());
    let mut play = Playback::new(trace.clone(), HmdDescription::fove0());
    for (a, b) in seen.iter().zip(&trace.samples) {
        assert!(a.bit_eq(b), "{a:?}\n{b:?}");
        assert!(play.sample_at(a.time).bit_eq(a));
    }
    // Writing the loaded trace again gives the identical file.
    assert_eq!(trace.to_text(), std::fs::read_to_string(&path).unwrap());
}

#[test]
fn recorder_refuses_to_overwrite_unless_asked() {
    let dir = temp();
    let path = dir.path().join("rec.csv");
    std::fs::write(&path, "precious").unwrap();
    let e = Recorder::create(SimulatedFove::fove0(1), &path, false)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("rec.csv") && e.contains("already exists"), "{e}");
    let mut rec = Recorder::create(SimulatedFove::fove0(1), &path, true).unwrap();
    rec.sample_at(100_000_000);
    rec.finish().unwrap();
    assert!(Trace::load(&path).is_ok());
}

#[test]
fn abandoned_recording_leaves_no_file_behind() {
    let dir = temp();
    let path = dir.path().join("rec.csv");
    {
        let mut rec = Recorder::create(SimulatedFove::fove0(1), &path, false).unwrap();
        rec.sample_at(100_000_000);
        // Mid-recording only the temporary file exists, never the final name.
        assert!(!path.exists());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn trace_save_refuses_to_overwrite() {
    let dir = temp();
    let path = dir.path().join("t.csv");
    let t = parse("0,1,0,0,-1\n").unwrap();
    t.save(&path, false).unwrap();
    assert!(matches!(
        t.save(&path, false),
        Err(HalError::AlreadyExists { .. })
    ));
    t.save(&path, true).unwrap();
}

#[test]
fn gazebase_import_converts_degrees_and_flags() {
    let text = "n,x,y,val,xT,yT\n0,0,0,0,0,0\n1,10,0,0,0,0\n2,NaN,NaN,4,0,0\n3,0,-5,4,0,0\n";
    let t = import_gazebase_text(text, Path::new("g.csv"), &DegreesImport::default()).unwrap();
    assert_eq!(t.header.rate_hz, 1000.0);
    assert_eq!(t.samples[1].time, 1_000_000);
    let d = t.samples[1].gaze.direction;
    assert!((d.x.atan2(-d.z).to_degrees() - 10.0).abs() < 1e-4);
    assert!(!t.samples[2].valid && !t.samples[3].valid);
    // Imported traces are ordinary traces: they survive the text format.
    let again = Trace::parse(&t.to_text(), Path::new("g2.csv")).unwrap();
    assert!(again
        .samples
        .iter()
        .zip(&t.samples)
        .all(|(a, b)| a.bit_eq(b)));
}

#[test]
fn gazebase_vr_binocular_columns_become_per_eye_rays() {
    let text = "n,x,y,lx,ly,rx,ry,xT,yT,zT\n0,1,1,1.5,1,0.5,1,0,0,0\n4,2,1,NaN,NaN,2,1,0,0,0\n";
    let t = import_gazebase_text(text, Path::new("vr.csv"), &DegreesImport::default()).unwrap();
    assert_eq!(t.header.rate_hz, 250.0);
    assert!(t.samples[0].eyes.is_some());
    assert_eq!(t.samples[1].eye_state[0], fovea_hal::EyeState::NotDetected);
    assert!(t.samples[1].eyes.is_none() && t.samples[1].valid);
}

#[test]
fn gazebase_import_errors_name_file_and_line() {
    let opts = DegreesImport::default();
    let e = import_gazebase_text("n,x,y\n0,0,0\n0,1,1\n", Path::new("g.csv"), &opts)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("g.csv:3:") && e.contains("duplicate"), "{e}");
    let e = import_gazebase_text("n,x\n0,0\n", Path::new("g.csv"), &opts)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("g.csv:1:") && e.contains("`y`"), "{e}");
    let e = import_gazebase_text("n,x,y\n0,abc,0\n", Path::new("g.csv"), &opts)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("g.csv:2:") && e.contains("abc"), "{e}");
}

#[test]
fn normalized_import_uses_the_recording_fov() {
    let fov = Fov::from_degrees(-45.0, 45.0, -45.0, 45.0);
    let text = "time_ms,x,y\n0,0.5,0.5\n40,0,0\n80,1,1\n";
    let t = import_normalized_text(
        text,
        Path::new("e.csv"),
        &NormalizedImport::new("ehtask", fov),
    )
    .unwrap();
    assert!((t.samples[0].gaze.direction - Vec3::NEG_Z).length() < 1e-6);
    // Bottom-left origin: (0,0) is down-left at 45°/45° tangents.
    let d = t.samples[1].gaze.direction;
    assert!(
        (d - Vec3::new(-1.0, -1.0, -1.0).normalize()).length() < 1e-5,
        "{d}"
    );
    assert_eq!(t.header.rate_hz, 25.0);
    assert_eq!(t.header.fov_deg, Some([-45.0, 45.0, -45.0, 45.0]));
}
