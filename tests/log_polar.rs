//! The `log-polar` comparator (Meng et al. 2018, kernel foveated rendering; comparators.md §D):
//! the polar space with the log-polar radial law. It traces exactly its buffer (screen / σ, no
//! clip), each filter the polar space supports (SVGF, A-SVGF, BMFR, TAA) runs on it without
//! validation messages and reduces noise against a converged reference, `fovea render --method
//! log-polar` reports it end to end, and bad profile values name their key.

use fovea_renderer::passes::denoise::asvgf::AsvgfSettings;
use fovea_renderer::passes::denoise::bmfr::BmfrSettings;
use fovea_renderer::passes::denoise::svgf::SvgfSettings;
use fovea_renderer::passes::denoise::taa::{TaaMode, TaaSettings};
use fovea_renderer::passes::denoise::DenoiserSettings;
use fovea_renderer::pipeline::{CameraPose, FrameInput, RenderSettings, Renderer};
use fovea_renderer::sampling::{Cartesian, LogPolarExtent, LogPolarParams, RadialLaw, SamplingSpace, VisualPolar, VisualPolarParams};
use fovea_renderer::to_screen::BlurSettings;
use fovea_tests::denoise::{assert_finite_non_negative, rmse_where, surface_interiors};
use fovea_tests::{assert_clean, gpu, owned_scene, save_preview};
use fovea_tools::render_profile::{ProfileOverrides, RenderProfile};
use glam::{UVec2, Vec2};

fn log_polar(screen: UVec2, gaze: Vec2, extent: LogPolarExtent) -> VisualPolar {
    let lp = LogPolarParams { extent, ..Default::default() };
    VisualPolar::new(screen, gaze, VisualPolarParams { radial: RadialLaw::LogPolar(lp), ..Default::default() }).unwrap()
}

#[test]
fn log_polar_traces_exactly_its_buffer() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let screen = UVec2::new(64, 72);
    let camera = CameraPose::from_scene_camera(scene.default_camera().unwrap(), screen.x, screen.y);
    for (gaze, extent) in [(Vec2::new(32.0, 36.0), LogPolarExtent::FarthestCorner), (Vec2::new(5.0, 60.0), LogPolarExtent::Diagonal)] {
        let space = log_polar(screen, gaze, extent);
        // Texel centres off the screen (full circles out to the extent); the GPU's jittered
        // samples differ only where a texel straddles the screen's border.
        let inside = |p: Vec2| p.x >= 0.0 && p.y >= 0.0 && p.x < screen.x as f32 && p.y < screen.y as f32;
        let off_centres = (0..36 * 40)
            .filter(|i| !inside(space.grid_to_screen(Vec2::new((i % 36) as f32 + 0.5, (i / 36) as f32 + 0.5)).unwrap()))
            .count() as f64;
        // 64 / 1.8 = 35.6, 72 / 1.8 = 40: every texel of the 36 × 40 buffer holds a sample.
        assert_eq!((space.grid_size(), SamplingSpace::sample_count(&space)), (UVec2::new(36, 40), 36 * 40));
        let mut r = Renderer::new(&ctx, &scene, Box::new(space), RenderSettings::default()).unwrap();
        let stats = r.render_frame(&FrameInput::mono(camera, 0, Some(gaze))).unwrap();
        assert_eq!(stats.samples_traced, 36 * 40, "{extent:?}: every texel traced once");
        let off = stats.samples_offscreen as f64;
        println!("{extent:?}: {off} samples off the screen, {off_centres} texel centres");
        assert!(off > 0.0 && (off - off_centres).abs() <= 0.05 * 1440.0, "{extent:?}: {stats:?}, {off_centres} centres off the screen");
        assert_eq!(stats.primary_rays, stats.samples_traced, "one primary ray per sample");
    }
    assert_clean(&ctx);
}

