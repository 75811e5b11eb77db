//! Fuzz targets: every reader of a file a user (or anyone who sends them one) hands fovea, called
//! with arbitrary bytes. Each must return an error or a checked value and never panic, abort or
//! allocate without bound (the image budgets here are 1 Mi pixels; the scene budgets small). The
//! same functions run two ways:
//!
//! - `cargo test -p fovea-fuzz` (every test run, stable Rust): the committed corpus under
//!   `fuzz/corpus/<target>/` and a bounded run of random mutations of it (`tests/corpus.rs`);
//! - `scripts/fuzz` (long runs): libFuzzer, coverage-guided, one binary per target
//!   (`fuzz_targets/`), growing the corpus.
//!
//! Targets check what their reader promises beyond "no panic": a camera path that loads gives a
//! finite pose at every time, an image decodes to its declared size, a baseline manifest that
//! parses has the bounded counts it was checked for.

use fovea_tools::replay::baseline::{parse_manifest, TraceId, MAX_FRAMES};
use std::path::{Path, PathBuf};

/// Pixels an image target decodes at most (tighter than the tools' 16 Mi, to keep runs fast).
const MAX_PIXELS: u64 = 1 << 20;

/// A folder of this process and thread for targets whose reader takes a path.
fn scratch() -> PathBuf {
    thread_local! {
        static DIR: PathBuf = {
            let thread = format!("{:?}", std::thread::current().id())
                .chars()
                .filter(char::is_ascii_alphanumeric)
                .collect::<String>();
            let dir = std::env::temp_dir().join(format!("fovea-fuzz-{}-{thread}", std::process::id()));
            std::fs::create_dir_all(&dir).expect("a scratch folder");
            dir
        };
    }
    DIR.with(|d| d.clone())
}

fn write(name: &str, data: &[u8]) -> PathBuf {
    let path = scratch().join(name);
    std::fs::write(&path, data).expect("writing a fuzz input");
    path
}

/// A glTF (JSON) or GLB file, by its first bytes, through the scene loader without its panic
/// backstop, with small budgets.
pub fn gltf(data: &[u8]) {
    let name = if data.starts_with(b"glTF") {
        "scene.glb"
    } else {
        "scene.gltf"
    };
    let path = write(name, data);
    let limits = fovea_scene::LoadLimits {
        max_triangles: 100_000,
        max_instances: 10_000,
        instance_above: 50_000,
        max_texels: MAX_PIXELS,
        max_bytes: 16 << 20,
    };
    let _ = fovea_scene::load_unguarded(&path, &limits);
}

/// A fovea gaze trace, a GazeBase-style CSV and a normalised-coordinates CSV.
pub fn trace(data: &[u8]) {
    use fovea_hal::trace::import::{
        import_gazebase_text, import_normalized_text, DegreesImport, NormalizedImport,
    };
    let text = String::from_utf8_lossy(data);
    if let Ok(trace) = fovea_hal::Trace::parse(&text, Path::new("fuzz.csv")) {
        // What parses writes back and parses again.
        fovea_hal::Trace::parse(&trace.to_text(), Path::new("again.csv"))
            .expect("a parsed trace written back parses");
    }
    let _ = import_gazebase_text(&text, Path::new("g.csv"), &DegreesImport::default());
    let fov = fovea_hal::Fov::from_degrees(-40.0, 40.0, -40.0, 40.0);
    let _ = import_normalized_text(&text, Path::new("n.csv"), &NormalizedImport::new("n", fov));
}

/// A headset profile, a simulator profile and a `--gaze` spec.
pub fn headset(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    if let Ok(h) = fovea_hal::HmdDescription::parse(&text, Path::new("fuzz.toml")) {
        assert!(h.refresh_hz >= fovea_hal::hmd::MIN_RATE_HZ && h.refresh_hz.is_finite());
    }
    let _ = fovea_hal::SimConfig::parse(&text, Path::new("fuzz.toml"));
    let _ = text.parse::<fovea_hal::GazeSpec>();
}

/// A render profile (TOML), read from a file as `--profile` reads it.
pub fn render_profile(data: &[u8]) {
    let path = write("profile.toml", data);
    let _ = fovea_tools::render_profile::RenderProfile::load(&path);
}

/// A camera path file: once it loads, every time gives a finite pose with a view direction.
pub fn camera_path(data: &[u8]) {
    let path = write("path.toml", data);
    let Ok(keys) = fovea_stage::camera_keys::CameraKeys::load(&path) else {
        return;
    };
    let start = fovea_renderer::frame::CameraPose {
        world_from_view: glam::Mat4::IDENTITY,
        fov_tan: glam::Vec4::new(-1.0, 1.0, -1.0, 1.0),
    };
    let (first, last) = (keys.keys()[0].time, keys.keys()[keys.keys().len() - 1].time);
    for i in 0..=16 {
        let t = first + (last - first) * i as f64 / 16.0;
        let pose = keys.pose(t, &start);
        assert!(
            pose.world_from_view.is_finite() && pose.fov_tan.is_finite(),
            "time {t}: {pose:?}"
        );
    }
}

/// A replay baseline's `baseline.json` (its files are the image targets).
pub fn baseline_manifest(data: &[u8]) {
    // The corpus's manifests are those of `sim:1` baselines.
    let id = TraceId::of("sim:1").expect("sim:1 is a gaze source");
    if let Ok(b) = parse_manifest(data, "baseline.json", &id) {
        assert!((1..=MAX_FRAMES).contains(&b.params.frames));
        assert_eq!(b.frames.len(), b.params.frames as usize);
        assert_eq!(b.files.len(), b.frames.len() + 1);
    }
}

/// A PNG or JPEG, as `fovea eval` and the baselines decode them.
pub fn png(data: &[u8]) {
    if let Ok((w, h, px)) = fovea_stage::decode::decode_rgba8(data, "fuzz.png", MAX_PIXELS, None) {
        assert_eq!(px.len() as u64, w as u64 * h as u64 * 4);
    }
}

/// An OpenEXR image, as references and environment maps are decoded.
pub fn exr(data: &[u8]) {
    if let Ok((w, h, px)) = fovea_stage::decode::decode_exr(data, "fuzz.exr", MAX_PIXELS, None) {
        assert_eq!(px.len() as u64, w as u64 * h as u64);
    }
}

/// A Radiance HDR image, then the environment map's checks on it.
pub fn hdr(data: &[u8]) {
    if let Ok((w, h, px)) = fovea_stage::decode::decode_hdr(data, "fuzz.hdr", MAX_PIXELS) {
        assert_eq!(px.len() as u64, w as u64 * h as u64);
        let texels = px.into_iter().map(glam::Vec3::from_array).collect();
        let _ = fovea_scene::EnvironmentMap::new(w, h, texels);
    }
}

/// A fuzz target: arbitrary bytes in, a panic on a finding.
pub type Target = fn(&[u8]);

/// Every target by name (the corpus folders' names).
pub const TARGETS: [(&str, Target); 9] = [
    ("gltf", gltf),
    ("trace", trace),
    ("headset", headset),
    ("render_profile", render_profile),
    ("camera_path", camera_path),
    ("baseline_manifest", baseline_manifest),
    ("png", png),
    ("exr", exr),
    ("hdr", hdr),
];
