//! `fovea eval` through its library entry point (as `tests/cli.rs` does for the other commands):
//! eval.json's fields and values on small synthetic EXRs, and bad input named in the error.
//! No GPU needed, except for `fovea quality`, which renders.

use fovea_tools::commands::eval::{run as eval, EvalArgs};
use fovea_tools::output::write_exr;
use std::path::{Path, PathBuf};

const W: u32 = 64;
const H: u32 = 72;

fn temp_dir(name: &str) -> PathBuf {
    let dir = fovea_tests::artifacts_dir().join(format!("eval-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A smooth image with some texture, so SSIM has structure to compare.
fn image(w: u32, h: u32) -> Vec<[f32; 4]> {
    (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            let v = 0.2 + 0.5 * x / w as f32 + 0.1 * ((x * 0.7).sin() * (y * 0.5).cos());
            [v, 0.8 * v, 0.3 + 0.2 * y / h as f32, 1.0]
        })
        .collect()
}

fn args<'a>(reference: &'a Path, test: &'a Path, gaze: &'a str, out: &'a Path) -> EvalArgs<'a> {
    EvalArgs {
        reference,
        test,
        gaze,
        rings: 10,
        out,
        headset: None,
        ppd: None,
    }
}

fn read_json(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("eval.json")).unwrap()).unwrap()
}

#[test]
fn identical_frames_score_perfectly() {
    let dir = temp_dir("identical");
    let reference = dir.join("ref.exr");
    write_exr(&reference, W, H, &image(W, H)).unwrap();
    let out = dir.join("out");
    eval(&args(&reference, &reference, "32,36", &out)).unwrap();
    assert!(out.join("eval.png").exists());
    let json = read_json(&out);
    assert_eq!(
        (json["width"].as_u64(), json["height"].as_u64()),
        (Some(W as u64), Some(H as u64))
    );
    assert_eq!(json["frame"]["rmse"], 0.0);
    assert_eq!(json["frame"]["ssim"], 1.0);
    assert_eq!(
        json["frame"]["psnr"],
        fovea_tools::eval::metrics::PSNR_CAP_DB
    );
    assert_eq!(json["frame"]["pixels"], W * H);
    let rings = json["rings"].as_array().unwrap();
    assert_eq!(rings.len(), 10);
    assert_eq!(
        rings
            .iter()
            .map(|r| r["pixels"].as_u64().unwrap())
            .sum::<u64>(),
        (W * H) as u64
    );
    let r_max = json["r_max_px"].as_f64().unwrap();
    assert!((r_max - (32f64.powi(2) + 36f64.powi(2)).sqrt()).abs() < 1e-9);
    for r in rings {
        for key in [
            "ring",
            "r_inner_px",
            "r_outer_px",
            "ecc_inner",
            "ecc_outer",
            "rmse",
            "psnr",
            "ssim",
        ] {
            assert!(r.get(key).is_some(), "ring lacks '{key}'");
        }
        assert_eq!(
            (&r["rmse"], &r["ssim"]),
            (&serde_json::json!(0.0), &serde_json::json!(1.0))
        );
    }
    assert_eq!(rings[9]["ecc_outer"], 80.0);
    // Running again into the same folder replaces only fovea's own files.
    eval(&args(&reference, &reference, "center", &out)).unwrap();
}

#[test]
fn peripheral_error_shows_only_in_outer_rings() {
    let dir = temp_dir("periphery");
    let (reference, test) = (dir.join("ref.exr"), dir.join("test.exr"));
    let clean = image(W, H);
    write_exr(&reference, W, H, &clean).unwrap();
    // Brighten every pixel farther than 30 px from the gaze (r_max ≈ 48.2 px; ring 6 starts at 28.9).
    let perturbed: Vec<_> = clean
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let (dx, dy) = (
                (i as u32 % W) as f32 + 0.5 - 32.0,
                (i as u32 / W) as f32 + 0.5 - 36.0,
            );
            if dx.hypot(dy) > 30.0 {
                [p[0] + 0.25, p[1] + 0.25, p[2] + 0.25, 1.0]
            } else {
                *p
            }
        })
        .collect();
    write_exr(&test, W, H, &perturbed).unwrap();
    let out = dir.join("out");
    eval(&args(&reference, &test, "32,36", &out)).unwrap();
    let json = read_json(&out);
    let rings = json["rings"].as_array().unwrap();
    // Rings 0..=3 end at 19.3 px: their 11×11 SSIM windows (reaching 5√2 ≈ 7.1 px) stay inside
    // the clean disc.
    for r in &rings[..4] {
        assert_eq!(r["rmse"], 0.0, "inner ring {r}");
        assert_eq!(r["ssim"], 1.0, "inner ring {r}");
    }
    for r in &rings[7..] {
        let rmse = r["rmse"].as_f64().unwrap();
        assert!((rmse - 0.25).abs() < 1e-6, "outer ring {r}");
        assert!(
            r["psnr"].as_f64().unwrap() < 13.0 && r["ssim"].as_f64().unwrap() < 1.0,
            "outer ring {r}"
        );
    }
    assert!(json["frame"]["rmse"].as_f64().unwrap() > 0.0);
}