/// 96×108 Cornell box, still camera, gaze at the centre, blur off: 16 frames of each filter
/// against the raw one-sample frame, both against the space's own converged image (the mean of
/// 128 raw frames after the remap), on the surface interiors. Against a full-resolution
/// Cartesian reference the buffer's resolution (≈ 0.3 samples per pixel) bounds what any filter
/// can do (measured: SVGF 1.8×, BMFR 3.0×); the noise the filters are for is measured against
/// the space's own limit. Bound: 2× (measured SVGF 2.4×, A-SVGF 2.3×, BMFR 2.5×, TAA 4.0×; the
/// à-trous and BMFR fits also smooth the coarse periphery, a bias the converged image lacks).
#[test]
fn each_filter_runs_on_log_polar_and_reduces_noise() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let size = UVec2::new(96, 108);
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], size.x, size.y);
    let blur_off = RenderSettings { blur: BlurSettings { sigma_at_30: 0.0 }, ..Default::default() };
    let mut reference_renderer = Renderer::new(&ctx, &scene, Box::new(Cartesian::new(size)), blur_off).unwrap();
    let full_reference = reference_renderer.render_reference(&camera, 128, 3, |_| {}).unwrap();
    drop(reference_renderer);
    let gaze = size.as_vec2() * 0.5;
    let frame = |f: u32| FrameInput::mono(camera, f, Some(gaze)).with_hdr(true);

    let mut raw_renderer = Renderer::new(&ctx, &scene, Box::new(log_polar(size, gaze, LogPolarExtent::FarthestCorner)), blur_off).unwrap();
    let (mut raw, mut reference) = (Vec::new(), vec![[0.0f32; 4]; (size.x * size.y) as usize]);
    const CONVERGED_FRAMES: u32 = 128;
    for f in (0..CONVERGED_FRAMES).rev() {
        raw_renderer.render_frame(&frame(f)).unwrap();
        raw_renderer.read_hdr(&mut raw).unwrap();
        for (m, p) in reference.iter_mut().zip(&raw) {
            (0..4).for_each(|c| m[c] += p[c] / CONVERGED_FRAMES as f32);
        }
    }
    drop(raw_renderer);
    save_preview("log_polar_converged.png", size.x, size.y, &reference);
    save_preview("log_polar_raw.png", size.x, size.y, &raw);

    let taa = TaaMode::SamplingGrid(TaaSettings::default());
    let filters = [
        ("svgf", DenoiserSettings::Svgf(SvgfSettings::default()), TaaMode::Off),
        ("asvgf", DenoiserSettings::Asvgf(AsvgfSettings::default()), TaaMode::Off),
        ("bmfr", DenoiserSettings::Bmfr(BmfrSettings::default()), TaaMode::Off),
        ("taa", DenoiserSettings::None, taa),
    ];
    let mut failures = Vec::new();
    for (name, denoiser, taa) in filters {
        let settings = RenderSettings { denoiser, taa, ..blur_off };
        let mut r = Renderer::new(&ctx, &scene, Box::new(log_polar(size, gaze, LogPolarExtent::FarthestCorner)), settings).unwrap();
        let mut out = Vec::new();
        for f in 0..16 {
            r.render_frame(&frame(f)).unwrap();
        }
        r.read_hdr(&mut out).unwrap();
        assert_finite_non_negative(name, &out);
        save_preview(&format!("log_polar_{name}.png"), size.x, size.y, &out);
        let interior = surface_interiors(&ctx, &r.view(0).gbuffer, r.space());
        let (a, b) = (rmse_where(&raw, &reference, |i| interior[i]), rmse_where(&out, &reference, |i| interior[i]));
        let (fa, fb) = (rmse_where(&raw, &full_reference, |i| interior[i]), rmse_where(&out, &full_reference, |i| interior[i]));
        println!("log-polar {name}: surface interiors RMSE {a:.4} → {b:.4} ({:.2}×) against the converged log-polar image, {fa:.4} → {fb:.4} ({:.2}×) against full resolution", a / b, fa / fb);
        if a / b < 2.0 {
            failures.push(format!("{name}: RMSE fell only {:.2}× ({a:.4} → {b:.4})", a / b));
        }
        assert_clean(&ctx);
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn render_command_runs_log_polar_and_reports_it() {
    let out = fovea_tests::artifacts_dir().join(format!("log-polar-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let profile = RenderProfile::default()
        .override_with(&ProfileOverrides { log_polar_extent: Some("diagonal".into()), ..Default::default() })
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
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["method"], "log-polar");
    assert_eq!(report["log_polar"]["extent"], "diagonal", "{report}");
    assert_eq!(report["log_polar"]["alpha"], 4.0);
    assert_eq!((report["vp_width"].as_u64(), report["vp_height"].as_u64()), (Some(36), Some(40)));
    assert_eq!(report["samples_traced"].as_u64(), Some(36 * 40), "{report}");
    for pass in ["trace", "mip_phi", "remap", "blur", "svgf_atrous"] {
        assert!(report["passes"].as_object().unwrap().keys().any(|k| k.starts_with(pass)), "{pass} missing: {}", report["passes"]);
    }
}

#[test]
fn bad_log_polar_input_names_the_flag_or_key() {
    let bad = ProfileOverrides { log_polar_extent: Some("edge".into()), ..Default::default() };
    let e = format!("{:#}", RenderProfile::default().override_with(&bad).unwrap_err());
    assert!(e.contains("--log-polar-extent") && e.contains("corner") && e.contains("diagonal"), "{e}");
    let dir = fovea_tests::artifacts_dir().join(format!("log-polar-profile-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (text, key) in [("[log_polar]\nsigma = 0.0\n", "sigma"), ("[log_polar]\nalpha = 40.0\n", "alpha"), ("[log_polar]\nextent = \"far\"\n", "extent")] {
        let path = dir.join("p.toml");
        std::fs::write(&path, text).unwrap();
        let e = format!("{:#}", RenderProfile::load(&path).unwrap_err());
        assert!(e.contains("[log_polar]") && e.contains(key), "{text}: {e}");
    }
    let p = RenderProfile::load(&fovea_tests::repo_root().join("config/render/default.toml")).unwrap();
    assert_eq!(p.log_polar, LogPolarParams::default(), "the default profile spells Meng's parameters");
}
