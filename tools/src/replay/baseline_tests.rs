use super::*;
use std::time::Duration;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fovea-baseline-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

const SIZE: (u32, u32) = (4, 4);

fn params(frames: u32) -> Params {
    Params {
        scene: "cornell-box".into(),
        method: "vp".into(),
        denoiser: "none".into(),
        taa: "off".into(),
        headset: "fove0".into(),
        width: SIZE.0,
        height: SIZE.1,
        frames,
        seed: 1,
        max_depth: 3,
        blur_sigma_at_30: 6.8,
        reference_spp: 16,
        rings: 2,
        camera: String::new(),
        environment: String::new(),
        gaze_timing: String::new(),
    }
}

fn frame_pixels(k: u32) -> Vec<u8> {
    (0..SIZE.0 * SIZE.1)
        .flat_map(|i| [(i * 10 + k) as u8, (k * 40) as u8, 7, 255])
        .collect()
}

/// A two-frame 4×4 baseline of `sim:3` under `root`, written as `fovea replay --update-baseline`
/// writes one.
fn write_baseline(root: &Path, seed: u32) -> (TraceId, PathBuf) {
    let id = TraceId::of("sim:3").unwrap();
    let store = Store::open_update(root).unwrap();
    let mut staging = store.begin(&id).unwrap();
    for k in 0..2 {
        staging
            .write_frame(k, SIZE.0, SIZE.1, &frame_pixels(k + seed))
            .unwrap();
    }
    let baseline = Baseline {
        format: FORMAT.into(),
        trace: "sim:3".into(),
        trace_sha256: id.sha256.clone(),
        commit: "test".into(),
        device: "none".into(),
        params: Params { seed, ..params(2) },
        frames: (0..2)
            .map(|k| FrameRecord {
                frame: k,
                gaze: [2.0, 2.0],
                origin: "live".into(),
                quality_flip: vec![Some(0.1), None],
            })
            .collect(),
        passes: BTreeMap::from([("trace".to_string(), 1.5)]),
        files: Vec::new(),
    };
    staging
        .commit(baseline, SIZE.0, SIZE.1, &[[0.25, 0.5, 1.0, 1.0]; 16])
        .unwrap();
    (id.clone(), store.folder(&id))
}

fn load_err(root: &Path, id: &TraceId) -> String {
    let store = Store::open_read(root).unwrap();
    match store.load(id) {
        Ok(_) => panic!("the baseline loaded"),
        Err(e) => format!("{e:#}"),
    }
}

/// Edits `baseline.json` with `edit` (on its JSON value).
fn edit_manifest(dir: &Path, edit: impl FnOnce(&mut serde_json::Value)) {
    let path = dir.join(MANIFEST);
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    edit(&mut v);
    std::fs::write(&path, serde_json::to_string_pretty(&v).unwrap()).unwrap();
}

/// Replaces a listed file with `bytes` and records its size and SHA-256 in the manifest, as a
/// careless edit or a hostile baseline would: the checks must hold without the hash's help.
fn replace_listed(dir: &Path, name: &str, bytes: &[u8]) {
    std::fs::write(dir.join(name), bytes).unwrap();
    edit_manifest(dir, |v| {
        for f in v["files"].as_array_mut().unwrap() {
            if f["name"] == name {
                f["bytes"] = bytes.len().into();
                f["sha256"] = sha256_hex(bytes).into();
            }
        }
    });
}

#[test]
fn a_written_baseline_loads_with_every_file_checked() {
    let root = temp_dir("good");
    let (id, dir) = write_baseline(&root, 0);
    assert!(
        dir.ends_with(&id.key) && id.key.starts_with("sim-3-"),
        "{dir:?}"
    );
    let store = Store::open_read(&root).unwrap();
    let loaded = store.load(&id).unwrap();
    assert_eq!(loaded.baseline.files.len(), 3);
    assert_eq!(loaded.frame(1).unwrap(), frame_pixels(1));
    assert_eq!(loaded.reference[5], [0.25, 0.5, 1.0, 1.0]);
    // Only the baseline's folder and the lock remain: no staging folder.
    let mut names: Vec<String> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, [LOCK_FILE.to_string(), id.key.clone()]);
}