#[test]
fn bad_inputs_are_named_in_the_error() {
    let dir = temp_dir("bad");
    let out = dir.join("out");
    let good = dir.join("good.exr");
    write_exr(&good, W, H, &image(W, H)).unwrap();

    let mut with_nan = image(W, H);
    with_nan[5 * W as usize + 3][1] = f32::NAN;
    let nan = dir.join("nan.exr");
    write_exr(&nan, W, H, &with_nan).unwrap();
    let err = format!("{:#}", eval(&args(&good, &nan, "32,36", &out)).unwrap_err());
    assert!(err.contains("nan.exr") && err.contains("(3, 5)"), "{err}");

    let small = dir.join("small.exr");
    write_exr(&small, 32, 36, &image(32, 36)).unwrap();
    let err = format!(
        "{:#}",
        eval(&args(&good, &small, "16,18", &out)).unwrap_err()
    );
    assert!(
        err.contains("small.exr") && err.contains("32×36") && err.contains("64×72"),
        "{err}"
    );

    let missing = dir.join("missing.exr");
    let err = format!(
        "{:#}",
        eval(&args(&missing, &good, "32,36", &out)).unwrap_err()
    );
    assert!(err.contains("missing.exr"), "{err}");

    let not_exr = dir.join("notes.exr");
    std::fs::write(&not_exr, "not an image").unwrap();
    let err = format!(
        "{:#}",
        eval(&args(&good, &not_exr, "32,36", &out)).unwrap_err()
    );
    assert!(err.contains("notes.exr"), "{err}");

    for gaze in ["100,10", "10,-1", "nan,3", "inf,3", "12"] {
        let err = format!("{:#}", eval(&args(&good, &good, gaze, &out)).unwrap_err());
        assert!(err.contains(gaze), "{gaze}: {err}");
    }
    // --rings: 1..=1000, and at most the half-diagonal (48.2 px for 64×72) so that no ring is
    // narrower than a pixel. Unchecked, 10⁸ rings abort on allocation and 10⁶ write a 256 MB
    // eval.json.
    for (rings, needle) in [
        (0, "1..=1000"),
        (1001, "1..=1000"),
        (1_000_000, "1..=1000"),
        (100_000_000, "1..=1000"),
        (49, "at most 48 rings"),
    ] {
        let err = format!(
            "{:#}",
            eval(&EvalArgs {
                rings,
                ..args(&good, &good, "32,36", &out)
            })
            .unwrap_err()
        );
        assert!(
            err.contains(&format!("--rings {rings}")) && err.contains(needle),
            "{rings}: {err}"
        );
    }
    // Nothing was written for failed runs.
    assert!(!out.exists());
    eval(&EvalArgs {
        rings: 48,
        ..args(&good, &good, "0,0", &out)
    })
    .unwrap();
    assert!(
        read_json(&out)["rings"]
            .as_array()
            .unwrap()
            .iter()
            .all(|r| r["pixels"].as_u64().unwrap() > 0),
        "every ring holds pixels"
    );
    std::fs::remove_dir_all(&out).unwrap();

    // A folder holding the user's files is refused and left alone.
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("mine.txt"), "mine").unwrap();
    let err = format!(
        "{:#}",
        eval(&args(&good, &good, "32,36", &out)).unwrap_err()
    );
    assert!(err.contains("mine.txt"), "{err}");
    assert_eq!(
        std::fs::read_to_string(out.join("mine.txt")).unwrap(),
        "mine"
    );
}

/// `fovea quality` of the Cornell box at 40×36 for `[methods, denoisers, taa, cameras]`: 3 frames,
/// the last 2 evaluated against 4-spp references, 4 rings, validation on.
fn quality_args<'a>(
    [methods, denoisers, taa, cameras]: [&'a [String]; 4],
    out: &'a std::path::Path,
) -> fovea_tools::commands::quality::QualityArgs<'a> {
    fovea_tools::commands::quality::QualityArgs {
        scene: "cornell-box",
        width: 40,
        height: 36,
        headset: "fove0",
        gaze: "sim:2",
        frames: 3,
        eval_frames: 2,
        methods,
        denoisers,
        taa,
        cameras,
        reference_spp: 4,
        rings: 4,
        seed: 1,
        profile: Default::default(),
        eyes: fovea_tools::commands::setup::Eyes::Left,
        stereo_noises: &[],
        camera: &fovea_stage::look::NO_CAMERA_FLAGS,
        references: None,
        display_exposure: fovea_tools::commands::quality::DisplayExposure::Stops(0.0),
        out,
        device: None,
        validation: true,
    }
}

