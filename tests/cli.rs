//! The `fovea` command-line contract through its library: report.json keys and exact counts,
//! bad input named clearly, and user files never overwritten.

use fovea_renderer::passes::exposure::{AutoExposure, Exposure};
use fovea_tools::commands::reference::{run as reference, ReferenceArgs};
use fovea_tools::commands::render::{run as render, RenderArgs};
use fovea_tools::commands::setup::parse_exposure;
use std::path::{Path, PathBuf};

fn temp_dir(name: &str) -> PathBuf {
    let dir = fovea_tests::artifacts_dir().join(format!("cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn render_args<'a>(scene: &'a str, out: &'a Path) -> RenderArgs<'a> {
    fovea_tests::small_render_args(scene, out)
}

#[test]
fn render_writes_frames_and_a_report_with_exact_counts() {
    let out = temp_dir("render");
    render(&render_args("cornell-box", &out)).unwrap();
    for f in [
        "frame_0000.png",
        "frame_0001.png",
        "frame_0000.exr",
        "frame_0001.exr",
        "report.json",
    ] {
        assert!(out.join(f).exists(), "{f} missing");
    }
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    for key in [
        "method",
        "width",
        "height",
        "frames",
        "samples_traced",
        "screen_pixels",
        "rays_traced",
        "passes",
    ] {
        assert!(report.get(key).is_some(), "report.json lacks '{key}'");
    }
    assert_eq!(report["samples_traced"], 40 * 36);
    assert_eq!(report["screen_pixels"], 40 * 36);
    assert_eq!(report["frames"], 2);
    assert_eq!(report["gaze"].as_array().unwrap().len(), 2);
    assert!(report["rays_traced"].as_u64().unwrap() > 40 * 36);
    assert!(report["passes"]["trace"].as_f64().unwrap() > 0.0);
    // Rendering again into the same folder replaces only fovea's own files.
    render(&render_args("cornell-box", &out)).unwrap();
}

/// `--method vp-paper`: the grid and its exact sample count, off-screen samples, the passes back
/// to the screen, and the debug views (grid image, density heat map per frame, one density plot);
/// `--method vp` (the default screen-clipped layout) keeps its whole budget with the gaze in the
/// corner.
#[test]
fn visual_polar_render_reports_its_grid_and_writes_debug_views() {
    use fovea_renderer::sampling::{VisualPolar, VisualPolarParams};
    let out = temp_dir("render-vp");
    let mut args = render_args("cornell-box", &out);
    args.method = "vp-paper";
    args.gaze = "2,3";
    args.profile = fovea_tests::profile_with_blur();
    args.camera_path = Default::default();
    args.debug_views = true;
    render(&args).unwrap();
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let vp = VisualPolar::new(
        glam::UVec2::new(40, 36),
        glam::Vec2::new(2.0, 3.0),
        VisualPolarParams::default(),
    )
    .unwrap();
    assert_eq!(report["method"], "vp-paper");
    assert_eq!(report["visual_polar"]["layout"], "paper");
    assert_eq!(report["vp_width"], vp.grid_size().x);
    assert_eq!(report["vp_height"], vp.grid_size().y);
    assert_eq!(report["screen_pixels"], 40 * 36);
    // Gaze in a corner: most of the r_max circle is off the screen (≈ 76 % at full size); the
    // samples far off it are culled, those the way back reads are traced and counted.
    let count = |key: &str| report[key].as_u64().unwrap();
    // Per-frame means, each rounded down: their sum may fall one short.
    assert!(
        (count("samples_traced") + count("samples_culled")).abs_diff(vp.sample_count()) <= 1,
        "{report}"
    );
    assert_eq!(report["offscreen_samples"], "cull");
    let (offscreen, culled) = (count("samples_offscreen"), count("samples_culled"));
    assert!(
        offscreen > 0 && culled > 0 && offscreen + culled > vp.sample_count() / 2,
        "{report}"
    );
    assert_eq!(report["visual_polar"]["clip_fraction"], 0.12);
    for pass in ["trace", "mip_phi", "remap", "blur_h", "blur_v", "tonemap"] {
        assert!(
            report["passes"][pass].as_f64().unwrap() > 0.0,
            "pass {pass} missing"
        );
    }
    for f in [
        "debug_grid_0000.png",
        "debug_density_0001.png",
        "debug_overlay_0001.png",
        "debug_density_plot.png",
        "frame_0001.exr",
    ] {
        assert!(out.join(f).exists(), "{f} missing");
    }
    let grid = image::open(out.join("debug_grid_0000.png")).unwrap();
    assert_eq!(
        (grid.width(), grid.height()),
        (vp.grid_size().x, vp.grid_size().y)
    );
    // The default layout at the same corner gaze: every sample on the screen, none culled.
    let out = temp_dir("render-vp-default");
    let mut args = render_args("cornell-box", &out);
    args.method = "vp";
    args.gaze = "2,3";
    args.camera_path = Default::default();
    render(&args).unwrap();
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["visual_polar"]["layout"], "screen-clipped");
    let count = |key: &str| report[key].as_u64().unwrap();
    assert_eq!(count("samples_culled"), 0, "{report}");
    assert!(
        count("samples_traced").abs_diff(vp.sample_count()) <= 1,
        "{report}"
    );
}

/// `--vp-eccentricity headset` through every VP pass (trace, SVGF, TAA, φ-mips, remap, blur)
/// on the simulated FOVE 0: validation-clean, recorded in report.json, and the frame matches the
/// paper axis' frame of the same scene and gaze in its mean (both see the whole Cornell box).
#[test]
fn headset_eccentricity_runs_every_vp_pass() {
    use fovea_tools::render_profile::EccentricityMode;
    let mean_of = |out: &Path| {
        let img = image::open(out.join("frame_0002.png")).unwrap().to_rgb8();
        img.pixels()
            .map(|p| p.0.iter().map(|&c| c as f64).sum::<f64>() / 3.0)
            .sum::<f64>()
            / img.pixels().len() as f64
    };
    let mut means = Vec::new();
    for mode in [EccentricityMode::Normalized, EccentricityMode::Headset] {
        let out = temp_dir(&format!("render-vp-{mode:?}"));
        let mut args = render_args("cornell-box", &out);
        args.method = "vp";
        args.gaze = "12,20";
        args.frames = 3;
        args.profile = fovea_tests::profile_with_blur();
        args.camera_path = Default::default();
        args.denoiser = "svgf";
        args.taa = "vp";
        args.profile.eccentricity = mode;
        // The headset axis exists for the paper layout: both axes are compared on it.
        args.profile.visual_polar.layout = fovea_renderer::sampling::VpLayout::Paper;
        render(&args).unwrap();
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap())
                .unwrap();
        let name = fovea_tools::render_profile::eccentricity_name(mode);
        assert_eq!(report["visual_polar"]["eccentricity"], name);
        let inverse = if mode == EccentricityMode::Headset {
            "exact"
        } else {
            "polynomial"
        };
        assert_eq!(report["visual_polar"]["inverse_cdf"], inverse);
        for pass in [
            "trace",
            "svgf_temporal",
            "svgf_atrous",
            "taa",
            "mip_phi",
            "remap",
            "blur_h",
            "tonemap",
        ] {
            assert!(
                report["passes"][pass].as_f64().unwrap_or(0.0) > 0.0,
                "{name}: pass {pass} missing"
            );
        }
        means.push(mean_of(&out));
    }
    println!(
        "mean 8-bit value: normalized {:.1}, headset {:.1}",
        means[0], means[1]
    );
    assert!(
        means[1] > 5.0 && (means[1] / means[0] - 1.0).abs() < 0.15,
        "frame means {means:?}"
    );
}

