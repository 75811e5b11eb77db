//! The `log-polar` comparator (Meng et al. 2018, kernel foveated rendering; comparators.md §D):
//! the polar space with the log-polar radial law. It traces exactly its buffer (screen / σ, no
//! clip), `fovea render --method log-polar` reports it end to end, and bad profile values name
//! their key. Every filter on it: tests/conformance.rs.

use fovea_renderer::frame::{CameraPose, FrameInput, OffscreenSamples, RenderSettings};
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::{
    LogPolarExtent, LogPolarParams, RadialLaw, SamplingSpace, VisualPolar, VisualPolarParams,
};
use fovea_tests::{assert_clean, gpu, owned_scene};
use fovea_tools::render_profile::{ProfileOverrides, RenderProfile};
use glam::{UVec2, Vec2};

fn log_polar(screen: UVec2, gaze: Vec2, extent: LogPolarExtent) -> VisualPolar {
    let lp = LogPolarParams {
        extent,
        ..Default::default()
    };
    VisualPolar::new(
        screen,
        gaze,
        VisualPolarParams {
            radial: RadialLaw::LogPolar(lp),
            ..Default::default()
        },
    )
    .unwrap()
}

#[test]
fn log_polar_traces_exactly_its_buffer() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let screen = UVec2::new(64, 72);
    let camera = CameraPose::from_scene_camera(scene.default_camera().unwrap(), screen.x, screen.y);
    for (gaze, extent) in [
        (Vec2::new(32.0, 36.0), LogPolarExtent::FarthestCorner),
        (Vec2::new(5.0, 60.0), LogPolarExtent::Diagonal),
    ] {
        let space = log_polar(screen, gaze, extent);
        // Texel centres off the screen (full circles out to the extent); the GPU's jittered
        // samples differ only where a texel straddles the screen's border.
        let inside =
            |p: Vec2| p.x >= 0.0 && p.y >= 0.0 && p.x < screen.x as f32 && p.y < screen.y as f32;
        let off_centres = (0..36 * 40)
            .filter(|i| {
                !inside(
                    space
                        .grid_to_screen(Vec2::new((i % 36) as f32 + 0.5, (i / 36) as f32 + 0.5))
                        .unwrap(),
                )
            })
            .count() as f64;
        // 64 / 1.8 = 35.6, 72 / 1.8 = 40: every texel of the 36 × 40 buffer holds a sample.
        assert_eq!(
            (space.grid_size(), SamplingSpace::sample_count(&space)),
            (UVec2::new(36, 40), 36 * 40)
        );
        let settings = RenderSettings {
            offscreen_samples: OffscreenSamples::Trace,
            ..Default::default()
        };
        let mut r = Renderer::new(&ctx, &scene, Box::new(space), settings).unwrap();
        let stats = r
            .render_frame(&FrameInput::mono(camera, 0, Some(gaze)))
            .unwrap();
        assert_eq!(
            stats.samples_traced,
            36 * 40,
            "{extent:?}: every texel traced once"
        );
        let off = stats.samples_offscreen as f64;
        println!("{extent:?}: {off} samples off the screen, {off_centres} texel centres");
        assert!(
            off > 0.0 && (off - off_centres).abs() <= 0.05 * 1440.0,
            "{extent:?}: {stats:?}, {off_centres} centres off the screen"
        );
        assert_eq!(
            stats.primary_rays, stats.samples_traced,
            "one primary ray per sample"
        );
    }
    assert_clean(&ctx);
}

#[test]
fn render_command_runs_log_polar_and_reports_it() {
    let out = fovea_tests::artifacts_dir().join(format!("log-polar-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let profile = fovea_tests::profile_with_blur()
        .override_with(&ProfileOverrides {
            log_polar_extent: Some("diagonal".into()),
            ..Default::default()
        })
        .unwrap();
    let args = fovea_tools::commands::render::RenderArgs {
        method: "log-polar",
        width: Some(64),
        height: Some(72),
        denoiser: "svgf",
        profile,
        ..fovea_tests::small_render_args("cornell-box", &out)
    };
    fovea_tools::commands::render::run(&args).unwrap();
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["method"], "log-polar");
    assert_eq!(report["log_polar"]["extent"], "diagonal", "{report}");
    assert_eq!(report["log_polar"]["alpha"], 4.0);
    assert_eq!(
        (report["vp_width"].as_u64(), report["vp_height"].as_u64()),
        (Some(36), Some(40))
    );
    // The diagonal's buffer reaches past the screen even around a centred gaze: its farthest
    // samples are culled by default.
    let (traced, culled) = (
        report["samples_traced"].as_u64().unwrap(),
        report["samples_culled"].as_u64().unwrap(),
    );
    assert!(traced + culled == 36 * 40 && culled > 0, "{report}");
    for pass in ["trace", "mip_phi", "remap", "blur", "svgf_atrous"] {
        assert!(
            report["passes"]
                .as_object()
                .unwrap()
                .keys()
                .any(|k| k.starts_with(pass)),
            "{pass} missing: {}",
            report["passes"]
        );
    }
}

#[test]
fn bad_log_polar_input_names_the_flag_or_key() {
    let bad = ProfileOverrides {
        log_polar_extent: Some("edge".into()),
        ..Default::default()
    };
    let e = format!(
        "{:#}",
        RenderProfile::default().override_with(&bad).unwrap_err()
    );
    assert!(
        e.contains("--log-polar-extent") && e.contains("corner") && e.contains("diagonal"),
        "{e}"
    );
    let dir =
        fovea_tests::artifacts_dir().join(format!("log-polar-profile-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (text, key) in [
        ("[log_polar]\nsigma = 0.0\n", "sigma"),
        ("[log_polar]\nalpha = 40.0\n", "alpha"),
        ("[log_polar]\nextent = \"far\"\n", "extent"),
    ] {
        let path = dir.join("p.toml");
        std::fs::write(&path, text).unwrap();
        let e = format!("{:#}", RenderProfile::load(&path).unwrap_err());
        assert!(e.contains("[log_polar]") && e.contains(key), "{text}: {e}");
    }
    let p =
        RenderProfile::load(&fovea_tests::repo_root().join("config/render/default.toml")).unwrap();
    assert_eq!(
        p.log_polar,
        LogPolarParams::default(),
        "the default profile spells Meng's parameters"
    );
}