/// `fovea quality` on a tiny sequence: every combination of the asked methods, denoisers, TAA
/// modes and cameras is rendered and measured against references of its own camera poses; the
/// folder can be reused; bad names and foreign files are refused.
#[test]
fn quality_command_measures_every_combination() {
    use fovea_tools::commands::quality::{run, QualityArgs};
    let out = temp_dir("quality");
    let strings = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let (methods, denoisers, taa, cameras) = (
        strings(&["vp", "cartesian"]),
        strings(&["none"]),
        strings(&["off", "screen"]),
        strings(&["still", "moving"]),
    );
    let args = |d| QualityArgs {
        denoisers: d,
        ..quality_args([&methods, &denoisers, &taa, &cameras], &out)
    };
    for _ in 0..2 {
        run(&args(&denoisers)).unwrap();
    }
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("quality.json")).unwrap()).unwrap();
    let runs = report["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 2 * 2 * 2, "{runs:?}");
    for r in runs {
        assert_eq!(r["rings"].as_array().unwrap().len(), 4);
        assert_eq!(r["frames"], serde_json::json!([1, 2]));
        let rmse = r["frame_rmse"].as_f64().unwrap();
        assert!(rmse.is_finite() && rmse > 0.0, "{r}");
        // FLIP and flicker (1 spp without a denoiser: every frame differs from the last).
        let (flip, flicker) = (
            r["frame_flip"].as_f64().unwrap(),
            r["frame_flicker"].as_f64().unwrap(),
        );
        assert!(
            flip > 0.0 && flip < 1.0 && flicker > 0.0 && flicker < 1.0,
            "{r}"
        );
        assert!(
            r["rings"]
                .as_array()
                .unwrap()
                .iter()
                .all(|ring| ring["flip"].is_number() && ring["flicker"].is_number()),
            "{r}"
        );
    }
    // A still camera needs one reference; a moving one a reference per evaluated frame.
    for name in [
        "reference_still_0000.exr",
        "reference_moving_0001.exr",
        "reference_moving_0002.exr",
    ] {
        assert!(out.join(name).is_file(), "{name} missing");
    }
    // Each reference also as displayed (what scripts/perceptual judges): the EXR through the
    // runs' exposure and tone curve.
    for name in ["reference_still_0000", "reference_moving_0002"] {
        let (_, _, linear) =
            fovea_tools::output::read_exr(&out.join(format!("{name}.exr"))).unwrap();
        let displayed = image::open(out.join(format!("{name}.png")))
            .unwrap()
            .to_rgba8();
        let expected = fovea_tools::output::tonemap_preview(
            &linear,
            1.0,
            fovea_renderer::passes::tonemap::ToneCurve::Aces,
        );
        assert_eq!(displayed.as_raw(), &expected, "{name}.png");
    }
    // What a video metric needs of the display, and where each run's frames are.
    assert_eq!(report["refresh_hz"], 70.0);
    assert_eq!(
        report["eye_fov_deg"][1].as_f64().map(|d| d.round()),
        Some(45.0)
    );
    for r in runs {
        let dir = out.join(r["run_dir"].as_str().unwrap());
        assert!(dir.join("frame_0002.png").is_file(), "{r}");
    }
    perceptual_report_reads_the_scores(&out, runs);
    let table = std::fs::read_to_string(out.join("quality.md")).unwrap();
    assert!(
        table.contains("**moving camera**")
            && table.contains("| vp + none, screen |")
            && table.contains("Temporal flicker"),
        "{table}"
    );
    let bad = strings(&["nlm"]);
    let err = format!("{:#}", run(&args(&bad)).unwrap_err());
    assert!(err.contains("--denoisers nlm"), "{err}");
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let err = format!("{:#}", run(&args(&denoisers)).unwrap_err());
    assert!(err.contains("notes.txt"), "{err}");
}

/// `fovea quality --references`: a run at another sample budget (a profile's VP grid) takes an
/// earlier folder's references byte for byte instead of rendering them, and is judged against
/// them; a folder of other reference settings is refused, naming the key.
#[test]
fn quality_reuses_the_references_of_the_same_settings() {
    use fovea_renderer::passes::exposure::{metered_exposure, AutoExposure};
    use fovea_renderer::passes::tonemap::ToneCurve;
    use fovea_tools::commands::quality::{run, DisplayExposure, QualityArgs};
    let (first, second) = (temp_dir("references-a"), temp_dir("references-b"));
    let strings = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let (methods, denoisers, taa, cameras) = (
        strings(&["vp"]),
        strings(&["none"]),
        strings(&["off"]),
        strings(&["still"]),
    );
    run(&quality_args(
        [&methods, &denoisers, &taa, &cameras],
        &first,
    ))
    .unwrap();
    let mut profile = fovea_tools::render_profile::RenderProfile::default();
    profile.visual_polar.axis_scale = 0.5;
    let reusing = QualityArgs {
        profile,
        references: Some(&first),
        ..quality_args([&methods, &denoisers, &taa, &cameras], &second)
    };
    run(&reusing).unwrap();
    for name in ["reference_still_0000.exr", "reference_still_0000.png"] {
        assert_eq!(
            std::fs::read(first.join(name)).unwrap(),
            std::fs::read(second.join(name)).unwrap(),
            "{name}"
        );
    }
    let samples = |dir: &Path| {
        let q: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("quality.json")).unwrap())
                .unwrap();
        assert!(q["runs"][0]["frame_rmse"].as_f64().unwrap() > 0.0, "{q}");
        q["runs"][0]["samples_traced"].as_u64().unwrap()
    };
    assert!(samples(&second) < samples(&first));

    // Displayed at the exposure metered on the reference: the references' PNGs and the run's
    // frames at that one exposure, recorded per run.
    let metered_dir = temp_dir("references-metered");
    run(&QualityArgs {
        display_exposure: DisplayExposure::Metered,
        out: &metered_dir,
        ..reusing.clone()
    })
    .unwrap();
    let (w, h, reference) =
        fovea_tools::output::read_exr(&metered_dir.join("reference_still_0000.exr")).unwrap();
    let flat = AutoExposure {
        gaze_boost: 0.0,
        ..Default::default()
    };
    let m = metered_exposure(&reference, w, h, &flat, glam::Vec2::ZERO, 1.0);
    assert!(
        m > 1.2,
        "the Cornell box meters brighter than exposure 1: {m}"
    );
    let png = |dir: &Path, name: &str| image::open(dir.join(name)).unwrap().to_rgba8().into_raw();
    assert_eq!(
        png(&metered_dir, "reference_still_0000.png"),
        fovea_tools::output::tonemap_preview(&reference, m, ToneCurve::Aces),
        "the reference as displayed at the metered exposure"
    );
    let q: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(metered_dir.join("quality.json")).unwrap())
            .unwrap();
    assert_eq!(q["runs"][0]["display_exposure"].as_f64().unwrap() as f32, m);
    let run_dir = q["runs"][0]["run_dir"].as_str().unwrap();
    let mean = |v: Vec<u8>| v.iter().map(|&b| b as f64).sum::<f64>() / v.len() as f64;
    let (bright, plain) = (
        mean(png(&metered_dir.join(run_dir), "frame_0002.png")),
        mean(png(&second.join(run_dir), "frame_0002.png")),
    );
    assert!(
        bright > plain * 1.1,
        "the run's frames are displayed at the metered exposure: mean {bright} vs {plain} at 1"
    );

    let other = QualityArgs {
        reference_spp: 8,
        ..reusing
    };
    let err = format!("{:#}", run(&other).unwrap_err());
    assert!(
        err.contains("reference_key") && err.contains("spp 8"),
        "{err}"
    );
}

