//! `fovea render`: N frames of the scene, written as PNG (and linear EXR), plus report.json with
//! exact sample/ray counts and mean GPU milliseconds per pass.

use crate::camera_path;
use crate::output::{prepare_output_dir, write_exr, write_json, write_png};
use crate::gaze::GazeDriver;
use anyhow::{bail, Context, Result};
use fovea_hal::GazeOrigin;
use fovea_renderer::passes::denoise::taa::TaaMode;
use fovea_renderer::passes::denoise::DenoiserSettings;
use fovea_renderer::pipeline::{CameraPose, FrameInput, RenderSettings, Renderer};
use crate::render_profile::RenderProfile;
use fovea_renderer::sampling::{Cartesian, SamplingSpace, VisualPolar, VpLayout};
use glam::UVec2;
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

pub struct RenderArgs<'a> {
    pub scene: &'a str,
    pub method: &'a str,
    /// Render size; `None` = the headset's per-eye recommended size × `scale`.
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub scale: f32,
    pub headset: &'a str,
    pub gaze: &'a str,
    pub frames: u32,
    pub out: &'a Path,
    pub exr: bool,
    pub camera_path: bool,
    pub seed: u32,
    pub max_depth: u32,
    pub exposure: f32,
    /// Visual-Polar parameters, blur and SVGF parameters (profile file + flags, already merged).
    pub profile: RenderProfile,
    /// Per frame: the sampling-grid image and a sample-density heat map; once: density plot.
    pub debug_views: bool,
    /// `none`, `svgf`, `asvgf` or `bmfr` (`DenoiserSettings::NAMES`).
    pub denoiser: &'a str,
    /// `off`, `vp` or `screen` (`TaaMode::NAMES`).
    pub taa: &'a str,
    pub device: Option<&'a str>,
    pub validation: bool,
}

/// The sampling methods `--method` accepts.
pub const METHODS: &[&str] = &["vp", "cartesian"];

#[derive(Serialize)]
struct Report {
    method: String,
    /// Denoiser in the sampling grid (`none`, `svgf`, `asvgf`, `bmfr`).
    denoiser: String,
    /// TAA: `off`, `vp` (in the sampling grid) or `screen` (after the remap; for Cartesian the
    /// sampling-grid filter, the grid being the screen).
    taa: String,
    scene: String,
    headset: String,
    gaze_source: String,
    /// Gaze point per frame in render pixels (the Cartesian method traces uniformly and only
    /// records it; foveated methods centre their sampling on it).
    gaze: Vec<[f32; 2]>,
    /// Frames whose gaze was live / held after a lost sample / the view centre.
    gaze_live: u32,
    gaze_held: u32,
    gaze_centre: u32,
    device: String,
    width: u32,
    height: u32,
    /// Sampling-grid size (the screen for Cartesian).
    vp_width: u32,
    vp_height: u32,
    frames: u32,
    /// Samples traced in one frame.
    samples_traced: u64,
    /// Traced samples per frame (mean) whose screen position is off the screen.
    samples_offscreen: u64,
    screen_pixels: u64,
    /// Rays traced in one frame (mean over frames): primary + shadow + continuation.
    rays_traced: u64,
    rays: RayReport,
    max_depth: u32,
    seed: u32,
    camera_path: bool,
    /// Visual-Polar parameters (vp only).
    visual_polar: Option<VpReport>,
    /// Foveated blur σ at 30° for a 1280×1440 eye (vp only; 0 = off).
    blur_sigma_at_30: Option<f32>,
    /// Pass name → mean GPU milliseconds per frame.
    passes: BTreeMap<String, f64>,
    /// Sum of the pass means.
    frame_gpu_ms: f64,
    /// Wall-clock seconds for all frames, including read-back and file writing.
    wall_seconds: f64,
    /// SIGINT/SIGTERM stopped the run after `frames` frames (of the requested ones).
    interrupted: bool,
}

#[derive(Serialize)]
struct VpReport {
    axis_scale: f32,
    clip_fraction: f32,
    fovea_deg: f32,
    density_exponent: f32,
    inverse_cdf: String,
    radius: String,
    /// "paper" or "screen-clipped".
    layout: String,
    /// The ρ axis: "normalized" (the paper's) or "headset" (true degrees through the eye's FOV).
    eccentricity: String,
}

#[derive(Serialize, Default)]
struct RayReport {
    primary: u64,
    shadow: u64,
    continuation: u64,
}