/// Two traces with one file name in different folders made one baseline folder (the second
/// overwrote the first); the key is the content's SHA-256.
#[test]
fn traces_of_one_name_get_separate_baselines() {
    let dir = temp_dir("names");
    let (a, b, c) = (dir.join("a"), dir.join("b"), dir.join("c"));
    for (folder, text) in [
        (&a, "t_ns,x\n1,2\n"),
        (&b, "t_ns,x\n1,3\n"),
        (&c, "t_ns,x\n1,2\n"),
    ] {
        std::fs::create_dir_all(folder).unwrap();
        std::fs::write(folder.join("trace.csv"), text).unwrap();
    }
    let id = |p: &Path| TraceId::of(&p.join("trace.csv").display().to_string()).unwrap();
    assert_ne!(id(&a).key, id(&b).key);
    assert!(id(&a).key.starts_with("trace-"));
    assert_eq!(id(&a), id(&c), "the same recording shares its baseline");
    assert_ne!(TraceId::of("sim:1").unwrap(), TraceId::of("sim:2").unwrap());
    assert_ne!(
        TraceId::of("sim:1").unwrap().sha256,
        TraceId::of("center").unwrap().sha256
    );
}

/// The replay's FLIP library panicked (exit 101) on a reference smaller than the frames.
#[test]
fn a_reference_of_another_size_is_named() {
    let root = temp_dir("small-ref");
    let (id, dir) = write_baseline(&root, 0);
    let small = temp_dir("small-ref-src").join("r.exr");
    crate::output::write_exr(&small, 2, 2, &[[1.0; 4]; 4]).unwrap();
    replace_listed(&dir, REFERENCE, &std::fs::read(&small).unwrap());
    let err = load_err(&root, &id);
    assert!(
        err.contains("reference.exr: the image is 2×2, expected 4×4"),
        "{err}"
    );
}

/// An EXR declaring 100000² pixels aborted on allocation (exit 134).
#[test]
fn a_reference_declaring_100000_squared_pixels_is_refused_from_its_header() {
    let root = temp_dir("huge-ref");
    let (id, dir) = write_baseline(&root, 0);
    replace_listed(
        &dir,
        REFERENCE,
        &fovea_test_kit::pictures::exr_declaring(100_000, 100_000),
    );
    let err = load_err(&root, &id);
    assert!(
        err.contains("reference.exr") && err.contains("100000×100000"),
        "{err}"
    );
}

#[test]
fn a_reference_with_nan_is_named_with_its_pixel() {
    let root = temp_dir("nan-ref");
    let (id, dir) = write_baseline(&root, 0);
    let src = temp_dir("nan-ref-src").join("r.exr");
    let mut texels = [[1.0f32; 4]; 16];
    texels[6][1] = f32::NAN;
    crate::output::write_exr(&src, 4, 4, &texels).unwrap();
    replace_listed(&dir, REFERENCE, &std::fs::read(&src).unwrap());
    let err = load_err(&root, &id);
    assert!(err.contains("reference.exr: pixel (2, 1)"), "{err}");
}

/// `baseline.json` claiming 100000 frames rendered for hours.
#[test]
fn frame_counts_are_bounded_and_consistent() {
    let root = temp_dir("frames");
    let (id, dir) = write_baseline(&root, 0);
    edit_manifest(&dir, |v| v["params"]["frames"] = 100_000.into());
    let err = load_err(&root, &id);
    assert!(
        err.contains("params.frames = 100000 must be in 1..=1000"),
        "{err}"
    );
    edit_manifest(&dir, |v| v["params"]["frames"] = 3.into());
    let err = load_err(&root, &id);
    assert!(
        err.contains("frames holds 2 records, params.frames says 3"),
        "{err}"
    );
    edit_manifest(&dir, |v| {
        v["params"]["frames"] = 2.into();
        v["files"].as_array_mut().unwrap().remove(1);
    });
    let err = load_err(&root, &id);
    assert!(
        err.contains("baseline.json: files lists 2 entries"),
        "{err}"
    );
}