/// `fovea perceptual-report` on a quality folder with hand-written FovVideoVDP scores (the
/// scorer itself, scripts/perceptual, is offline): one table row per run with its JOD and
/// samples, a plot per cost axis and camera; missing or stale scores are refused by name.
fn perceptual_report_reads_the_scores(quality: &Path, runs: &[serde_json::Value]) {
    use fovea_tools::commands::perceptual_report::{run, PerceptualReportArgs};
    let out = quality.with_extension("perceptual");
    let _ = std::fs::remove_dir_all(&out);
    let folders = [quality.to_path_buf()];
    let args = PerceptualReportArgs {
        folders: &folders,
        out: &out,
    };
    let err = format!("{:#}", run(&args).unwrap_err());
    assert!(
        err.contains("no perceptual.json") && err.contains("scripts/perceptual"),
        "{err}"
    );
    let scored: Vec<serde_json::Value> = runs
        .iter()
        .enumerate()
        .map(|(i, r)| serde_json::json!({ "run_dir": r["run_dir"], "jod": 5.0 + i as f64 * 0.125 }))
        .collect();
    let perceptual = |runs: &[serde_json::Value]| {
        serde_json::json!({
            "metric": "FovVideoVDP", "scene": "cornell-box", "width": 40, "height": 36,
            "gaze_source": "sim:2", "frames_per_second": 70.0, "pixels_per_degree": 0.5,
            "runs": runs,
        })
        .to_string()
    };
    let path = quality.join("perceptual.json");
    std::fs::write(&path, perceptual(&scored)).unwrap();
    run(&args).unwrap();
    let md = std::fs::read_to_string(out.join("perceptual.md")).unwrap();
    for (i, r) in runs.iter().enumerate() {
        let row = format!(
            "| {} + {}, taa {} | {} |",
            r["method"].as_str().unwrap(),
            r["denoiser"].as_str().unwrap(),
            r["taa"].as_str().unwrap(),
            r["samples_traced"]
        );
        let jod = format!("{:.3} |", 5.0 + i as f64 * 0.125);
        assert!(
            md.lines().any(|l| l.contains(&row) && l.contains(&jod)),
            "no row {row} … {jod} in\n{md}"
        );
    }
    for camera in ["still", "moving"] {
        for axis in ["samples", "gpu_ms"] {
            let png = out.join(format!("jod_{axis}_cornell-box_40x36_sim-2_{camera}.png"));
            assert!(png.is_file(), "{} missing", png.display());
        }
    }
    let mut stale = scored.clone();
    stale[0]["run_dir"] = "run_still_gone_none_taa-off".into();
    std::fs::write(&path, perceptual(&stale)).unwrap();
    let err = format!("{:#}", run(&args).unwrap_err());
    assert!(
        err.contains("run_still_gone_none_taa-off") && err.contains("score the folder again"),
        "{err}"
    );
    std::fs::remove_file(&path).unwrap();
}

/// `fovea quality --eyes both --stereo-noise independent,surface`: each run renders both eyes,
/// judges each against its own reference and adds the binocular measure (per ring, beside the
/// converged pair's, with the flicker of the eyes' difference) to quality.json and quality.md.
#[test]
fn quality_of_both_eyes_adds_the_binocular_measure() {
    use fovea_renderer::frame::StereoNoise;
    use fovea_tools::commands::quality::{run, QualityArgs};
    use fovea_tools::commands::setup::Eyes;
    let out = temp_dir("quality-stereo");
    let strings = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let (methods, denoisers, taa, cameras) = (
        strings(&["cartesian"]),
        strings(&["svgf"]),
        strings(&["off"]),
        strings(&["still", "moving"]),
    );
    let noises = [StereoNoise::Independent, StereoNoise::Surface];
    run(&QualityArgs {
        eyes: Eyes::Both,
        stereo_noises: &noises,
        ..quality_args([&methods, &denoisers, &taa, &cameras], &out)
    })
    .unwrap();
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("quality.json")).unwrap()).unwrap();
    assert_eq!(report["eyes"], "both");
    let runs = report["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 2 * 2, "{runs:?}");
    for r in runs {
        let b = &r["binocular"];
        let finite = |v: &serde_json::Value| v.as_f64().is_some_and(|x| x.is_finite() && x >= 0.0);
        assert!(finite(&b["frame"]["difference"]), "{b}");
        assert!(finite(&b["frame"]["reference_difference"]), "{b}");
        assert!(finite(&b["frame"]["difference_flicker"]), "{b}");
        let seen = b["frame"]["visible_in_both"].as_f64().unwrap();
        assert!(seen > 0.5 && seen <= 1.0, "{b}");
        assert_eq!(b["rings"].as_array().unwrap().len(), 4);
        let right = &b["right_eye"];
        assert!(
            finite(&right["frame_flip"]) && finite(&right["frame_flicker"]),
            "{b}"
        );
        assert_eq!(right["rings"].as_array().unwrap().len(), 4);
    }
    let noise_of = |r: &serde_json::Value| r["stereo_noise"].as_str().unwrap().to_string();
    assert_eq!(noise_of(&runs[0]), "independent");
    assert_eq!(noise_of(&runs[1]), "surface");
    // The default profile's cross-eye reuse (`auto`) runs with SVGF: each run's report says so.
    assert!(
        runs.iter().all(|r| r["cross_eye_reuse"] == true),
        "{runs:?}"
    );
    for name in [
        "reference_still_left_0000.exr",
        "reference_still_right_0000.exr",
        "reference_moving_right_0002.exr",
        "run_moving_cartesian_svgf_taa-off_noise-surface/frame_0002_right.png",
    ] {
        assert!(out.join(name).is_file(), "{name} missing");
    }
    let table = std::fs::read_to_string(out.join("quality.md")).unwrap();
    assert!(
        table.contains("Binocular difference")
            && table.contains("| cartesian + svgf, off, surface + cross-eye |")
            && table.contains("flicker of the difference"),
        "{table}"
    );
}