#[test]
fn output_folders_with_user_files_are_refused() {
    let out = temp_dir("userfile");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let err = render(&render_args("cornell-box", &out))
        .unwrap_err()
        .to_string();
    assert!(err.contains("notes.txt"), "{err}");
    assert_eq!(
        std::fs::read_to_string(out.join("notes.txt")).unwrap(),
        "mine"
    );

    let exr = out.join("notes.txt");
    let args = ReferenceArgs {
        scene: "cornell-box",
        width: 8,
        height: 8,
        spp: 1,
        max_depth: 3,
        seed: 1,
        out: &exr,
        force: false,
        preview: false,
        device: None,
        validation: true,
        camera: &fovea_stage::look::NO_CAMERA_FLAGS,
        headset: "fove0",
        eye: fovea_hal::Eye::Left,
        environment: Default::default(),
        path_regularisation: 1.0,
    };
    let err = reference(&args).unwrap_err().to_string();
    assert!(err.contains("already exists"), "{err}");
    assert_eq!(std::fs::read_to_string(&exr).unwrap(), "mine");
}

#[test]
fn bad_scene_input_is_named_in_the_error() {
    let dir = temp_dir("badscene");
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("out");
    let err = format!(
        "{:#}",
        render(&render_args("no/such/scene.gltf", &out)).unwrap_err()
    );
    assert!(err.contains("no/such/scene.gltf"), "{err}");

    let malformed = dir.join("malformed.gltf");
    std::fs::write(
        &malformed,
        "{ \"asset\": { \"version\": \"2.0\" }, \"meshes\": [ ",
    )
    .unwrap();
    let err = format!(
        "{:#}",
        render(&render_args(malformed.to_str().unwrap(), &out)).unwrap_err()
    );
    assert!(err.contains("malformed.gltf"), "{err}");

    let draco = dir.join("draco.gltf");
    std::fs::write(
        &draco,
        r#"{"asset":{"version":"2.0"},"extensionsUsed":["KHR_draco_mesh_compression"],"extensionsRequired":["KHR_draco_mesh_compression"]}"#,
    )
    .unwrap();
    let err = format!(
        "{:#}",
        render(&render_args(draco.to_str().unwrap(), &out)).unwrap_err()
    );
    assert!(
        err.contains("draco.gltf") && err.contains("KHR_draco_mesh_compression"),
        "{err}"
    );

    let err = format!(
        "{:#}",
        render(&render_args("no-such-builtin", &out)).unwrap_err()
    );
    assert!(err.contains("no-such-builtin"), "{err}");
}

#[test]
fn bad_headset_and_gaze_arguments_are_named() {
    let out = temp_dir("badargs");
    let mut args = render_args("cornell-box", &out);
    args.headset = "no_such_headset";
    let err = format!("{:#}", render(&args).unwrap_err());
    assert!(err.contains("no_such_headset"), "{err}");
    let mut args = render_args("cornell-box", &out);
    args.gaze = "sim:notanumber";
    let err = format!("{:#}", render(&args).unwrap_err());
    assert!(err.contains("sim:notanumber"), "{err}");
    let mut args = render_args("cornell-box", &out);
    args.method = "magic";
    let err = format!("{:#}", render(&args).unwrap_err());
    assert!(err.contains("magic"), "{err}");
    // Not a file name and not a silent fallback to the centre.
    for (gaze, needle) in [
        ("NaN,5", "finite pixel coordinates"),
        ("1e30,5", "(1e30, 5.0) lies outside the 40×36 render image"),
        ("41,5", "outside"),
    ] {
        let mut args = render_args("cornell-box", &out);
        args.gaze = gaze;
        let err = format!("{:#}", render(&args).unwrap_err());
        assert!(
            err.contains(gaze) && err.contains(needle) && !err.contains("cannot read"),
            "{err}"
        );
    }
    let mut args = render_args("cornell-box", &out);
    args.gaze = "/dev/zero";
    let err = format!("{:#}", render(&args).unwrap_err());
    assert!(
        err.contains("/dev/zero") && err.contains("not a regular file"),
        "{err}"
    );
}