#[test]
fn manifest_fields_are_checked() {
    let root = temp_dir("fields");
    let (id, dir) = write_baseline(&root, 0);
    type Edit = fn(&mut serde_json::Value);
    let cases: [(&str, Edit, &str); 6] = [
        (
            "trace",
            |v| v["trace_sha256"] = "0".repeat(64).into(),
            "belongs to another trace",
        ),
        (
            "format",
            |v| v["format"] = "fovea-replay-baseline 1".into(),
            "remake the baseline",
        ),
        (
            "gaze",
            |v| v["frames"][1]["gaze"][0] = 1e39.into(),
            "frames[1].gaze",
        ),
        (
            "origin",
            |v| v["frames"][0]["origin"] = "elsewhere".into(),
            "frames[0].origin",
        ),
        (
            "flip",
            |v| v["frames"][0]["quality_flip"][0] = 7.into(),
            "frames[0].quality_flip",
        ),
        (
            "bytes",
            |v| v["files"][0]["bytes"] = (1u64 << 40).into(),
            "files[frame_0000.png].bytes",
        ),
    ];
    let original = std::fs::read(dir.join(MANIFEST)).unwrap();
    for (case, edit, needle) in cases {
        std::fs::write(dir.join(MANIFEST), &original).unwrap();
        edit_manifest(&dir, edit);
        let err = load_err(&root, &id);
        assert!(
            err.contains("baseline.json") && err.contains(needle),
            "{case}: {err}"
        );
    }
}

/// A frame replaced after the baseline was made (or half of an interleaved update) is caught by
/// its size or SHA-256; one of another size by its header.
#[test]
fn changed_frames_are_named() {
    let root = temp_dir("changed");
    let (id, dir) = write_baseline(&root, 0);
    let good = std::fs::read(dir.join("frame_0001.png")).unwrap();
    let other = temp_dir("changed-src").join("f.png");
    crate::output::write_png(&other, SIZE.0, SIZE.1, &frame_pixels(9)).unwrap();
    std::fs::write(dir.join("frame_0001.png"), std::fs::read(&other).unwrap()).unwrap();
    let err = load_err(&root, &id);
    assert!(
        err.contains("frame_0001.png") && (err.contains("SHA-256") || err.contains("bytes")),
        "{err}"
    );
    std::fs::write(dir.join("frame_0001.png"), &good).unwrap();
    crate::output::write_png(&other, 8, 2, &[9u8; 64]).unwrap();
    replace_listed(&dir, "frame_0001.png", &std::fs::read(&other).unwrap());
    let err = load_err(&root, &id);
    assert!(
        err.contains("frame_0001.png: the image is 8×2, expected 4×4"),
        "{err}"
    );
}