/// `--reference-spp` and the frame size of `fovea quality` have upper bounds, checked before
/// anything renders or the output folder is made.
#[test]
fn quality_counts_are_bounded() {
    use fovea_tools::commands::quality::{run, QualityArgs};
    let out = temp_dir("quality-bounds");
    let _ = std::fs::remove_dir_all(&out);
    let names = |v: &str| vec![v.to_string()];
    let (methods, denoisers, taa, cameras) =
        (names("vp"), names("none"), names("off"), names("still"));
    let base = || quality_args([&methods, &denoisers, &taa, &cameras], &out);
    for (args, needle) in [
        (
            QualityArgs {
                reference_spp: u32::MAX,
                ..base()
            },
            "--reference-spp 4294967295 must be at most 1048576",
        ),
        (
            QualityArgs {
                width: 100_000,
                height: 100_000,
                ..base()
            },
            "--width 100000 --height 100000: at most 16777216 pixels",
        ),
    ] {
        let err = format!("{:#}", run(&args).unwrap_err());
        assert!(err.contains(needle), "{err}");
    }
    assert!(!out.exists());
}

/// `fovea quality --methods all`: every method of `fovea render` is measured, and the
/// combinations a method cannot run (a denoiser on a space without temporal filters) are listed
/// with the space's reason, in quality.json and in the table, instead of failing or vanishing.
#[test]
fn quality_methods_all_lists_what_a_method_refuses() {
    use fovea_tools::commands::quality::{expand_methods, run, QualityArgs};
    let out = temp_dir("quality-all");
    let strings = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let methods = expand_methods(strings(&["all"]));
    assert_eq!(methods, strings(&fovea_tools::commands::methods::names()));
    let (denoisers, taa, cameras) = (
        strings(&["none", "svgf"]),
        strings(&["off"]),
        strings(&["still"]),
    );
    let args = QualityArgs {
        frames: 2,
        eval_frames: 1,
        rings: 3,
        ..quality_args([&methods, &denoisers, &taa, &cameras], &out)
    };
    run(&args).unwrap();
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("quality.json")).unwrap()).unwrap();
    let refused: Vec<&str> = report["refused"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["method"].as_str().unwrap())
        .collect();
    assert_eq!(
        refused,
        [
            "uniform-budget",
            "linear-falloff",
            "random-acuity",
            "pixel-blocks",
            "vrs-tiles"
        ]
    );
    assert!(report["refused"]
        .as_array()
        .unwrap()
        .iter()
        .all(|r| r["denoiser"] == "svgf"
            && r["reason"]
                .as_str()
                .unwrap()
                .contains("supports no denoiser")));
    let runs = report["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 2 * methods.len() - refused.len(), "{runs:?}");
    for m in &methods {
        assert!(
            runs.iter().any(|r| r["method"] == m.as_str()
                && r["denoiser"] == "none"
                && r["frame_flip"].as_f64().unwrap() > 0.0),
            "{m}"
        );
    }
    let table = std::fs::read_to_string(out.join("quality.md")).unwrap();
    assert!(
        table.contains("| random-acuity + svgf, off | refused: random-acuity supports no denoiser"),
        "{table}"
    );

    // The method table from this run and a bench report, into docs/quality.md between its markers.
    let bench_out = out.join("bench");
    let scenes = strings(&["cornell-box"]);
    fovea_tools::commands::bench::run(&fovea_tools::commands::bench::BenchArgs {
        scenes: &scenes,
        builders: &[fovea_renderer::scene::bvh::BvhBuilder::DEFAULT],
        flatten: false,
        sizes: &[],
        vp_sizes: &[(64, 72)],
        vp_gaze: fovea_tools::commands::bench::CENTRED_GAZE,
        frames: 1,
        loop_size: None,
        loop_frames: 2,
        camera_path: None,
        out: &bench_out,
        dump_rays: false,
        loop_scenes: &[],
        loop_headsets: &[],
        traversals: &[],
        device: None,
        validation: true,
    })
    .unwrap();
    let root = temp_dir("method-table");
    let docs = root.join("docs");
    std::fs::create_dir_all(&docs).unwrap();
    let quality_md = docs.join("quality.md");
    std::fs::write(&quality_md, "# mine\n\n<!-- method-table:begin -->\nold\n<!-- method-table:end -->\n\nafter: quoting `<!-- method-table:begin -->` keeps it\n").unwrap();
    // The pictures beside the document, so it links them as methods/NAME.png.
    let pictures = docs.join("methods");
    let bench_report = [bench_out.join("report.json")];
    // The committed equal-samples report of docs/quality.md's claim (VP against composite, σ 1.66).
    let equal = [std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../docs/methods/quality-equal-samples-composite.json")];
    let table_args = |doc| fovea_tools::commands::method_table::MethodTableArgs {
        quality: &out,
        bench: &bench_report,
        doc,
        pictures: &pictures,
        equal_samples: &equal,
    };
    fovea_tools::commands::method_table::run(&table_args(&quality_md)).unwrap();
    let text = std::fs::read_to_string(&quality_md).unwrap();
    assert!(text.starts_with("# mine\n\n<!-- method-table:begin -->\n") && text.ends_with("<!-- method-table:end -->\n\nafter: quoting `<!-- method-table:begin -->` keeps it\n") && !text.contains("old"), "{text}");
    for m in &methods {
        assert!(text.contains(&format!("| {m} + none | ")), "{m}: {text}");
        assert!(
            pictures.join(format!("{m}.png")).is_file()
                && pictures.join(format!("{m}_flip.png")).is_file(),
            "{m}"
        );
        assert!(
            text.contains(&format!("![{m}](methods/{m}.png)"))
                && text.contains(&format!("![{m} FLIP](methods/{m}_flip.png)")),
            "{m}"
        );
    }
    assert!(
        text.contains("| pixel-blocks + svgf | refused:")
            && text.contains("faster traversal per sample for Visual-Polar than random acuity"),
        "{text}"
    );
    assert!(text.contains("Visual-Polar vs composite (Andersson & Hansson 2020) at equal samples (44985 vs 45034, gaze `sim:1`") && text.contains("none 0.349 / 0.221 / 0.184 vs 0.347 / 0.310 / 0.240"), "{text}");
    // A report of many methods is no equal-samples pair: named, and the document left as it was.
    let many = [out.join("quality.json")];
    let err = format!(
        "{:#}",
        fovea_tools::commands::method_table::run(
            &fovea_tools::commands::method_table::MethodTableArgs {
                equal_samples: &many,
                ..table_args(&quality_md)
            }
        )
        .unwrap_err()
    );
    assert!(
        err.contains("quality.json") && err.contains("exactly one other method"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&quality_md).unwrap(), text);
    let bare = docs.join("BARE.md");
    std::fs::write(&bare, "no markers").unwrap();
    let err = format!(
        "{:#}",
        fovea_tools::commands::method_table::run(&table_args(&bare)).unwrap_err()
    );
    assert!(
        err.contains("BARE.md") && err.contains("method-table:begin"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&bare).unwrap(), "no markers");
}

/// `fovea quality --rings` is bounded like `fovea eval`'s (by the render size), before anything
/// is rendered or written.
#[test]
fn quality_rings_are_bounded_before_rendering() {
    use fovea_tools::commands::quality::{run, QualityArgs};
    let out = temp_dir("quality-rings").join("out");
    let names = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let (methods, denoisers, taa, cameras) = (
        names(&["vp"]),
        names(&["none"]),
        names(&["off"]),
        names(&["still"]),
    );
    // 40×36: half-diagonal 26.9 px.
    for (rings, needle) in [(1001, "1..=1000"), (27, "at most 26 rings")] {
        let args = QualityArgs {
            rings,
            ..quality_args([&methods, &denoisers, &taa, &cameras], &out)
        };
        let err = format!("{:#}", run(&args).unwrap_err());
        assert!(
            err.contains(&format!("--rings {rings}")) && err.contains(needle),
            "{err}"
        );
    }
    assert!(!out.exists());
}

/// `--headset`: rings of true eccentricity through the FOV, out to the farthest corner's; an
/// error placed beyond 30° true eccentricity shows only in the rings past 30°.
#[test]
fn true_eccentricity_rings_through_a_headset() {
    use fovea_renderer::sampling::HeadsetAxis;
    let dir = temp_dir("true-ecc");
    let reference = dir.join("ref.exr");
    let clean = image(W, H);
    write_exr(&reference, W, H, &clean).unwrap();
    let gaze = glam::Vec2::new(32.0, 36.0);
    // config/headsets/fove0.toml
    let fov = fovea_renderer::sampling::FovTangents::from_angles_deg(-45.0, 45.0, -48.4, 48.4);
    let axis = HeadsetAxis::new(fov, glam::UVec2::new(W, H), gaze);
    let noisy: Vec<[f32; 4]> = clean
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let px = glam::Vec2::new((i as u32 % W) as f32 + 0.5, (i as u32 / W) as f32 + 0.5);
            if axis.eccentricity(px - gaze) > 30.0 {
                [p[0] + 0.5, p[1], p[2], 1.0]
            } else {
                *p
            }
        })
        .collect();
    let test = dir.join("test.exr");
    write_exr(&test, W, H, &noisy).unwrap();
    let out = dir.join("out");
    eval(&EvalArgs {
        headset: Some("fove0"),
        ..args(&reference, &test, "32,36", &out)
    })
    .unwrap();
    let json = read_json(&out);
    let t = &json["true_eccentricity"];
    assert_eq!(t["headset"], "fove0");
    let e_max = t["e_max_deg"].as_f64().unwrap();
    assert!(
        (e_max - axis.e_max as f64).abs() < 1e-9 && e_max > 50.0,
        "e_max {e_max}"
    );
    let rings = t["rings"].as_array().unwrap();
    assert_eq!(
        rings
            .iter()
            .map(|r| r["pixels"].as_u64().unwrap())
            .sum::<u64>(),
        (W * H) as u64
    );
    for r in rings {
        let (inner, outer, rmse) = (
            r["inner"].as_f64().unwrap(),
            r["outer"].as_f64().unwrap(),
            r["rmse"].as_f64(),
        );
        if outer <= 30.0 {
            assert_eq!(rmse, Some(0.0), "ring {inner}–{outer}° should be clean");
        } else if inner >= 30.0 {
            assert!(
                rmse.unwrap() > 0.1,
                "ring {inner}–{outer}° should show the error"
            );
        }
    }
    // Without --headset the field is absent; a bad headset is named.
    eval(&args(&reference, &test, "32,36", &out)).unwrap();
    assert!(read_json(&out).get("true_eccentricity").is_none());
    let err = format!(
        "{:#}",
        eval(&EvalArgs {
            headset: Some("nope"),
            ..args(&reference, &test, "32,36", &out)
        })
        .unwrap_err()
    );
    assert!(err.contains("--headset nope"), "{err}");
}

