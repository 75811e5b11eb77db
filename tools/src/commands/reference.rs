//! `fovea reference`: a converged linear-radiance EXR (many samples per pixel, chosen depth).

use super::flags::{DeviceArgs, SceneFlags};
use super::render_args::Eyes;
use crate::output::{check_new_file, tonemap_preview, write_exr, write_png};
use anyhow::{bail, Context as _, Result};
use fovea_renderer::frame::{CameraPose, RenderSettings};
use fovea_renderer::passes::tonemap::ToneCurve;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::Cartesian;
use fovea_renderer::vk::Context;
use glam::UVec2;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub struct ReferenceArgs<'a> {
    pub scene: &'a str,
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub max_depth: u32,
    pub seed: u32,
    pub out: &'a Path,
    pub force: bool,
    /// Also write a tonemapped PNG next to the EXR (same name, .png).
    pub preview: bool,
    pub device: Option<&'a str>,
    pub validation: bool,
    pub camera: &'a fovea_stage::look::CameraOptions,
    /// The headset whose eye is rendered (`--projection headset`) and which eye.
    pub headset: &'a str,
    pub eye: fovea_hal::Eye,
    pub environment: fovea_stage::look::EnvironmentOptions,
    /// `RenderSettings::path_regularisation` (already checked).
    pub path_regularisation: f32,
}

/// The most samples per pixel `fovea reference --spp` takes (about 2²⁰: a 64-spp frame of noise
/// is already below FLIP's visibility at 16 Ki; a million is a converged bound, not a goal).
pub const MAX_REFERENCE_SPP: u32 = 1 << 20;

/// Checks the numbers of the flags.
pub fn check(args: &ReferenceArgs) -> Result<()> {
    if args.width == 0 || args.height == 0 || args.spp == 0 || args.max_depth == 0 {
        bail!("--width, --height, --spp and --max-depth must be at least 1");
    }
    let max_side = super::setup::MAX_RENDER_SIDE;
    if args.width > max_side || args.height > max_side {
        bail!(
            "--width {} --height {}: each must be at most {max_side} pixels",
            args.width,
            args.height
        );
    }
    if args.spp > MAX_REFERENCE_SPP {
        bail!(
            "--spp {} must be at most {MAX_REFERENCE_SPP} (a reference converges long before)",
            args.spp
        );
    }
    if args.max_depth > super::setup::MAX_DEPTH_LIMIT {
        bail!(
            "--max-depth {} must be in 1..={} (path vertices)",
            args.max_depth,
            super::setup::MAX_DEPTH_LIMIT
        );
    }
    Ok(())
}

/// The Cartesian renderer of the reference and the eye's pose.
pub fn renderer(args: &ReferenceArgs) -> Result<(Arc<Context>, Renderer, CameraPose)> {
    let rig = fovea_stage::projection::EyeRig {
        projection: args.camera.projection,
        hmd: fovea_hal::HmdDescription::resolve(args.headset)
            .with_context(|| format!("--headset {}", args.headset))?,
        stereo: false,
        width: args.width,
        height: args.height,
        metres_per_unit: args.camera.world_scale,
    };
    let (scene, camera) =
        fovea_stage::look::load(args.scene, args.camera, &args.environment, rig.framing())?;
    let pose = rig.eye(&rig.head(&camera), args.eye);
    let ctx = super::open_device(args.device, args.validation)?;
    let settings = RenderSettings {
        max_depth: args.max_depth,
        seed: args.seed,
        path_regularisation: args.path_regularisation,
        ..Default::default()
    };
    let space = Box::new(Cartesian::new(UVec2::new(args.width, args.height)));
    let renderer = Renderer::new(&ctx, &scene, space, settings)?;
    Ok((ctx, renderer, pose))
}