/// Runs `f` on a thread; fails the test when it takes longer than `seconds` (a write that opened a
/// FIFO would block forever).
fn within_seconds<T: Send + 'static>(seconds: u64, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(std::time::Duration::from_secs(seconds))
        .expect("the command blocked")
}

#[test]
fn a_symbolic_link_in_the_output_folder_is_refused() {
    let dir = temp_dir("symlink");
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(dir.join("victim.txt"), "keep me").unwrap();
    std::os::unix::fs::symlink(dir.join("victim.txt"), out.join("frame_0000.png")).unwrap();
    let err = format!(
        "{:#}",
        render(&render_args("cornell-box", &out)).unwrap_err()
    );
    assert!(err.contains("symbolic link 'frame_0000.png'"), "{err}");
    assert_eq!(
        std::fs::read_to_string(dir.join("victim.txt")).unwrap(),
        "keep me"
    );
    assert!(
        std::fs::symlink_metadata(out.join("frame_0000.png"))
            .unwrap()
            .file_type()
            .is_symlink(),
        "the link is left alone"
    );
}

/// Two renders started together into one folder: the lock lets exactly one write there; the
/// other is refused before it touches anything. Held explicitly, the lock refuses a run too.
#[test]
fn two_concurrent_renders_into_one_folder_are_refused() {
    let out = temp_dir("concurrent");
    let barrier = std::sync::Arc::new(std::sync::Barrier::new(2));
    let runs: Vec<_> = (0..2)
        .map(|_| {
            let (out, barrier) = (out.clone(), barrier.clone());
            std::thread::spawn(move || {
                let mut args = render_args("cornell-box", &out);
                args.frames = 8;
                barrier.wait();
                render(&args).map_err(|e| format!("{e:#}"))
            })
        })
        .collect();
    let results: Vec<Result<(), String>> = runs.into_iter().map(|t| t.join().unwrap()).collect();
    let refused: Vec<&String> = results.iter().filter_map(|r| r.as_ref().err()).collect();
    assert_eq!(
        refused.len(),
        1,
        "exactly one run may write into the folder: {results:?}"
    );
    assert!(
        refused[0].contains("in use by another fovea run"),
        "{}",
        refused[0]
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["frames"], 8);

    let held = fovea_tools::output::prepare_output_dir(&out).unwrap();
    let err = format!(
        "{:#}",
        render(&render_args("cornell-box", &out)).unwrap_err()
    );
    assert!(err.contains("in use by another fovea run"), "{err}");
    drop(held);
    render(&render_args("cornell-box", &out)).unwrap();
}

/// A rerun with fewer frames and without EXR leaves exactly its own outputs.
#[test]
fn a_rerun_removes_the_earlier_runs_stale_frames() {
    let out = temp_dir("stale");
    let mut args = render_args("cornell-box", &out);
    args.frames = 3;
    render(&args).unwrap();
    assert!(out.join("frame_0002.png").exists() && out.join("frame_0002.exr").exists());
    let mut args = render_args("cornell-box", &out);
    args.exr = false;
    render(&args).unwrap();
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        vec![
            ".fovea.lock",
            "frame_0000.png",
            "frame_0001.png",
            "report.json"
        ]
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(
        (report["frames"].as_u64(), report["interrupted"].as_bool()),
        (Some(2), Some(false))
    );
}