/// FLIP (NVIDIA's implementation) in eval.json: whole frame and per ring, on EXRs through the
/// tone curve and on PNGs as they are; `--ppd` recorded as `flip_ppd` (default from the headset).
#[test]
fn flip_whole_frame_and_per_ring_for_exr_and_png() {
    let dir = temp_dir("flip");
    let (reference, test) = (dir.join("ref.exr"), dir.join("test.exr"));
    let noisy: Vec<[f32; 4]> = image(W, H)
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let n = if (i * 7919) % 13 < 6 { 0.25 } else { -0.2 };
            [p[0] + n, p[1] + n, p[2] + n, 1.0]
        })
        .collect();
    write_exr(&reference, W, H, &image(W, H)).unwrap();
    write_exr(&test, W, H, &noisy).unwrap();
    let out = dir.join("exr");
    eval(&args(&reference, &test, "32,36", &out)).unwrap();
    let j = read_json(&out);
    assert_eq!(j["inputs"], "exr");
    // The FOVE 0's 90° across 64 pixels.
    let ppd = j["flip_ppd"].as_f64().unwrap();
    assert!((ppd - 64.0 / 90.0).abs() < 1e-3, "{ppd}");
    let flip = j["frame"]["flip"].as_f64().unwrap();
    assert!(flip > 0.05 && flip < 1.0, "{flip}");
    let rings = j["rings"].as_array().unwrap();
    assert!(rings
        .iter()
        .all(|r| r["flip"].as_f64().is_some_and(|f| f > 0.0)));
    // The rings partition the frame: their pixel-weighted FLIP is the frame's.
    let weighted: f64 = rings
        .iter()
        .map(|r| r["flip"].as_f64().unwrap() * r["pixels"].as_f64().unwrap())
        .sum::<f64>()
        / (W * H) as f64;
    assert!(
        (weighted - flip).abs() < 1e-9,
        "rings {weighted} vs frame {flip}"
    );

    // The same pictures as PNGs (tonemapped like the EXRs were): the same FLIP; identical → 0.
    let png = |name: &str, texels: &[[f32; 4]]| {
        let path = dir.join(name);
        fovea_tools::output::write_png(
            &path,
            W,
            H,
            &fovea_tools::output::tonemap_preview(
                texels,
                1.0,
                fovea_renderer::passes::tonemap::ToneCurve::Aces,
            ),
        )
        .unwrap();
        path
    };
    let (reference_png, test_png) = (png("ref.png", &image(W, H)), png("test.png", &noisy));
    let out_png = dir.join("png");
    eval(&EvalArgs {
        ppd: Some(ppd as f32),
        ..args(&reference_png, &test_png, "32,36", &out_png)
    })
    .unwrap();
    let p = read_json(&out_png);
    assert_eq!(p["inputs"], "png");
    assert!(
        (p["frame"]["flip"].as_f64().unwrap() - flip).abs() < 1e-6,
        "PNG {} vs EXR {flip}",
        p["frame"]["flip"]
    );
    let same = dir.join("same");
    eval(&EvalArgs {
        ppd: Some(30.0),
        ..args(&reference_png, &reference_png, "center", &same)
    })
    .unwrap();
    let s = read_json(&same);
    assert_eq!(
        (s["frame"]["flip"].as_f64(), s["flip_ppd"].as_f64()),
        (Some(0.0), Some(30.0))
    );

    // Mixed kinds and a bad --ppd are refused.
    let mixed = format!(
        "{:#}",
        eval(&args(&reference, &test_png, "32,36", &dir.join("mixed"))).unwrap_err()
    );
    assert!(mixed.contains("both"), "{mixed}");
    let bad = format!(
        "{:#}",
        eval(&EvalArgs {
            ppd: Some(f32::NAN),
            ..args(&reference_png, &test_png, "32,36", &dir.join("bad"))
        })
        .unwrap_err()
    );
    assert!(bad.contains("--ppd"), "{bad}");
}