/// A FIFO in place of a frame blocked the replay; a device was read.
#[test]
fn fifos_devices_and_links_in_a_baseline_are_refused_without_blocking() {
    let root = temp_dir("fifo");
    let (id, dir) = write_baseline(&root, 0);
    let frame = dir.join("frame_0001.png");
    std::fs::remove_file(&frame).unwrap();
    let c = std::ffi::CString::new(frame.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let (send, receive) = std::sync::mpsc::channel();
    let (r, i) = (root.clone(), id.clone());
    std::thread::spawn(move || send.send(load_err(&r, &i)).unwrap());
    let err = receive
        .recv_timeout(Duration::from_secs(20))
        .expect("loading a baseline with a FIFO frame blocked");
    assert!(
        err.contains("frame_0001.png") && err.contains("FIFO"),
        "{err}"
    );
    std::fs::remove_file(&frame).unwrap();
    std::os::unix::fs::symlink("/dev/zero", &frame).unwrap();
    let err = load_err(&root, &id);
    assert!(err.contains("frame_0001.png is a symbolic link"), "{err}");
}

/// A baseline folder that is a link was written through; now it is neither read nor replaced.
#[test]
fn a_linked_baseline_folder_is_neither_read_nor_written_through() {
    let root = temp_dir("link");
    let (id, dir) = write_baseline(&root, 0);
    let elsewhere = temp_dir("link-target");
    std::fs::rename(&dir, elsewhere.join("moved")).unwrap();
    std::os::unix::fs::symlink(elsewhere.join("moved"), &dir).unwrap();
    let err = load_err(&root, &id);
    assert!(err.contains("a symbolic link"), "{err}");
    let before = std::fs::read(elsewhere.join("moved/baseline.json")).unwrap();
    let store = Store::open_update(&root).unwrap();
    let mut staging = store.begin(&id).unwrap();
    staging.write_frame(0, 4, 4, &frame_pixels(5)).unwrap();
    let baseline = Baseline {
        format: FORMAT.into(),
        trace: "sim:3".into(),
        trace_sha256: id.sha256.clone(),
        commit: String::new(),
        device: String::new(),
        params: params(1),
        frames: Vec::new(),
        passes: BTreeMap::new(),
        files: Vec::new(),
    };
    let err = format!(
        "{:#}",
        staging.commit(baseline, 4, 4, &[[0.0; 4]; 16]).unwrap_err()
    );
    assert!(err.contains("a symbolic link"), "{err}");
    assert_eq!(
        std::fs::read(elsewhere.join("moved/baseline.json")).unwrap(),
        before
    );
    drop(store);
    let linked_root = temp_dir("link-root").join("root");
    std::os::unix::fs::symlink(&root, &linked_root).unwrap();
    let err = format!("{:#}", Store::open_update(&linked_root).err().unwrap());
    assert!(err.contains("a symbolic link"), "{err}");
}

/// An update that stops before its commit (a full disk, a signal) leaves the old baseline whole
/// and loadable, and no staging folder once the next update has run.
#[test]
fn an_update_that_stops_midway_leaves_the_old_baseline_whole() {
    let root = temp_dir("midway");
    let (id, dir) = write_baseline(&root, 0);
    let before: Vec<Vec<u8>> = ["frame_0000.png", "frame_0001.png", REFERENCE, MANIFEST]
        .iter()
        .map(|n| std::fs::read(dir.join(n)).unwrap())
        .collect();
    {
        let store = Store::open_update(&root).unwrap();
        let mut staging = store.begin(&id).unwrap();
        staging.write_frame(0, 4, 4, &frame_pixels(7)).unwrap();
        // A killed run leaves its staging folder behind: forget it instead of dropping it.
        std::mem::forget(staging);
    }
    let after: Vec<Vec<u8>> = ["frame_0000.png", "frame_0001.png", REFERENCE, MANIFEST]
        .iter()
        .map(|n| std::fs::read(dir.join(n)).unwrap())
        .collect();
    assert_eq!(before, after);
    Store::open_read(&root).unwrap().load(&id).unwrap();
    // The next update removes the dead run's staging folder; a complete one replaces the old.
    write_baseline(&root, 1);
    let loaded = Store::open_read(&root).unwrap().load(&id).unwrap();
    assert_eq!(loaded.frame(0).unwrap(), frame_pixels(1));
    assert_eq!(
        std::fs::read_dir(&root).unwrap().count(),
        2,
        "lock and baseline only"
    );
}

/// Two concurrent updates both exited 0, interleaving their files.
#[test]
fn a_second_update_or_a_replay_during_an_update_is_refused() {
    let root = temp_dir("locked");
    let (id, _) = write_baseline(&root, 0);
    let reading = Store::open_read(&root).unwrap();
    let err = format!("{:#}", Store::open_update(&root).err().unwrap());
    assert!(err.contains("in use by another fovea run"), "{err}");
    drop(reading);
    let updating = Store::open_update(&root).unwrap();
    let err = format!("{:#}", Store::open_update(&root).err().unwrap());
    assert!(err.contains("in use by another fovea run"), "{err}");
    let err = format!("{:#}", Store::open_read(&root).err().unwrap());
    assert!(err.contains("being updated"), "{err}");
    drop(updating);
    Store::open_read(&root).unwrap().load(&id).unwrap();
}