pub fn run(args: &ReferenceArgs) -> Result<()> {
    check(args)?;
    check_new_file(args.out, args.force)?;
    if args.preview {
        check_new_file(&args.out.with_extension("png"), args.force)?;
    }
    let (ctx, mut renderer, pose) = renderer(args)?;
    let bar = ProgressBar::new(args.spp as u64);
    bar.set_style(ProgressStyle::with_template(
        "{bar:40} {pos}/{len} spp  {elapsed} (eta {eta})",
    )?);
    let started = std::time::Instant::now();
    // Summed in the fixed batch order of `reference_sum`, so `fovea sweep` can split it exactly.
    let image = crate::reference_sum::render(
        &mut renderer,
        &pose,
        args.spp,
        args.max_depth,
        &mut |done| {
            bar.set_position(done as u64);
            Ok(())
        },
    )?;
    bar.finish_and_clear();
    super::check_validation(&ctx)?;
    write(args, args.out, &image)?;
    println!(
        "wrote {} ({}×{}, {} spp, max depth {}, path regularisation {}) in {:.1} s on {}",
        args.out.display(),
        args.width,
        args.height,
        args.spp,
        args.max_depth,
        args.path_regularisation,
        started.elapsed().as_secs_f64(),
        ctx.info.name
    );
    fireflies(args, &image);
    Ok(())
}

/// Writes the reference to `out` (and its preview next to it with `--preview`).
pub fn write(args: &ReferenceArgs, out: &Path, image: &[[f32; 4]]) -> Result<()> {
    write_exr(out, args.width, args.height, image)?;
    if args.preview {
        let displayed = tonemap_preview(image, 1.0, ToneCurve::Aces);
        write_png(
            &out.with_extension("png"),
            args.width,
            args.height,
            &displayed,
        )?;
    }
    Ok(())
}

/// What a converged image should not have: isolated pixels far brighter than their neighbours.
pub fn fireflies(args: &ReferenceArgs, image: &[[f32; 4]]) {
    let displayed = tonemap_preview(image, 1.0, ToneCurve::Aces);
    let (w, h) = (args.width as usize, args.height as usize);
    let [ff30, ff60, ff100] = [30.0, 60.0, 100.0]
        .map(|levels| crate::eval::metrics::isolated_bright_pixels(&displayed, w, h, levels));
    println!("fireflies (pixels of the tonemapped image brighter than all 8 neighbours by > 30 / 60 / 100 of 255 levels): {ff30} / {ff60} / {ff100} of {}", w * h);
}

// `fovea reference`'s flags (also the command a reference sweep splits; its help is the
// variant's in `crate::cli::Command`).
#[derive(clap::Args)]
pub struct ReferenceCommand {
    #[arg(long, default_value = fovea_stage::scenes::DEFAULT_SCENE)]
    pub scene: String,
    #[arg(long, default_value_t = 256)]
    pub width: u32,
    #[arg(long, default_value_t = 256)]
    pub height: u32,
    #[arg(long, default_value_t = 1024)]
    pub spp: u32,
    #[arg(long, default_value_t = 3)]
    pub max_depth: u32,
    #[arg(long, default_value_t = 1)]
    pub seed: u32,
    #[arg(long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub look: SceneFlags,
    /// Headset profile whose eye is rendered (with --projection headset, the default).
    #[arg(long, default_value = "fove0")]
    pub headset: String,
    /// The eye: left (as `fovea render` writes by default) or right.
    #[arg(long, default_value = "left")]
    pub eye: String,
    /// Replace FILE if it exists.
    #[arg(long)]
    pub force: bool,
    /// Also write a tonemapped PNG preview (FILE with .png).
    #[arg(long)]
    pub preview: bool,
    #[command(flatten)]
    pub device: DeviceArgs,
}

impl ReferenceCommand {
    pub fn run(self) -> Result<()> {
        self.with_args(&mut run)
    }

    /// The flags as the command's arguments, handed to `run` (the command itself, or a sweep).
    pub fn with_args(self, run: &mut dyn FnMut(&ReferenceArgs) -> Result<()>) -> Result<()> {
        let ReferenceCommand {
            scene,
            width,
            height,
            spp,
            max_depth,
            seed,
            out,
            look,
            headset,
            eye,
            force,
            preview,
            device,
        } = self;
        device.choose_traversal()?;
        run(&ReferenceArgs {
            camera: &look.camera()?,
            headset: &headset,
            eye: match Eyes::parse(&eye)? {
                Eyes::Left => fovea_hal::Eye::Left,
                Eyes::Right => fovea_hal::Eye::Right,
                Eyes::Both => bail!("--eye both: a reference is one eye (left or right)"),
            },
            environment: look.environment()?,
            path_regularisation: crate::render_profile::check_path_regularisation(
                look.path_regularisation,
                "--path-regularisation",
            )?,
            scene: &scene,
            width,
            height,
            spp,
            max_depth,
            seed,
            out: &out,
            force,
            preview,
            device: device.device.as_deref(),
            validation: device.validation,
        })
    }
}