/// `fovea eval`'s FLIP against NVIDIA's own tool on the same files: the pairs and the values of
/// `flip-evaluator` 1.7 (`flip -r reference.png -t TEST -ppd PPD`) are in tests/data/flip/ (its
/// README: how they were made). The whole-frame `flip` must equal the tool's mean within 2e-6
/// (measured: at most 8e-7 apart; the tool sums its mean in f32, eval in f64).
#[test]
fn flip_matches_nvidias_tool_on_a_known_pair() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/flip");
    let reference = data.join("reference.png");
    // (test image, ppd, the tool's mean)
    let cases = [
        ("test.png", 67.0206, 0.1883212924003601),
        ("test.png", 10.0, 0.2579818069934845),
        ("test.png", 14.2222, 0.25202101469039917),
        ("test_blocks.png", 67.0206, 0.25503864884376526),
        ("test_blocks.png", 10.0, 0.31406715512275696),
        ("test_blocks.png", 14.2222, 0.308245450258255),
    ];
    let dir = temp_dir("flip-nvidia");
    for (k, (test, ppd, expected)) in cases.into_iter().enumerate() {
        let out = dir.join(k.to_string());
        eval(&EvalArgs {
            ppd: Some(ppd),
            ..args(&reference, &data.join(test), "center", &out)
        })
        .unwrap();
        let flip = read_json(&out)["frame"]["flip"].as_f64().unwrap();
        println!("{test} at {ppd} ppd: fovea eval {flip:.7}, NVIDIA's flip {expected:.7}");
        assert!(
            (flip - expected).abs() < 2e-6,
            "{test} at {ppd} ppd: {flip} vs NVIDIA's {expected}"
        );
    }
}

