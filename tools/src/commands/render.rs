//! `fovea render`: N frames of the scene, written as PNG (and linear EXR), plus report.json with
//! exact sample/ray counts and mean GPU milliseconds per pass.

use crate::camera_path;
use crate::output::{prepare_output_dir, write_exr, write_png};
use anyhow::{bail, Result};
use fovea_renderer::pipeline::{CameraPose, FrameInput, RenderSettings, Renderer};
use fovea_renderer::sampling::{Cartesian, SamplingSpace};
use glam::UVec2;
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

pub struct RenderArgs<'a> {
    pub scene: &'a str,
    pub method: &'a str,
    pub width: u32,
    pub height: u32,
    pub frames: u32,
    pub out: &'a Path,
    pub exr: bool,
    pub camera_path: bool,
    pub seed: u32,
    pub max_depth: u32,
    pub exposure: f32,
    pub device: Option<&'a str>,
    pub validation: bool,
}

#[derive(Serialize)]
struct Report {
    method: String,
    scene: String,
    device: String,
    width: u32,
    height: u32,
    frames: u32,
    /// Samples traced in one frame.
    samples_traced: u64,
    screen_pixels: u64,
    /// Rays traced in one frame (mean over frames): primary + shadow + continuation.
    rays_traced: u64,
    rays: RayReport,
    max_depth: u32,
    seed: u32,
    camera_path: bool,
    /// Pass name → mean GPU milliseconds per frame.
    passes: BTreeMap<String, f64>,
    /// Sum of the pass means.
    frame_gpu_ms: f64,
    /// Wall-clock seconds for all frames, including read-back and file writing.
    wall_seconds: f64,
}

#[derive(Serialize, Default)]
struct RayReport {
    primary: u64,
    shadow: u64,
    continuation: u64,
}

pub fn run(args: &RenderArgs) -> Result<()> {
    if args.width == 0 || args.height == 0 || args.frames == 0 {
        bail!("--width, --height and --frames must be at least 1");
    }
    if args.method != "cartesian" {
        bail!("--method {}: only 'cartesian' is implemented so far (Visual-Polar is not done yet)", args.method);
    }
    let scene = crate::scenes::load(args.scene)?;
    let Some(camera) = scene.default_camera() else {
        bail!("{}: the scene has no perspective camera", scene.source.display());
    };
    prepare_output_dir(args.out)?;
    let start_pose = CameraPose::from_scene_camera(camera, args.width, args.height);
    let ctx = super::open_device(args.device, args.validation)?;
    let settings = RenderSettings { max_depth: args.max_depth, seed: args.seed, exposure: args.exposure, ..Default::default() };
    let space = Box::new(Cartesian { screen: UVec2::new(args.width, args.height) });
    let screen_pixels = space.screen_size().x as u64 * space.screen_size().y as u64;
    let mut renderer = Renderer::new(&ctx, &scene, space, settings)?;
    let centre = scene.bounds().center();

    let bar = ProgressBar::new(args.frames as u64);
    bar.set_style(ProgressStyle::with_template("{bar:40} frame {pos}/{len}  {elapsed} (eta {eta})")?);
    let started = std::time::Instant::now();
    let mut pass_sums: BTreeMap<String, f64> = BTreeMap::new();
    let (mut samples, mut rays) = (0u64, RayReport::default());
    let mut ldr = Vec::new();
    let mut hdr = Vec::new();
    for frame in 0..args.frames {
        let camera = if args.camera_path { camera_path::orbit(&start_pose, centre, frame, args.frames) } else { start_pose };
        let stats = renderer.render_frame(&FrameInput { camera, frame_index: frame, read_hdr: args.exr })?;
        samples += stats.samples_traced;
        rays.primary += stats.primary_rays;
        rays.shadow += stats.shadow_rays;
        rays.continuation += stats.continuation_rays;
        for t in renderer.timings() {
            *pass_sums.entry(t.name.to_string()).or_default() += t.ms;
        }
        renderer.read_ldr(&mut ldr)?;
        write_png(&args.out.join(format!("frame_{frame:04}.png")), args.width, args.height, &ldr)?;
        if args.exr {
            renderer.read_hdr(&mut hdr)?;
            write_exr(&args.out.join(format!("frame_{frame:04}.exr")), args.width, args.height, &hdr)?;
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    super::check_validation(&ctx)?;

    let n = args.frames as u64;
    let passes: BTreeMap<String, f64> = pass_sums.into_iter().map(|(k, v)| (k, v / args.frames as f64)).collect();
    let rays = RayReport { primary: rays.primary / n, shadow: rays.shadow / n, continuation: rays.continuation / n };
    let report = Report {
        method: args.method.to_string(),
        scene: scene.source.display().to_string(),
        device: ctx.info.name.clone(),
        width: args.width,
        height: args.height,
        frames: args.frames,
        samples_traced: samples / n,
        screen_pixels,
        rays_traced: rays.primary + rays.shadow + rays.continuation,
        rays,
        max_depth: args.max_depth,
        seed: args.seed,
        camera_path: args.camera_path,
        frame_gpu_ms: passes.values().sum(),
        passes,
        wall_seconds: started.elapsed().as_secs_f64(),
    };
    let path = args.out.join("report.json");
    std::fs::write(&path, serde_json::to_string_pretty(&report)? + "\n")?;
    println!(
        "rendered {} frame(s) of {}×{} ({}) on {}: {:.1} ms GPU per frame, {} rays per frame → {}",
        args.frames,
        args.width,
        args.height,
        report.method,
        report.device,
        report.frame_gpu_ms,
        report.rays_traced,
        args.out.display()
    );
    Ok(())
}
