//! `fovea reference`: a converged linear-radiance EXR (many samples per pixel, chosen depth).

use crate::output::{check_new_file, tonemap_preview, write_exr, write_png};
use anyhow::{bail, Context, Result};
use fovea_renderer::frame::RenderSettings;
use fovea_renderer::passes::tonemap::ToneCurve;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::Cartesian;
use glam::UVec2;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::Path;

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
    pub camera: &'a crate::look::CameraOptions,
    /// The headset whose eye is rendered (`--projection headset`) and which eye.
    pub headset: &'a str,
    pub eye: fovea_hal::Eye,
    pub environment: crate::look::EnvironmentOptions,
    /// `RenderSettings::path_regularisation` (already checked).
    pub path_regularisation: f32,
}

pub fn run(args: &ReferenceArgs) -> Result<()> {
    if args.width == 0 || args.height == 0 || args.spp == 0 || args.max_depth == 0 {
        bail!("--width, --height, --spp and --max-depth must be at least 1");
    }
    if args.max_depth > super::setup::MAX_DEPTH_LIMIT {
        bail!(
            "--max-depth {} must be in 1..={} (path vertices)",
            args.max_depth,
            super::setup::MAX_DEPTH_LIMIT
        );
    }
    check_new_file(args.out, args.force)?;
    let preview = args.out.with_extension("png");
    if args.preview {
        check_new_file(&preview, args.force)?;
    }
    let rig = crate::projection::EyeRig {
        projection: args.camera.projection,
        hmd: fovea_hal::HmdDescription::resolve(args.headset)
            .with_context(|| format!("--headset {}", args.headset))?,
        stereo: false,
        width: args.width,
        height: args.height,
        metres_per_unit: args.camera.world_scale,
    };
    let (scene, camera) =
        crate::look::load(args.scene, args.camera, &args.environment, rig.framing())?;
    let pose = rig.eye(&rig.head(&camera), args.eye);
    let ctx = super::open_device(args.device, args.validation)?;
    let settings = RenderSettings {
        max_depth: args.max_depth,
        seed: args.seed,
        path_regularisation: args.path_regularisation,
        ..Default::default()
    };
    let space = Box::new(Cartesian::new(UVec2::new(args.width, args.height)));
    let mut renderer = Renderer::new(&ctx, &scene, space, settings)?;
    let bar = ProgressBar::new(args.spp as u64);
    bar.set_style(ProgressStyle::with_template(
        "{bar:40} {pos}/{len} spp  {elapsed} (eta {eta})",
    )?);
    let started = std::time::Instant::now();
    let image = renderer.render_reference(&pose, args.spp, args.max_depth, |done| {
        bar.set_position(done as u64)
    })?;
    bar.finish_and_clear();
    write_exr(args.out, args.width, args.height, &image)?;
    let displayed = tonemap_preview(&image, 1.0, ToneCurve::Aces);
    if args.preview {
        write_png(&preview, args.width, args.height, &displayed)?;
    }
    super::check_validation(&ctx)?;
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
    // What a converged image should not have: isolated pixels far brighter than their neighbours.
    let (w, h) = (args.width as usize, args.height as usize);
    let [ff30, ff60, ff100] = [30.0, 60.0, 100.0]
        .map(|levels| crate::metrics::isolated_bright_pixels(&displayed, w, h, levels));
    println!("fireflies (pixels of the tonemapped image brighter than all 8 neighbours by > 30 / 60 / 100 of 255 levels): {ff30} / {ff60} / {ff100} of {}", w * h);
    Ok(())
}