pub fn run(args: &RenderArgs) -> Result<()> {
    let hmd = fovea_hal::HmdDescription::resolve(args.headset).with_context(|| format!("--headset {}", args.headset))?;
    if !(args.scale > 0.0 && args.scale <= 4.0) {
        bail!("--scale {} must be in (0, 4]", args.scale);
    }
    let eye = hmd.eye(fovea_hal::Eye::Left);
    let width = args.width.unwrap_or(((eye.recommended_width as f32 * args.scale).round() as u32).max(1));
    let height = args.height.unwrap_or(((eye.recommended_height as f32 * args.scale).round() as u32).max(1));
    if width == 0 || height == 0 || args.frames == 0 {
        bail!("--width, --height and --frames must be at least 1");
    }
    if !METHODS.contains(&args.method) {
        bail!("--method {}: expected one of {}", args.method, METHODS.join(", "));
    }
    let denoiser = match DenoiserSettings::parse(args.denoiser).context("--denoiser")? {
        DenoiserSettings::Svgf(_) => DenoiserSettings::Svgf(args.profile.svgf),
        DenoiserSettings::Asvgf(_) => DenoiserSettings::Asvgf(args.profile.asvgf),
        DenoiserSettings::Bmfr(_) => DenoiserSettings::Bmfr(args.profile.bmfr),
        other => other,
    };
    let taa = TaaMode::parse(args.taa).context("--taa")?.with_settings(args.profile.taa);
    // TAA reprojects with the paper's mapping, like SVGF (the screen-space one finds depths in the
    // VP G-buffer the same way).
    if args.method == "vp" && args.profile.visual_polar.layout != VpLayout::Paper && taa != TaaMode::Off {
        bail!("--taa {} supports only the paper's Visual-Polar layout (--vp-layout paper)", args.taa);
    }
    // SVGF and BMFR reproject and filter with the paper's mapping (no per-column arc table yet).
    if args.method == "vp" && args.profile.visual_polar.layout != VpLayout::Paper && denoiser != DenoiserSettings::None {
        bail!("--denoiser {} supports only the paper's Visual-Polar layout (--vp-layout paper)", args.denoiser);
    }
    let mut gaze = GazeDriver::open(args.gaze, &hmd, width, height)?;
    let scene = crate::scenes::load(args.scene)?;
    let Some(camera) = scene.default_camera() else {
        bail!("{}: the scene has no perspective camera", scene.source.display());
    };
    let out_dir = prepare_output_dir(args.out)?;
    let start_pose = CameraPose::from_scene_camera(camera, width, height);
    let ctx = super::open_device(args.device, args.validation)?;
    let settings = RenderSettings {
        max_depth: args.max_depth,
        seed: args.seed,
        exposure: args.exposure,
        blur: args.profile.blur,
        denoiser,
        taa,
        ..Default::default()
    };
    let screen = UVec2::new(width, height);
    // Built around the screen centre: every frame, the first included, re-centres it on its gaze.
    let screen_centre = screen.as_vec2() * 0.5;
    let fov = crate::render_profile::fov_tangents(&eye.fov);
    let vp_params = args.profile.visual_polar_for(fov).with_context(|| format!("--headset {}", args.headset))?;
    let space: Box<dyn SamplingSpace> = match args.method {
        "vp" => Box::new(VisualPolar::new(screen, screen_centre, vp_params).context("Visual-Polar space")?),
        _ => Box::new(Cartesian::new(screen)),
    };
    let grid = space.grid_size();
    let screen_pixels = screen.x as u64 * screen.y as u64;
    let mut renderer = Renderer::new(&ctx, &scene, space, settings)?;
    let mut debug = args.debug_views.then(|| super::debug_views::DebugViews::new(args.out, screen, grid));
    let centre = scene.bounds().center();

    let bar = ProgressBar::new(args.frames as u64);
    bar.set_style(ProgressStyle::with_template("{bar:40} frame {pos}/{len}  {elapsed} (eta {eta})")?);
    let started = std::time::Instant::now();
    let mut pass_sums: BTreeMap<String, f64> = BTreeMap::new();
    let (mut samples, mut offscreen, mut rays) = (0u64, 0u64, RayReport::default());
    let mut gaze_points = Vec::with_capacity(args.frames as usize);
    let mut origins = [0u32; 3];
    let mut ldr = Vec::new();
    let mut hdr = Vec::new();
    let mut frames_done = 0;
    for frame in 0..args.frames {
        let frame_gaze = gaze.frame(frame)?;
        gaze_points.push(frame_gaze.pixel.to_array());
        origins[match frame_gaze.origin {
            GazeOrigin::Live => 0,
            GazeOrigin::Held => 1,
            GazeOrigin::Centre => 2,
        }] += 1;
        let camera = camera_path::pose(&start_pose, centre, frame, args.frames, args.camera_path);
        let input = FrameInput {
            camera,
            frame_index: frame,
            gaze: Some(frame_gaze.pixel),
            read_hdr: args.exr,
            read_grid: debug.is_some(),
        };
        let stats = renderer.render_frame(&input)?;
        samples += stats.samples_traced;
        offscreen += stats.samples_offscreen;
        rays.primary += stats.primary_rays;
        rays.shadow += stats.shadow_rays;
        rays.continuation += stats.continuation_rays;
        for t in renderer.timings() {
            *pass_sums.entry(t.name.to_string()).or_default() += t.ms;
        }
        renderer.read_ldr(&mut ldr)?;
        write_png(&args.out.join(format!("frame_{frame:04}.png")), width, height, &ldr)?;
        if args.exr {
            renderer.read_hdr(&mut hdr)?;
            write_exr(&args.out.join(format!("frame_{frame:04}.exr")), width, height, &hdr)?;
        }
        if let Some(debug) = &mut debug {
            debug.frame(frame, &renderer)?;
        }
        bar.inc(1);
        frames_done = frame + 1;
        if crate::interrupt::requested().is_some() {
            break; // the frame in flight is complete; report what was rendered
        }
    }
    bar.finish_and_clear();
    let interrupted = crate::interrupt::requested();
    if let Some(debug) = &debug {
        debug.finish(&renderer)?;
    }
    super::check_validation(&ctx)?;

    let n = frames_done as u64;
    let passes: BTreeMap<String, f64> = pass_sums.into_iter().map(|(k, v)| (k, v / frames_done as f64)).collect();
    let rays = RayReport { primary: rays.primary / n, shadow: rays.shadow / n, continuation: rays.continuation / n };
    let report = Report {
        method: args.method.to_string(),
        denoiser: denoiser.name().to_string(),
        taa: taa.name().to_string(),
        scene: scene.source.display().to_string(),
        headset: hmd.id.clone(),
        gaze_source: args.gaze.to_string(),
        gaze: gaze_points,
        gaze_live: origins[0],
        gaze_held: origins[1],
        gaze_centre: origins[2],
        device: ctx.info.name.clone(),
        width,
        height,
        vp_width: grid.x,
        vp_height: grid.y,
        frames: frames_done,
        samples_traced: samples / n,
        samples_offscreen: offscreen / n,
        screen_pixels,
        rays_traced: rays.primary + rays.shadow + rays.continuation,
        rays,
        max_depth: args.max_depth,
        seed: args.seed,
        camera_path: args.camera_path,
        visual_polar: (args.method == "vp").then(|| vp_report(&args.profile)),
        blur_sigma_at_30: (args.method == "vp").then_some(args.profile.blur.sigma_at_30),
        frame_gpu_ms: passes.values().sum(),
        passes,
        wall_seconds: started.elapsed().as_secs_f64(),
        interrupted: interrupted.is_some(),
    };
    write_json(&args.out.join("report.json"), &report)?;
    out_dir.remove_stale()?;
    if let Some(interrupted) = interrupted {
        return Err(interrupted.into());
    }
    println!(
        "rendered {} frame(s) of {}×{} ({}, denoiser {}, taa {}, grid {}×{}, {} samples) on {}: {:.1} ms GPU per frame, {} rays per frame → {}",
        frames_done,
        width,
        height,
        report.method,
        report.denoiser,
        report.taa,
        grid.x,
        grid.y,
        report.samples_traced,
        report.device,
        report.frame_gpu_ms,
        report.rays_traced,
        args.out.display()
    );
    Ok(())
}

fn vp_report(profile: &RenderProfile) -> VpReport {
    use fovea_renderer::sampling::{InverseCdf, RadiusMode};
    let p = &profile.visual_polar;
    VpReport {
        axis_scale: p.axis_scale,
        clip_fraction: p.clip_fraction,
        fovea_deg: p.fovea_deg,
        density_exponent: p.density_exponent,
        // The headset axis always uses the exact inverse (the quartic is a fit for [0, 80]).
        inverse_cdf: match (p.inverse_cdf, profile.eccentricity) {
            (_, crate::render_profile::EccentricityMode::Headset) | (InverseCdf::Exact, _) => "exact".into(),
            (InverseCdf::Polynomial, _) => "polynomial".into(),
        },
        radius: match p.radius_mode {
            RadiusMode::FarthestCorner => "corner".into(),
            RadiusMode::Fixed(r) => format!("{r}"),
        },
        layout: crate::render_profile::layout_name(p.layout).into(),
        eccentricity: crate::render_profile::eccentricity_name(profile.eccentricity).into(),
    }
}
