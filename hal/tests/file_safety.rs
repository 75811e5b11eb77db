//! What hal reads from disk: only regular files within a documented size, so `--gaze /dev/zero`
//! or a FIFO fails at once with a clear error; a UTF-8 byte-order mark is accepted; `--gaze`
//! coordinates that are not finite or lie off the image are refused by name.

use fovea_hal::file::{MAX_PROFILE_BYTES, MAX_TRACE_BYTES};
use fovea_hal::trace::import::{import_gazebase, DegreesImport};
use fovea_hal::{GazeSpec, HalError, HmdDescription, Playback, SimConfig, Trace};
use std::path::{Path, PathBuf};
use std::time::Duration;

const TRACE: &str = "# fovea-gaze-trace 1\n# device: fove0\n# rate_hz: 100\n# coordinates: openxr-view\ntime_ns,valid,dir_x,dir_y,dir_z\n0,1,0,0,-1\n10000000,1,0,0,-1\n";

/// Fails the test if `f` blocks (a plain open of a FIFO waits for a writer forever).
fn within_seconds<T: Send + 'static>(seconds: u64, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(Duration::from_secs(seconds))
        .expect("reading blocked")
}

fn mkfifo(dir: &Path, name: &str) -> PathBuf {
    let path = dir.join(name);
    assert!(std::process::Command::new("mkfifo")
        .arg(&path)
        .status()
        .unwrap()
        .success());
    path
}

fn message(result: Result<impl Sized, HalError>) -> String {
    match result {
        Ok(_) => panic!("must be refused"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn devices_and_fifos_are_refused_without_reading_or_blocking() {
    let dir = tempfile::tempdir().unwrap();
    let msg = within_seconds(10, || {
        message(Playback::open(
            Path::new("/dev/zero"),
            HmdDescription::fove0(),
        ))
    });
    assert!(
        msg.contains("/dev/zero") && msg.contains("a device, not a regular file"),
        "{msg}"
    );
    let fifo = mkfifo(dir.path(), "gaze.csv");
    let msg = within_seconds(10, move || message(Trace::load(&fifo)));
    assert!(msg.contains("gaze.csv") && msg.contains("FIFO"), "{msg}");
    let fifo = mkfifo(dir.path(), "gazebase.csv");
    let msg = within_seconds(10, move || {
        message(import_gazebase(&fifo, &DegreesImport::default()))
    });
    assert!(msg.contains("FIFO"), "{msg}");
    let fifo = mkfifo(dir.path(), "headset.toml");
    let msg = within_seconds(10, move || message(HmdDescription::load(&fifo)));
    assert!(msg.contains("FIFO"), "{msg}");
    let msg = within_seconds(10, || message(SimConfig::load(Path::new("/dev/zero"))));
    assert!(msg.contains("a device"), "{msg}");
    // Through --gaze, as the CLI does.
    let spec: GazeSpec = "/dev/zero".parse().unwrap();
    let msg = within_seconds(10, move || message(spec.open(HmdDescription::fove0())));
    assert!(msg.contains("a device, not a regular file"), "{msg}");
}

#[test]
fn files_over_the_documented_size_are_refused_before_reading() {
    let dir = tempfile::tempdir().unwrap();
    // Sparse: no disk space, but the size is what a real oversized file reports.
    let big = dir.path().join("big.csv");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(MAX_TRACE_BYTES + 1)
        .unwrap();
    let msg = message(Trace::load(&big));
    assert!(
        msg.contains("big.csv")
            && msg.contains(&format!(
                "more than the {MAX_TRACE_BYTES}-byte limit for a gaze trace"
            )),
        "{msg}"
    );
    let toml = dir.path().join("big.toml");
    std::fs::File::create(&toml)
        .unwrap()
        .set_len(MAX_PROFILE_BYTES + 1)
        .unwrap();
    assert!(message(HmdDescription::load(&toml)).contains("limit for a headset profile"));
    let bad = dir.path().join("latin1.csv");
    std::fs::write(&bad, b"# fovea-gaze-trace 1\n\xe9\n").unwrap();
    assert!(message(Trace::load(&bad)).contains("not UTF-8 text (invalid byte at offset 21)"));
}

#[test]
fn a_utf8_byte_order_mark_is_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bom.csv");
    std::fs::write(&path, format!("\u{FEFF}{TRACE}")).unwrap();
    let with_bom = Trace::load(&path).unwrap();
    assert_eq!(with_bom, Trace::parse(TRACE, &path).unwrap());
    let csv = dir.path().join("gazebase.csv");
    std::fs::write(&csv, "\u{FEFF}n,x,y\n0,0,0\n4,1,0\n8,2,0\n").unwrap();
    assert_eq!(
        import_gazebase(&csv, &DegreesImport::default())
            .unwrap()
            .samples
            .len(),
        3
    );
    // A BOM in the middle is still content, and still wrong.
    assert!(Trace::parse(&format!("{TRACE}\u{FEFF}20000000,1,0,0,-1\n"), &path).is_err());
}

#[test]
fn gaze_coordinates_must_be_finite_and_on_the_image() {
    for input in [
        "NaN,5",
        "nan,5",
        "5,NaN",
        "inf,5",
        "-inf,5",
        "1e39,5",
        "infinity,0",
    ] {
        let msg = message(input.parse::<GazeSpec>());
        assert!(
            msg.contains(input) && msg.contains("finite pixel coordinates"),
            "{input}: {msg}"
        );
        assert!(
            !msg.contains("cannot read"),
            "{input} must not be taken for a file: {msg}"
        );
    }
    let far: GazeSpec = "1e30,5".parse().unwrap();
    assert_eq!(far, GazeSpec::Fixed { x: 1e30, y: 5.0 });
    let msg = message(far.open(HmdDescription::fove0()));
    assert!(
        msg.contains("outside the 1280×1440 left-eye image of headset `fove0`"),
        "{msg}"
    );
    assert!(message(
        "-5,10"
            .parse::<GazeSpec>()
            .unwrap()
            .open(HmdDescription::fove0())
    )
    .contains("outside"));
    assert!(
        "1280,1440"
            .parse::<GazeSpec>()
            .unwrap()
            .open(HmdDescription::fove0())
            .is_ok(),
        "the far corner is on the image"
    );
}