/// FLIP of two uniform sRGB colours in closed form (Andersson et al. 2020, LDR-FLIP), written out
/// here from the paper: a uniform image has no edges or points (the feature term is 0, so the
/// error is the colour term alone) and the normalised CSF filters leave it as it is; the error is
/// the HyAB distance of the Hunt-adjusted CIELAB colours raised to q_c = 0.7, remapped with
/// p_c = 0.4, p_t = 0.95 against c_max, the same distance between pure green and pure blue.
fn uniform_flip(a: [u8; 3], b: [u8; 3]) -> f64 {
    fn linear(c: f64) -> f64 {
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    }
    // sRGB (D65) to XYZ, and CIELAB against the D65 white.
    fn lab(rgb: [f64; 3]) -> [f64; 3] {
        let [r, g, b] = rgb;
        let xyz = [
            0.4124564 * r + 0.3575761 * g + 0.1804375 * b,
            0.2126729 * r + 0.7151522 * g + 0.0721750 * b,
            0.0193339 * r + 0.1191920 * g + 0.9503041 * b,
        ];
        let white = [0.95047, 1.0, 1.08883];
        let f = |t: f64| {
            let d: f64 = 6.0 / 29.0;
            if t > d.powi(3) {
                t.cbrt()
            } else {
                t / (3.0 * d * d) + 4.0 / 29.0
            }
        };
        let [fx, fy, fz] = [0, 1, 2].map(|i| f(xyz[i] / white[i]));
        [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
    }
    let hunt = |[l, a, b]: [f64; 3]| [l, 0.01 * l * a, 0.01 * l * b];
    let hyab = |p: [f64; 3], q: [f64; 3]| (p[0] - q[0]).abs() + (p[1] - q[1]).hypot(p[2] - q[2]);
    let colour = |c: [u8; 3]| hunt(lab(c.map(|v| linear(v as f64 / 255.0))));
    let (qc, pc, pt) = (0.7, 0.4, 0.95);
    let cmax = hyab(hunt(lab([0.0, 1.0, 0.0])), hunt(lab([0.0, 0.0, 1.0]))).powf(qc);
    let e = hyab(colour(a), colour(b)).powf(qc);
    if e < pc * cmax {
        e * pt / (pc * cmax)
    } else {
        pt + (e - pc * cmax) / (cmax - pc * cmax) * (1.0 - pt)
    }
}

/// `fovea eval` on uniform images gives the closed-form FLIP of their two colours, for the whole
/// frame and in every ring: small differences on the linear part of the remap, large ones beyond
/// p_c, a pure hue change and black against white.
#[test]
fn flip_of_uniform_images_has_its_closed_form() {
    let dir = temp_dir("flip-uniform");
    let png = |name: &str, c: [u8; 3]| {
        let path = dir.join(name);
        let bytes = [c[0], c[1], c[2], 255].repeat((W * H) as usize);
        fovea_tools::output::write_png(&path, W, H, &bytes).unwrap();
        path
    };
    let pairs = [
        ([128, 128, 128], [136, 136, 136]),
        ([40, 90, 160], [40, 100, 150]),
        ([200, 60, 60], [60, 200, 60]),
        ([0, 0, 0], [255, 255, 255]),
    ];
    for (k, (a, b)) in pairs.into_iter().enumerate() {
        let (reference, test) = (png(&format!("a{k}.png"), a), png(&format!("b{k}.png"), b));
        let out = dir.join(format!("out{k}"));
        eval(&EvalArgs {
            ppd: Some(30.0),
            ..args(&reference, &test, "center", &out)
        })
        .unwrap();
        let j = read_json(&out);
        let want = uniform_flip(a, b);
        let frame = j["frame"]["flip"].as_f64().unwrap();
        println!("{a:?} vs {b:?}: fovea eval {frame:.6}, closed form {want:.6}");
        // Measured within 2e-5 (the tool computes in f32, with its own matrix digits).
        assert!(
            (frame - want).abs() < 1e-4,
            "{a:?} vs {b:?}: FLIP {frame}, closed form {want}"
        );
        for ring in j["rings"].as_array().unwrap() {
            let f = ring["flip"].as_f64().unwrap();
            assert!((f - want).abs() < 1e-4, "{a:?} vs {b:?}: ring {ring}");
        }
    }
}

/// The per-pixel FLIP map against NVIDIA's tool at the pixels its README records (tests/data/flip:
/// (0, 0), (80, 90), (159, 179) and the maximum of `flip -r reference.png -t TEST -ppd PPD`).
#[test]
fn flip_map_matches_nvidias_tool_pixel_by_pixel() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/flip");
    let rgba = |name: &str| image::open(data.join(name)).unwrap().to_rgba8();
    let reference = rgba("reference.png");
    // (test image, ppd, [(0,0), (80,90), (159,179)], max)
    let cases = [
        (
            "test.png",
            67.0206,
            [
                0.45378413796424866,
                0.1099155992269516,
                0.023592688143253326,
            ],
            0.6221623420715332,
        ),
        (
            "test.png",
            10.0,
            [
                0.43456751108169556,
                0.5752170085906982,
                0.042438384145498276,
            ],
            0.9760982394218445,
        ),
        (
            "test_blocks.png",
            14.2222,
            [0.30537059903144836, 0.5236210823059082, 0.0674961730837822],
            0.9726236462593079,
        ),
    ];
    let (w, h) = reference.dimensions();
    for (test, ppd, pixels, max) in cases {
        let map = fovea_tools::eval::flip::flip_map(&reference, &rgba(test), w, h, ppd);
        for ((x, y), want) in [(0, 0), (80, 90), (159, 179)].into_iter().zip(pixels) {
            let got = map[(y * w + x) as usize];
            assert!(
                (got - want).abs() < 1e-4,
                "{test} at {ppd} ppd, pixel ({x}, {y}): {got} vs NVIDIA's {want}"
            );
        }
        let got_max = map.iter().cloned().fold(0.0, f64::max);
        assert!(
            (got_max - max).abs() < 1e-4,
            "{test} at {ppd} ppd: max {got_max} vs NVIDIA's {max}"
        );
    }
}