/// `fovea reference --force` replaces only regular files: a FIFO or a link as `--out` is refused
/// before rendering (writing would block or write through the link), and the target is untouched.
#[test]
fn reference_force_refuses_non_regular_targets() {
    let dir = temp_dir("force");
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = dir.join("pipe.exr");
    assert!(std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    std::fs::write(dir.join("victim.exr"), "old").unwrap();
    let link = dir.join("link.exr");
    std::os::unix::fs::symlink(dir.join("victim.exr"), &link).unwrap();
    for (target, kind) in [(fifo, "a FIFO"), (link, "a symbolic link")] {
        let err = within_seconds(60, move || {
            let args = ReferenceArgs {
                scene: "cornell-box",
                width: 8,
                height: 8,
                spp: 1,
                max_depth: 3,
                seed: 1,
                out: &target,
                force: true,
                preview: false,
                device: None,
                validation: true,
                camera: &fovea_stage::look::NO_CAMERA_FLAGS,
                headset: "fove0",
                eye: fovea_hal::Eye::Left,
                environment: Default::default(),
                path_regularisation: 1.0,
            };
            format!("{:#}", reference(&args).unwrap_err())
        });
        assert!(
            err.contains(kind) && err.contains("only writes or replaces regular files"),
            "{err}"
        );
    }
    assert_eq!(
        std::fs::read_to_string(dir.join("victim.exr")).unwrap(),
        "old"
    );
}

/// `fovea bench`'s real-time loop section alone (no scenes, no ray or VP sizes) at 64×72 with 3
/// timed frames per repeat: report.json's `loop` holds the three runs with counts that follow from
/// how each run submits. Figures measured in time are only checked to be there, never against a threshold.
#[test]
fn bench_loop_section_reports_each_runs_submits_waits_and_bytes() {
    use fovea_tools::commands::bench::{run as bench, BenchArgs};
    let out = temp_dir("bench-loop");
    let args = |loop_frames| BenchArgs {
        scenes: &[],
        builders: &[fovea_renderer::scene::bvh::BvhBuilder::DEFAULT],
        flatten: false,
        sizes: &[],
        vp_sizes: &[],
        vp_gaze: fovea_tools::commands::bench::CENTRED_GAZE,
        frames: 1,
        loop_size: Some((64, 72)),
        loop_frames,
        camera_path: None,
        out: &out,
        dump_rays: false,
        loop_scenes: &[],
        loop_headsets: &[],
        traversals: &[],
        device: None,
        validation: true,
    };
    let err = bench(&args(1)).unwrap_err().to_string();
    assert!(err.contains("--loop-frames"), "{err}");
    bench(&args(3)).unwrap();
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    for part in ["bvh", "rays", "visual_polar"] {
        assert_eq!(
            report[part].as_array().map(Vec::len),
            Some(0),
            "{part} was not skipped"
        );
    }
    let l = &report["loop"];
    assert_eq!(
        (
            l["width"].as_u64(),
            l["height"].as_u64(),
            l["frames"].as_u64()
        ),
        (Some(64), Some(72), Some(3))
    );
    assert_eq!(l["repeats"], 2);
    // (run, frames in flight, renderers = scene uploads, drains in 2 × 3 timed frames): one slot
    // waits for the newest frame every time; two slots never do.
    for (name, in_flight, renderers, drains) in [
        ("stereo_in_flight_1", 1, 1, 6),
        ("stereo_in_flight_2", 2, 1, 0),
        ("two_mono_in_flight_2", 2, 2, 0),
    ] {
        let run = &l[name];
        assert_eq!(run["timed_frames"], 6, "{name}");
        let f = |key: &str| {
            run[key]
                .as_f64()
                .unwrap_or_else(|| panic!("{name}.{key} missing"))
        };
        assert_eq!(run["frames_in_flight"], in_flight, "{name}");
        assert_eq!(run["renderers"], renderers, "{name}");
        assert_eq!(run["views_per_renderer"], 2 / renderers, "{name}");
        assert_eq!(
            f("submits_per_frame"),
            renderers as f64,
            "{name}: one submit per renderer and frame"
        );
        assert_eq!(
            f("fence_waits_per_frame"),
            renderers as f64,
            "{name}: one slot freed per renderer and frame"
        );
        assert_eq!(run["drain_waits"], drains, "{name}");
        for key in [
            "frames_per_second",
            "wall_ms_per_frame",
            "gpu_ms_per_frame",
            "host_ms_per_frame",
            "process_cpu_ms_per_frame",
        ] {
            assert!(
                f(key).is_finite() && f(key) > 0.0,
                "{name}.{key} = {}",
                f(key)
            );
        }
        assert!(
            f("others_cpu_ms_per_frame") >= 0.0 && f("steal_ms_per_frame") >= 0.0,
            "{name}"
        );
        assert!(
            (f("frames_per_second") * f("wall_ms_per_frame") / 1e3 - 1.0).abs() < 1e-9,
            "{name}"
        );
        let passes = run["passes_ms"].as_object().unwrap();
        // The default profile has no foveated blur: the remap writes the screen and one tonemap
        // pass the display image.
        assert!(
            ["trace", "svgf_temporal", "remap", "tonemap"]
                .iter()
                .all(|p| passes.contains_key(*p)),
            "{name}: passes {:?}",
            passes.keys()
        );
        assert!(
            !passes.keys().any(|p| p.starts_with("blur")),
            "{name}: a blur pass with the blur off"
        );
        let sum: f64 = passes.values().map(|v| v.as_f64().unwrap()).sum();
        assert!(
            (sum - f("gpu_ms_per_frame")).abs() < 1e-9 * sum.max(1.0),
            "{name}"
        );
    }
    let bytes = |name: &str, key: &str| l[name][key].as_i64().unwrap();
    // One scene shared by both eyes: stereo = scene + 2 views, two mono = 2 × (scene + view), so
    // two mono renders hold at least one more scene upload.
    let (stereo, mono) = (
        bytes("stereo_in_flight_2", "gpu_bytes"),
        bytes("two_mono_in_flight_2", "gpu_bytes"),
    );
    let scene = bytes("stereo_in_flight_2", "scene_bytes");
    assert!(scene > 0 && bytes("two_mono_in_flight_2", "scene_bytes") == 2 * scene);
    assert!(
        stereo < mono && mono - stereo >= scene && stereo > mono / 2,
        "stereo {stereo} B, two mono {mono} B, scene {scene} B"
    );
    let close = |a: f64, b: f64| (a / b - 1.0).abs() < 1e-9;
    assert!(close(
        l["stereo_vs_two_mono_bytes"].as_f64().unwrap(),
        stereo as f64 / mono as f64
    ));
    let fps = |name: &str| l[name]["frames_per_second"].as_f64().unwrap();
    assert!(close(
        l["in_flight_2_vs_1_fps"].as_f64().unwrap(),
        fps("stereo_in_flight_2") / fps("stereo_in_flight_1")
    ));
}

/// `fovea bench`'s headset loop alone (`--loop-scenes cornell-box --loop-headsets 64x72`, 2 timed
/// frames per repeat): report.json's `headset_loop` holds one entry with the three methods, each a
/// stereo renderer with 2 frames in flight running the passes of its method and denoiser, and the
/// VP / Cartesian ratios of those runs. Times are only checked to be there.
#[test]
fn bench_headset_loop_reports_each_method_per_scene_and_size() {
    use fovea_tools::commands::bench::{run as bench, BenchArgs};
    use fovea_tools::commands::bench_headsets::LoopHeadset;
    let out = temp_dir("bench-headset-loop");
    let scenes = ["cornell-box".to_string()];
    let headsets = LoopHeadset::parse_list("64x72").unwrap();
    let args = |loop_frames| BenchArgs {
        scenes: &[],
        builders: &[fovea_renderer::scene::bvh::BvhBuilder::DEFAULT],
        flatten: false,
        sizes: &[],
        vp_sizes: &[],
        vp_gaze: fovea_tools::commands::bench::CENTRED_GAZE,
        frames: 1,
        loop_size: None,
        loop_frames,
        camera_path: None,
        out: &out,
        dump_rays: false,
        loop_scenes: &scenes,
        loop_headsets: &headsets,
        traversals: &[],
        device: None,
        validation: true,
    };
    let err = bench(&args(1)).unwrap_err().to_string();
    assert!(err.contains("--loop-frames"), "{err}");
    bench(&args(2)).unwrap();
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert!(
        report["loop"].is_null(),
        "the real-time loop was not skipped"
    );
    let entries = report["headset_loop"].as_array().unwrap();
    assert_eq!(entries.len(), 1);
    let h = &entries[0];
    for (key, value) in [
        ("scene", "cornell-box"),
        ("headset", "fove0"),
        ("camera", "orbit"),
        ("gaze", "sim:1"),
    ] {
        assert_eq!(h[key], value, "{key}");
    }
    assert!(["cpu-driver", "gpu"].contains(&h["traversal"].as_str().unwrap()));
    assert_eq!(
        (
            h["width"].as_u64(),
            h["height"].as_u64(),
            h["eyes"].as_u64()
        ),
        (Some(64), Some(72), Some(2))
    );
    assert_eq!(
        (h["frames"].as_u64(), h["repeats"].as_u64()),
        (Some(2), Some(2))
    );
    let runs = h["runs"].as_array().unwrap();
    let names: Vec<(&str, &str)> = runs
        .iter()
        .map(|r| {
            (
                r["method"].as_str().unwrap(),
                r["denoiser"].as_str().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        names,
        [("vp", "svgf"), ("vp", "asvgf"), ("cartesian", "svgf")]
    );
    for (run, (method, denoiser)) in runs.iter().zip(names) {
        let name = format!("{method} + {denoiser}");
        assert_eq!(run["timed_frames"], 4, "{name}");
        assert_eq!(run["renderers"], 1, "{name}");
        assert_eq!(run["views_per_renderer"], 2, "{name}");
        assert_eq!(run["frames_in_flight"], 2, "{name}");
        assert_eq!(run["submits_per_frame"], 1.0, "{name}");
        for key in ["frames_per_second", "wall_ms_per_frame", "gpu_ms_per_frame"] {
            let v = run[key]
                .as_f64()
                .unwrap_or_else(|| panic!("{name}.{key} missing"));
            assert!(v.is_finite() && v > 0.0, "{name}.{key} = {v}");
        }
        let passes = run["passes_ms"].as_object().unwrap();
        let has = |pass: &str| passes.contains_key(pass);
        assert!(
            has("trace") && has("svgf_atrous"),
            "{name}: {:?}",
            passes.keys()
        );
        assert_eq!(has("asvgf_gradient"), denoiser == "asvgf", "{name}");
        // Only the VP frames go back to the screen through φ-mips and the remap.
        assert_eq!(has("mip_phi") && has("remap"), method == "vp", "{name}");
    }
    let ratio = |key: &str, of: &str| {
        let r = h[key].as_f64().unwrap();
        let expected = runs[0][of].as_f64().unwrap() / runs[2][of].as_f64().unwrap();
        assert!((r / expected - 1.0).abs() < 1e-9, "{key} {r} vs {expected}");
    };
    ratio("vp_vs_cartesian_frame_time", "wall_ms_per_frame");
    ratio("vp_vs_cartesian_gpu_ms", "gpu_ms_per_frame");
}

/// Values that would render a black, flat or meaningless frame without a word are refused
/// before the device opens, each error naming its flag and the rule.
#[test]
fn meaningless_values_are_refused_with_the_flag_named() {
    let out = temp_dir("values");
    let refused = |args: &RenderArgs, needles: &[&str]| {
        let err = format!("{:#}", render(args).unwrap_err());
        assert!(
            needles.iter().all(|n| err.contains(n)),
            "{needles:?}: {err}"
        );
    };
    for exposure in [f32::NAN, f32::INFINITY, -1.0, 0.0, 1e-30, 1e30] {
        let mut args = render_args("cornell-box", &out);
        args.exposure = Exposure::Manual(exposure);
        refused(&args, &["--exposure", "±13 stops"]);
    }
    let mut args = render_args("cornell-box", &out);
    args.exposure = Exposure::Auto(AutoExposure {
        compensation_ev: 20.0,
        ..AutoExposure::default()
    });
    refused(&args, &["--exposure auto+20", "±13 stops"]);
    // The flag's text: auto, auto±EV, or EV stops; anything else names the forms.
    assert_eq!(parse_exposure("auto").unwrap(), Exposure::auto());
    assert_eq!(
        parse_exposure("auto-1.5").unwrap(),
        Exposure::Auto(AutoExposure {
            compensation_ev: -1.5,
            ..AutoExposure::default()
        })
    );
    assert_eq!(parse_exposure("2").unwrap(), Exposure::Manual(4.0));
    assert_eq!(parse_exposure("-1").unwrap(), Exposure::Manual(0.5));
    for bad in [
        "",
        "automatic",
        "auto1",
        "auto+",
        "NaN",
        "inf",
        "14",
        "auto-14",
        "1e30",
    ] {
        let err = format!("{:#}", parse_exposure(bad).unwrap_err());
        assert!(err.contains("--exposure"), "{bad:?}: {err}");
    }
    for max_depth in [0, 65, u32::MAX] {
        let mut args = render_args("cornell-box", &out);
        args.max_depth = max_depth;
        refused(&args, &[&format!("--max-depth {max_depth}"), "1..=64"]);
    }
    // Visual-Polar: a 2×2 grid at least (3×3 screens at the default --vp-scale 2/3) and 2 pixels
    // per screen axis; Cartesian renders any size.
    for (w, h, needle) in [
        (1, 1, "no periphery"),
        (2, 2, "1×1 Visual-Polar grid"),
        (2, 40, "1×27 Visual-Polar grid"),
        (40, 1, "no periphery"),
    ] {
        let mut args = render_args("cornell-box", &out);
        (args.method, args.width, args.height) = ("vp", Some(w), Some(h));
        refused(
            &args,
            &[needle, "--width/--height", "--scale", "--method cartesian"],
        );
    }
    let mut args = render_args("cornell-box", &out);
    args.method = "vp";
    args.profile.visual_polar.axis_scale = 0.04; // --vp-scale 0.04: 40×36 → a 2×1 grid
    refused(
        &args,
        &["2×1 Visual-Polar grid", "--vp-scale 0.04", "at least 38×38"],
    );
    // A fixed radius within 10 screen diagonals (40×36: 538 px); a profile's value alike.
    let mut args = render_args("cornell-box", &out);
    args.method = "vp";
    args.profile.visual_polar.radius_mode = fovea_renderer::sampling::RadiusMode::Fixed(600.0);
    refused(
        &args,
        &["--vp-radius", "visual_polar.radius", "600 px", "538 px"],
    );
    assert!(!out.exists(), "nothing is written for a refused run");

    let out = temp_dir("values-ok");
    let mut args = render_args("cornell-box", &out);
    (args.method, args.width, args.height, args.frames, args.exr) =
        ("vp", Some(3), Some(3), 1, false);
    args.profile.visual_polar.radius_mode = fovea_renderer::sampling::RadiusMode::Fixed(42.0);
    (args.max_depth, args.exposure) = (64, Exposure::stops(13.0));
    render(&args).unwrap();
    let mut args = render_args("cornell-box", &out);
    (
        args.width,
        args.height,
        args.frames,
        args.exr,
        args.max_depth,
        args.exposure,
    ) = (Some(1), Some(1), 1, false, 1, Exposure::stops(-13.0));
    render(&args).unwrap();

    for max_depth in [0, 65] {
        let exr = out.join("ref.exr");
        let args = ReferenceArgs {
            scene: "cornell-box",
            width: 8,
            height: 8,
            spp: 1,
            max_depth,
            seed: 1,
            out: &exr,
            force: false,
            preview: false,
            device: None,
            validation: true,
            camera: &fovea_stage::look::NO_CAMERA_FLAGS,
            headset: "fove0",
            eye: fovea_hal::Eye::Left,
            environment: Default::default(),
            path_regularisation: 1.0,
        };
        let err = format!("{:#}", reference(&args).unwrap_err());
        assert!(err.contains("--max-depth"), "{err}");
    }
}

/// A gaze behind the eye or outside its view foveates at the image centre and is counted as
/// such in report.json (`gaze_centre`, `gaze_outside_view`), not as live.
#[test]
fn gaze_outside_the_view_is_reported_as_centre() {
    use fovea_hal::{GazeSample, HmdDescription, TraceWriter};
    use glam::Vec3;
    let out = temp_dir("gaze-outside");
    std::fs::create_dir_all(&out).unwrap();
    let hmd = HmdDescription::resolve("fove0").unwrap();
    let trace = out.with_extension("csv");
    let _ = std::fs::remove_file(&trace);
    let mut writer = TraceWriter::create(&hmd, &trace, false).unwrap();
    // Live ahead, behind the eye, 71.6° left (the FOVE 0 sees ±45°), live ahead again.
    let directions = [
        Vec3::NEG_Z,
        Vec3::Z,
        Vec3::new(-3.0, 0.0, -1.0).normalize(),
        Vec3::new(0.1, 0.0, -1.0).normalize(),
    ];
    for (k, d) in directions.iter().enumerate() {
        writer.write(&GazeSample::looking(
            fovea_stage::gaze::frame_time(1e9 / hmd.refresh_hz as f64, k as u32),
            k as u64,
            *d,
        ));
    }
    writer.finish().unwrap();
    for (method, eyes) in [
        ("cartesian", fovea_tools::commands::setup::Eyes::Left),
        ("vp", fovea_tools::commands::setup::Eyes::Both),
    ] {
        let mut args = render_args("cornell-box", &out);
        (
            args.method,
            args.eyes,
            args.frames,
            args.exr,
            args.camera_path,
        ) = (method, eyes, 4, false, Default::default());
        args.gaze = trace.to_str().unwrap();
        render(&args).unwrap();
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap())
                .unwrap();
        let counts = ["gaze_live", "gaze_held", "gaze_centre", "gaze_outside_view"]
            .map(|k| report[k].as_u64());
        assert_eq!(
            counts,
            [Some(2), Some(0), Some(2), Some(2)],
            "{method}: {report}"
        );
        for frame in [1, 2] {
            assert_eq!(
                report["gaze"][frame],
                serde_json::json!([20.0, 18.0]),
                "{method}: frame {frame} at the image centre"
            );
        }
    }
}

/// `--camera-path FILE`: keyframes drive the camera. A path that stands still at a point renders
/// exactly what the free camera at that point renders; one that moves changes the next frame;
/// report.json says which motion ran; a bad file is named.
#[test]
fn camera_path_files_drive_the_camera() {
    use fovea_stage::camera_path::CameraMotion;
    let dir = temp_dir("camera-keys");
    std::fs::create_dir_all(&dir).unwrap();
    let still = dir.join("still.toml");
    let keys = "[[key]]\ntime = 0\nposition = [0.2, 1.0, 3.4]\nlook = [0.0, 1.0, 0.0]\nfov = 50\n";
    std::fs::write(&still, format!("{keys}[[key]]\ntime = 10\nposition = [0.2, 1.0, 3.4]\nlook = [0.0, 1.0, 0.0]\nfov = 50\n")).unwrap();
    let moving = dir.join("moving.toml");
    // The headset's 70 Hz: frame 1 is shown 1/70 s in, a third of the way to the second key.
    std::fs::write(&moving, format!("{keys}[[key]]\ntime = 0.04\nposition = [-0.6, 1.3, 3.0]\nlook = [0.0, 1.0, 0.0]\nfov = 50\n")).unwrap();
    let frames = |out: &Path| {
        (0..2)
            .map(|i| std::fs::read(out.join(format!("frame_{i:04}.png"))).unwrap())
            .collect::<Vec<_>>()
    };

    let free = fovea_stage::look::CameraOptions {
        position: Some("0.2,1.0,3.4".into()),
        look: Some("0,1,0".into()),
        fov: Some(50.0),
        camera: None,
        projection: fovea_stage::look::Projection::SceneCamera,
        world_scale: 1.0,
    };
    let out_free = dir.join("free");
    let args = RenderArgs {
        camera: &free,
        camera_path: CameraMotion::Still,
        ..render_args("cornell-box", &out_free)
    };
    render(&args).unwrap();
    // The keys' fov is the scene camera's: both runs render through it.
    let scene_camera = fovea_stage::look::CameraOptions {
        projection: fovea_stage::look::Projection::SceneCamera,
        ..Default::default()
    };
    let out_still = dir.join("still");
    let args = RenderArgs {
        camera: &scene_camera,
        camera_path: CameraMotion::from_flag(Some(still.to_str().unwrap())).unwrap(),
        ..render_args("cornell-box", &out_still)
    };
    render(&args).unwrap();
    assert_eq!(
        frames(&out_free),
        frames(&out_still),
        "a path standing at the free camera's point renders the free camera's frames"
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_still.join("report.json")).unwrap())
            .unwrap();
    assert_eq!(
        (
            report["camera_path"].as_bool(),
            report["camera_motion"].as_str()
        ),
        (Some(true), Some("keys"))
    );

    let out_moving = dir.join("moving");
    let args = RenderArgs {
        camera: &scene_camera,
        camera_path: CameraMotion::from_flag(Some(moving.to_str().unwrap())).unwrap(),
        ..render_args("cornell-box", &out_moving)
    };
    render(&args).unwrap();
    let (moved, held) = (frames(&out_moving), frames(&out_still));
    assert_eq!(moved[0], held[0], "both paths start at the same key");
    assert_ne!(
        moved[1], held[1],
        "the moving path's second frame sees the scene from elsewhere"
    );

    assert_eq!(
        CameraMotion::from_flag(Some("orbit")).unwrap(),
        CameraMotion::Orbit
    );
    assert_eq!(CameraMotion::from_flag(None).unwrap(), CameraMotion::Still);
    let err = format!(
        "{:#}",
        CameraMotion::from_flag(Some(dir.join("absent.toml").to_str().unwrap())).unwrap_err()
    );
    assert!(
        err.contains("--camera-path") && err.contains("absent.toml"),
        "{err}"
    );
}

/// `fovea bench --camera-path FILE`: the VP vs Cartesian frames follow the keyframes and the ray
/// rates take their primary rays from frames along it, and the report says so.
#[test]
fn bench_vp_frames_follow_a_camera_path() {
    use fovea_stage::camera_keys::{CameraKeys, Key};
    use fovea_tools::commands::bench::{run as bench, BenchArgs};
    use glam::Vec3;
    let out = temp_dir("bench-camera-path");
    let key = |time, x| Key {
        time,
        position: Vec3::new(x, 1.0, 3.4),
        look: Vec3::new(0.0, 1.0, 0.0),
        fov: None,
    };
    let keys = CameraKeys::new(vec![key(0.0, -0.3), key(0.05, 0.3)]).unwrap();
    let scenes = ["cornell-box".to_string()];
    let args = BenchArgs {
        scenes: &scenes,
        builders: &[fovea_renderer::scene::bvh::BvhBuilder::DEFAULT],
        flatten: false,
        sizes: &[(32, 36)],
        vp_sizes: &[(64, 72)],
        vp_gaze: glam::Vec2::new(0.1, 0.05),
        frames: 2,
        loop_size: None,
        loop_frames: 2,
        camera_path: Some(&keys),
        out: &out,
        dump_rays: true,
        loop_scenes: &[],
        loop_headsets: &[],
        traversals: &[],
        device: None,
        validation: true,
    };
    bench(&args).unwrap();
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let vp = &report["visual_polar"][0];
    assert_eq!(vp["camera_motion"], "keys");
    assert!(
        vp["vp_frame_ms"].as_f64().unwrap() > 0.0
            && vp["cartesian_frame_ms"].as_f64().unwrap() > 0.0,
        "{vp}"
    );
    let comparators = vp["comparators"].as_array().unwrap();
    let methods: Vec<&str> = comparators
        .iter()
        .map(|c| c["method"].as_str().unwrap())
        .collect();
    assert_eq!(
        methods,
        [
            "uniform-budget",
            "log-polar",
            "linear-falloff",
            "random-acuity",
            "pixel-blocks",
            "composite",
            "vp-paper",
            "vp-screen-clipped",
            "vp-screen-aware",
            "vp-headset",
            "fixed-foveation",
            "vrs-tiles"
        ]
    );
    for c in comparators {
        assert!(
            c["samples"].as_u64().unwrap() > 0
                && c["frame_ms"].as_f64().unwrap() > 0.0
                && c["passes_ms"]["trace"].as_f64().unwrap() > 0.0,
            "{c}"
        );
    }
    // Random acuity traces Visual-Polar's samples.
    assert_eq!(comparators[3]["samples"], vp["vp_samples"]);
    // Fixed foveation: VP's samples, but around the lens centre, so far fewer of them lie off the
    // screen than the paper layout's around the gaze near the corner below.
    let (paper, fixed) = (&comparators[6], &comparators[10]);
    assert_eq!(fixed["samples"], vp["vp_samples"]);
    assert!(
        fixed["samples_traced"].as_u64() > paper["samples_traced"].as_u64(),
        "{fixed}"
    );
    // --vp-gaze near the top-left corner: most of the paper layout's circle lies off the screen,
    // and the samples far off it are culled; with every sample traced (the paper's way) all of
    // them are. The default layout keeps its whole budget on the screen.
    assert_eq!(vp["gaze"][0].as_f64(), Some(6.4), "{vp}");
    let (samples, traced) = (
        vp["vp_samples"].as_u64().unwrap(),
        paper["samples_traced"].as_u64().unwrap(),
    );
    assert_eq!(paper["samples"].as_u64(), Some(samples), "{paper}");
    // (At 64×72 the culling margin, three footprints and three pixels, keeps a large share.)
    assert!(traced < samples * 3 / 4, "{paper}");
    assert!(
        vp["vp_samples_traced"].as_u64().unwrap().abs_diff(samples) <= 1,
        "{vp}"
    );
    assert_eq!(
        vp["vp_offscreen_traced"]["samples_traced"].as_u64(),
        Some(samples),
        "{vp}"
    );
    assert!(
        vp["vp_offscreen_traced"]["frame_ratio"].as_f64().unwrap() > 0.0,
        "{vp}"
    );
    // The blur in the grid: its two passes and the tonemap instead of the screen blur's.
    let grid_blur = &vp["vp_grid_blur"]["passes_ms"];
    assert!(
        ["blur_grid_phi", "blur_grid_rho", "tonemap"]
            .iter()
            .all(|p| grid_blur[*p].as_f64().unwrap_or(0.0) > 0.0),
        "{grid_blur}"
    );
    assert!(
        grid_blur.get("blur_h").is_none() && grid_blur.get("blur_v_tonemap").is_none(),
        "{grid_blur}"
    );
    let share = vp["grid_blur_to_screen_share"].as_f64().unwrap();
    assert!(share > 0.0 && share < 1.0, "{vp}");
    // VP's rays against the screen's through the same pass: the per-sample overhead measured apart.
    let f = |key: &str| vp[key].as_f64().unwrap_or_else(|| panic!("{key} in {vp}"));
    assert!(
        f("screen_mrays_per_s") > 0.0 && f("screen_shuffled_mrays_per_s") > 0.0,
        "{vp}"
    );
    let ordered = f("screen_mrays_per_s") / f("vp_order_mrays_per_s");
    let shuffled = f("screen_shuffled_mrays_per_s") / f("shuffled_mrays_per_s");
    assert!(
        (f("vp_ray_cost_ordered") / ordered - 1.0).abs() < 1e-9
            && (f("vp_ray_cost_shuffled") / shuffled - 1.0).abs() < 1e-9,
        "{vp}"
    );
    // Each denoiser's whole frames hold its own passes and the rest of the frame (the frame-ratio
    // target with a denoiser).
    for d in vp["denoisers"].as_array().unwrap() {
        let g = |key: &str| d[key].as_f64().unwrap_or_else(|| panic!("{key} in {d}"));
        assert!(
            g("vp_frame_ms") > g("vp_ms") && g("cartesian_frame_ms") > g("cartesian_ms"),
            "{d}"
        );
        assert!(
            (g("frame_ratio") * g("cartesian_frame_ms") / g("vp_frame_ms") - 1.0).abs() < 1e-9,
            "{d}"
        );
    }
    let rays = &report["rays"][0];
    assert_eq!(
        rays["ray_poses"].as_u64(),
        Some(fovea_tools::commands::bench::PATH_RAY_POSES as u64),
        "{rays}"
    );
    assert!(
        rays["primary_mrays_per_s"].as_f64().unwrap() > 0.0,
        "{rays}"
    );
    // --dump-rays: the Cornell box's 36 triangles and the rays of every pose, 32 bytes each.
    let size = |kind: &str| {
        std::fs::metadata(out.join(format!("rays_cornell-box-32x36.{kind}.bin")))
            .unwrap()
            .len()
    };
    assert_eq!(size("triangles"), 36 * 9 * 4);
    assert_eq!(
        size("primary"),
        fovea_tools::commands::bench::PATH_RAY_POSES as u64 * 32 * 36 * 32
    );
    assert!(size("indirect") > 0 && size("indirect") % 32 == 0);
}

/// `--frames-in-flight` had no bound and was not capped by `--frames` (10⁶ slots passed 6 GB): a
/// run keeps at most as many frames in flight as it renders, and more than 8 is refused before
/// anything is allocated.
#[test]
fn frames_in_flight_are_bounded_and_capped_by_the_frame_count() {
    let out = temp_dir("in-flight");
    let capped = RenderArgs {
        frames: 2,
        frames_in_flight: 8,
        ..render_args("cornell-box", &out)
    };
    render(&capped).unwrap();
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["frames_in_flight"], 2);
    for n in [0, 9, 1_000_000] {
        let args = RenderArgs {
            frames_in_flight: n,
            ..render_args("cornell-box", &out)
        };
        let err = format!("{:#}", render(&args).unwrap_err());
        assert!(
            err.contains(&format!("--frames-in-flight {n} must be in 1..=8")),
            "{err}"
        );
    }
}
