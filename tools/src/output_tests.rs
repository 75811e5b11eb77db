use super::*;
use fovea_test_kit::file_names as names;

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("fovea-output-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn mkfifo(path: &Path) {
    assert!(std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .unwrap()
        .success());
}

#[test]
fn links_fifos_and_folders_are_never_written_through() {
    let d = dir("targets");
    std::fs::write(d.join("victim.txt"), "keep").unwrap();
    std::os::unix::fs::symlink(d.join("victim.txt"), d.join("frame_0000.png")).unwrap();
    let err = write_png(&d.join("frame_0000.png"), 1, 1, &[0, 0, 0, 255]).unwrap_err();
    assert!(err.to_string().contains("is a symbolic link"), "{err}");
    assert_eq!(
        std::fs::read_to_string(d.join("victim.txt")).unwrap(),
        "keep"
    );
    mkfifo(&d.join("out.exr"));
    // Refused without opening it (opening a FIFO for writing would block).
    let err = check_new_file(&d.join("out.exr"), true).unwrap_err();
    assert!(err.to_string().contains("FIFO"), "{err}");
    let err = write_exr(&d.join("out.exr"), 1, 1, &[[1.0; 4]]).unwrap_err();
    assert!(err.to_string().contains("FIFO"), "{err}");
    let err = check_new_file(Path::new("/dev/null"), true).unwrap_err();
    assert!(err.to_string().contains("a device"), "{err}");
}

#[test]
fn written_images_and_json_read_back() {
    let d = dir("roundtrip");
    write_png(&d.join("a.png"), 2, 1, &[255, 0, 0, 255, 0, 255, 0, 255]).unwrap();
    assert_eq!(
        image::open(d.join("a.png")).unwrap().to_rgba8().into_raw(),
        vec![255, 0, 0, 255, 0, 255, 0, 255]
    );
    write_exr(
        &d.join("a.exr"),
        2,
        1,
        &[[0.5, 1.0, 2.0, 1.0], [0.0, 0.25, 4.0, 1.0]],
    )
    .unwrap();
    let (w, h, px) = read_exr(&d.join("a.exr")).unwrap();
    assert_eq!((w, h, px[1][2]), (2, 1, 4.0));
    write_json(&d.join("r.json"), &serde_json::json!({"k": 1})).unwrap();
    assert_eq!(
        std::fs::read_to_string(d.join("r.json")).unwrap(),
        "{\n  \"k\": 1\n}\n"
    );
    assert!(
        write_exr(&d.join("b.exr"), 3, 1, &[[0.0; 4]]).is_err(),
        "size mismatch is an error, not a panic"
    );
}

#[test]
fn output_folders_refuse_links_and_a_second_concurrent_run() {
    let d = dir("locked");
    let held = prepare_output_dir(&d).unwrap();
    let err = prepare_output_dir(&d).unwrap_err();
    assert!(
        err.to_string().contains("in use by another fovea run"),
        "{err}"
    );
    drop(held);
    let again = prepare_output_dir(&d).unwrap();
    drop(again);

    let linked = dir("linked");
    std::os::unix::fs::symlink("/etc", linked.join("debug_grid_0000.png")).unwrap();
    let err = prepare_output_dir(&linked).unwrap_err();
    assert!(
        err.to_string()
            .contains("symbolic link 'debug_grid_0000.png'"),
        "{err}"
    );
    assert!(
        !linked.join(LOCK_FILE).exists(),
        "a refused folder is not touched"
    );
}

#[test]
fn stale_outputs_of_an_earlier_run_are_removed_and_leftover_temporaries_cleaned() {
    let d = dir("stale");
    for f in [
        "frame_0000.png",
        "frame_0001.png",
        "frame_0002.png",
        "frame_0000.exr",
        "report.json",
    ] {
        std::fs::write(d.join(f), "old run").unwrap();
    }
    std::fs::write(
        d.join(".frame_0001.png.4242.7.tmp"),
        "dead run's partial file",
    )
    .unwrap();
    let out = prepare_output_dir(&d).unwrap();
    assert!(!d.join(".frame_0001.png.4242.7.tmp").exists());
    write_png(&d.join("frame_0000.png"), 1, 1, &[0, 0, 0, 255]).unwrap();
    write_png(&d.join("frame_0001.png"), 1, 1, &[0, 0, 0, 255]).unwrap();
    write_text(&d.join("report.json"), "{}").unwrap();
    assert_eq!(out.remove_stale().unwrap(), 2);
    assert_eq!(
        names(&d),
        vec![LOCK_FILE, "frame_0000.png", "frame_0001.png", "report.json"]
    );
    assert_eq!(
        std::fs::read_to_string(d.join("report.json")).unwrap(),
        "{}"
    );
}

#[test]
fn exr_inputs_must_be_regular_files() {
    let d = dir("exr_inputs");
    mkfifo(&d.join("ref.exr"));
    let err = read_exr(&d.join("ref.exr")).unwrap_err();
    assert!(
        err.to_string()
            .contains("a FIFO (named pipe), not a regular file"),
        "{err}"
    );
    assert!(read_exr(Path::new("/dev/zero"))
        .unwrap_err()
        .to_string()
        .contains("a device"));
}
