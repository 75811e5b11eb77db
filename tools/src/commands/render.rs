//! `fovea render`: N frames of the scene, written as PNG (and linear EXR), plus report.json with
//! exact sample/ray counts and mean GPU milliseconds per pass.

use super::flags::DeviceArgs;
use super::methods::{ReportSection, VpVariant};
use super::render_args::Eyes;
pub use super::render_args::RenderArgs;
use super::render_args::{RenderDefaults, RenderOpts, DEFAULT_SCALE};
use super::setup::Setup;
use crate::output::{prepare_output_dir, write_exr, write_json, write_png};
use crate::render_profile::RenderProfile;
use anyhow::Result;
use fovea_hal::GazeOrigin;
use fovea_renderer::frame::FrameStats;
use fovea_renderer::gpu_scene::GpuScene;
use fovea_renderer::pipeline::Renderer;
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use std::collections::BTreeMap;

#[derive(Serialize)]
struct Report {
    method: String,
    /// Denoiser in the sampling grid (`none`, `svgf`, `asvgf`, `bmfr`).
    denoiser: String,
    /// TAA: `off`, `vp` (in the sampling grid) or `screen` (after the remap; for Cartesian the
    /// sampling-grid filter, the grid being the screen).
    taa: String,
    /// Texture filtering: `cones` (ray-cone mip levels) or `off` (level 0).
    texture_lod: &'static str,
    /// Path regularisation strength (0 = off, the unbiased estimator).
    path_regularisation: f32,
    /// `cull` (samples far off the screen not traced) or `trace`.
    offscreen_samples: &'static str,
    /// `off` or `di` (ReSTIR DI at the primary hit, `--resampling`).
    resampling: &'static str,
    /// How the eyes' random numbers relate: `independent`, `screen` or `surface`.
    stereo_noise: &'static str,
    /// `surface` noise: its cells' edge in sample footprints.
    #[serde(skip_serializing_if = "Option::is_none")]
    surface_cell: Option<f32>,
    /// Whether each eye's samples took the other eye's (`--cross-eye-reuse`: with both eyes,
    /// `auto` where they can).
    cross_eye_reuse: bool,
    scene: String,
    headset: String,
    /// `headset` (each eye through the profile's frustum, the camera the head) or
    /// `scene-camera` (`--projection`).
    projection: &'static str,
    /// "left", "right" or "both".
    eyes: String,
    frames_in_flight: usize,
    gaze_source: String,
    /// Gaze point per frame in the left eye's render pixels (the Cartesian method traces uniformly and only
    /// records it; foveated methods centre their sampling on it).
    gaze: Vec<[f32; 2]>,
    /// A run of both eyes: the same gaze per frame in the right eye's render pixels.
    #[serde(skip_serializing_if = "Option::is_none")]
    gaze_right: Option<Vec<[f32; 2]>>,
    /// Per frame: live, held or centre (`fovea replay` checks the playback frame by frame).
    gaze_origin: Vec<&'static str>,
    /// Frames whose gaze was live / held after a lost sample / the view centre.
    gaze_live: u32,
    gaze_held: u32,
    gaze_centre: u32,
    /// Of `gaze_centre`: frames whose gaze lay behind or outside a rendered eye's view (the
    /// source gave one, the frame foveated at the image centre).
    gaze_outside_view: u32,
    /// With the latency model (`--latency-ms`, `--tracker-hz`, `--gaze-predict`): per frame
    /// where the eye is at its display time (left eye's render pixels, null without gaze or off
    /// the image), and the latency accounting.
    #[serde(skip_serializing_if = "Option::is_none")]
    gaze_true: Option<Vec<Option<[f32; 2]>>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    gaze_latency: Option<fovea_stage::gaze::LatencyLog>,
    device: String,
    width: u32,
    height: u32,
    /// Sampling-grid size (the screen for Cartesian).
    vp_width: u32,
    vp_height: u32,
    frames: u32,
    /// Samples traced in one frame of one eye (mean).
    samples_traced: u64,
    /// Traced samples per frame (mean) whose screen position is off the screen.
    samples_offscreen: u64,
    /// Samples per frame (mean) not traced because they lay far off the screen (`--offscreen-samples cull`).
    samples_culled: u64,
    screen_pixels: u64,
    /// Rays traced in one frame of one eye (mean): primary + shadow + continuation.
    rays_traced: u64,
    rays: RayReport,
    max_depth: u32,
    seed: u32,
    /// `auto` (metered and adapted), `auto+EV`/`auto-EV`, or the fixed exposure in stops.
    exposure_mode: String,
    /// The display transform (`--tone`).
    tone: &'static str,
    /// Per frame: the exposure multiplier its pixels were displayed with (both eyes share it).
    exposure: Vec<f32>,
    /// Whether the camera moved (`camera_motion` says how).
    camera_path: bool,
    /// `still`, `orbit` or `keys` (a `--camera-path` file).
    camera_motion: &'static str,
    /// Visual-Polar parameters (vp only).
    visual_polar: Option<VpReport>,
    /// Log-polar parameters (log-polar only).
    log_polar: Option<LogPolarReport>,
    /// Andersson & Hansson's mode (composite only).
    composite_mode: Option<&'static str>,
    /// Foveated blur σ at 30° for a 1280×1440 eye (the methods with the foveated blur; 0 = off).
    blur_sigma_at_30: Option<f32>,
    /// Where that blur was asked to run: screen | grid (`--blur-space`; the grid where the space
    /// allows it, see the passes in `passes`: `blur_grid_*` or `blur_h`/`blur_v*`).
    blur_space: Option<&'static str>,
    /// Pass name → mean GPU milliseconds per frame (both eyes' passes summed in a stereo run).
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
    /// "paper", "screen-clipped" or "screen-aware".
    layout: String,
    /// The ρ axis: "normalized" (the paper's) or "headset" (true degrees through the eye's FOV).
    eccentricity: String,
}

#[derive(Serialize)]
struct LogPolarReport {
    sigma: f32,
    alpha: f32,
    /// "corner" (Meng) or "diagonal" (Andersson & Hansson).
    extent: &'static str,
}

#[derive(Serialize, Default)]
struct RayReport {
    primary: u64,
    shadow: u64,
    continuation: u64,
}

pub fn run(args: &RenderArgs) -> Result<()> {
    let frames = args.frames;
    let mut setup = Setup::new(args, frames)?;
    let (width, height, eyes) = (setup.width, setup.height, setup.eyes);
    let out_dir = prepare_output_dir(args.out)?;
    // Every file of the run goes here first and into `args.out` only once all are written.
    let staged = out_dir.stage()?;
    let ctx = super::open_device(args.device, args.validation)?;
    let spaces = setup.spaces(args.method, &args.profile)?;
    let grid = spaces[0].grid_size();
    let screen = setup.screen();
    let screen_pixels = screen.x as u64 * screen.y as u64;
    // Debug views read the space's gaze after each frame: they need each frame waited for.
    let in_flight = if args.debug_views {
        1
    } else {
        super::setup::frames_in_flight(args.frames_in_flight, frames)
    };
    let scene = GpuScene::upload(&ctx, &setup.scene)?;
    let mut renderer = Renderer::with_views(&ctx, scene, spaces, setup.settings, in_flight)?;
    let mut out = FrameWriter {
        args,
        dir: staged.path(),
        eyes,
        width,
        height,
        debug: args
            .debug_views
            .then(|| super::debug_views::DebugViews::new(staged.path(), screen, grid)),
        pass_sums: BTreeMap::new(),
        totals: FrameStats::default(),
        ldr: Vec::new(),
        hdr: Vec::new(),
        exposures: Vec::with_capacity(frames as usize),
    };

    let bar = ProgressBar::new(frames as u64);
    bar.set_style(ProgressStyle::with_template(
        "{bar:40} frame {pos}/{len}  {elapsed} (eta {eta})",
    )?);
    let started = std::time::Instant::now();
    let mut gaze_points = Vec::with_capacity(frames as usize);
    let mut gaze_right = Vec::with_capacity(frames as usize);
    let mut gaze_origin = Vec::with_capacity(frames as usize);
    let mut origins = [0u32; 3];
    let mut outside_view = 0u32;
    let mut latency_log = fovea_stage::gaze::LatencyLog::for_driver(&setup.gaze);
    let mut submitted = 0u32;
    let mut recent = super::overview::RecentFrames::default();
    crate::interrupt::running(); // a signal from here on stops after the frames in flight
    for frame in 0..frames {
        if crate::interrupt::requested().is_some() {
            break; // finish the frames in flight below; report what was rendered
        }
        let (input, frame_gaze) = setup.frame_input(frame)?;
        gaze_points.push(frame_gaze.pixel.to_array());
        gaze_right.push(frame_gaze.pixels[fovea_hal::Eye::Right.index()].to_array());
        gaze_origin.push(frame_gaze.origin.name());
        origins[match frame_gaze.origin {
            GazeOrigin::Live => 0,
            GazeOrigin::Held => 1,
            GazeOrigin::Centre => 2,
        }] += 1;
        outside_view += u32::from(frame_gaze.reason.is_some());
        if let Some(log) = &mut latency_log {
            log.push(&frame_gaze);
        }
        let input = input.with_hdr(args.exr).with_grid(args.debug_views);
        recent.push(input);
        // The slot this frame takes held frame − in_flight: write that one out first.
        if let Some(done) = renderer.retire_next()? {
            out.write(&renderer, done)?;
            bar.inc(1);
        }
        renderer.submit(&input, None)?;
        submitted = frame + 1;
    }
    renderer.finish()?;
    for done in submitted.saturating_sub(in_flight as u32) as u64..submitted as u64 {
        out.write(&renderer, done)?;
        bar.inc(1);
    }
    bar.finish_and_clear();
    let interrupted = crate::interrupt::requested();
    let frames = submitted;
    if frames == 0 {
        // Stopped before the first frame: nothing to report.
        return Err(interrupted
            .map(anyhow::Error::from)
            .unwrap_or_else(|| anyhow::anyhow!("no frame rendered")));
    }
    if let Some(debug) = &out.debug {
        debug.finish(&renderer)?;
    }
    let overview = match args.overview && interrupted.is_none() {
        true => {
            let staged_overview = super::overview::Overview {
                ctx: &ctx,
                setup: &setup,
                renderer: &renderer,
                last_frame: frames as u64 - 1,
                recent: &recent,
            }
            .write(staged.path())?;
            // Where it lies once the run is moved into place.
            Some(
                args.out
                    .join(staged_overview.file_name().unwrap_or_default()),
            )
        }
        false => None,
    };
    super::check_validation(&ctx)?;

    let views = eyes.list().len() as u64;
    let n = frames as u64 * views;
    let totals = out.totals;
    let passes: BTreeMap<String, f64> = out
        .pass_sums
        .into_iter()
        .map(|(k, v)| (k, v / frames as f64))
        .collect();
    let rays = RayReport {
        primary: totals.primary_rays / n,
        shadow: totals.shadow_rays / n,
        continuation: totals.continuation_rays / n,
    };
    let method = super::methods::method(args.method)?;
    let report = Report {
        method: args.method.to_string(),
        denoiser: setup.denoiser.name().to_string(),
        taa: setup.taa.name().to_string(),
        texture_lod: args.profile.texture_lod.name(),
        path_regularisation: args.profile.path_regularisation(),
        offscreen_samples: args.profile.offscreen_samples.name(),
        resampling: args.profile.resampling.mode.name(),
        stereo_noise: args.profile.stereo_noise.name(),
        surface_cell: (args.profile.stereo_noise == fovea_renderer::frame::StereoNoise::Surface)
            .then(|| args.profile.surface_cell()),
        cross_eye_reuse: renderer.reuses_across_eyes(),
        scene: setup.scene.source.display().to_string(),
        headset: setup.hmd.id.clone(),
        projection: args.camera.projection.name(),
        eyes: eyes.name().to_string(),
        frames_in_flight: in_flight,
        gaze_source: args.gaze.to_string(),
        gaze: gaze_points,
        gaze_right: (eyes == Eyes::Both).then_some(gaze_right),
        gaze_origin,
        gaze_live: origins[0],
        gaze_held: origins[1],
        gaze_centre: origins[2],
        gaze_outside_view: outside_view,
        gaze_true: latency_log.as_ref().map(|l| l.true_pixels.clone()),
        gaze_latency: latency_log,
        device: ctx.info.name.clone(),
        width,
        height,
        vp_width: grid.x,
        vp_height: grid.y,
        frames,
        samples_traced: totals.samples_traced / n,
        samples_offscreen: totals.samples_offscreen / n,
        samples_culled: totals.samples_culled / n,
        screen_pixels,
        rays_traced: rays.primary + rays.shadow + rays.continuation,
        rays,
        max_depth: args.max_depth,
        seed: args.seed,
        exposure_mode: exposure_name(&args.exposure),
        tone: args.tone.name(),
        exposure: out.exposures,
        camera_path: args.camera_path.moves(),
        camera_motion: args.camera_path.name(),
        visual_polar: match method.report {
            ReportSection::VisualPolar(variant) => Some(vp_report(&args.profile, variant)),
            _ => None,
        },
        log_polar: (method.report == ReportSection::LogPolar).then(|| {
            let p = &args.profile.log_polar;
            LogPolarReport {
                sigma: p.sigma,
                alpha: p.alpha,
                extent: crate::render_profile::log_polar_extent_name(p.extent),
            }
        }),
        composite_mode: (method.report == ReportSection::Composite)
            .then(|| args.profile.composite_mode.name()),
        blur_sigma_at_30: method.blurs.then_some(args.profile.blur.sigma_at_30),
        blur_space: method.blurs.then_some(args.profile.blur.space.name()),
        frame_gpu_ms: passes.values().sum(),
        passes,
        wall_seconds: started.elapsed().as_secs_f64(),
        interrupted: interrupted.is_some(),
    };
    write_json(&staged.path().join(crate::output::REPORT_FILE), &report)?;
    staged.commit(&out_dir)?;
    if let Some(interrupted) = interrupted {
        return Err(interrupted.into());
    }
    println!(
        "rendered {} frame(s) of {}×{} ({} eye(s), {}, resampling {}, denoiser {}, taa {}, grid {}×{}, {} samples per eye) on {}: {:.1} ms GPU per frame, {} rays per eye and frame → {}",
        frames,
        width,
        height,
        eyes.name(),
        report.method,
        report.resampling,
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
    if let Some(path) = overview {
        println!(
            "overview: {} (left: the last frame; middle: the same frame at full cost, every pixel traced; right: samples per pixel, the gaze marked)",
            path.display()
        );
    }
    Ok(())
}

/// Writes each completed frame's images and adds its counts and timings up.
struct FrameWriter<'a> {
    args: &'a RenderArgs<'a>,
    /// Where the frames go (the run's staging folder).
    dir: &'a std::path::Path,
    eyes: Eyes,
    width: u32,
    height: u32,
    debug: Option<super::debug_views::DebugViews>,
    pass_sums: BTreeMap<String, f64>,
    totals: FrameStats,
    ldr: Vec<u8>,
    hdr: Vec<[f32; 4]>,
    exposures: Vec<f32>,
}

impl FrameWriter<'_> {
    fn write(&mut self, renderer: &Renderer, frame: u64) -> Result<()> {
        self.exposures.push(renderer.frame_exposure(frame)?);
        for t in renderer.frame_timings(frame)? {
            *self.pass_sums.entry(t.name.to_string()).or_default() += t.ms;
        }
        for (view, eye) in self.eyes.list().iter().enumerate() {
            let stats = renderer.frame_stats(frame, view)?;
            self.totals.samples_traced += stats.samples_traced;
            self.totals.samples_offscreen += stats.samples_offscreen;
            self.totals.samples_culled += stats.samples_culled;
            self.totals.primary_rays += stats.primary_rays;
            self.totals.shadow_rays += stats.shadow_rays;
            self.totals.continuation_rays += stats.continuation_rays;
            // A one-eye run keeps the plain names (frame_NNNN.png); stereo names each eye.
            let suffix = match self.eyes {
                Eyes::Both => format!("_{}", super::setup::eye_name(*eye)),
                _ => String::new(),
            };
            renderer.read_view_ldr(frame, view, &mut self.ldr)?;
            write_png(
                &self.dir.join(format!("frame_{frame:04}{suffix}.png")),
                self.width,
                self.height,
                &self.ldr,
            )?;
            if self.args.exr {
                renderer.read_view_hdr(frame, view, &mut self.hdr)?;
                write_exr(
                    &self.dir.join(format!("frame_{frame:04}{suffix}.exr")),
                    self.width,
                    self.height,
                    &self.hdr,
                )?;
            }
        }
        if let Some(debug) = &mut self.debug {
            debug.frame(frame as u32, renderer)?;
        }
        Ok(())
    }
}

/// `--exposure` as the report names it: `auto`, `auto+EV`, or the fixed exposure in stops.
pub fn exposure_name(exposure: &fovea_renderer::passes::exposure::Exposure) -> String {
    use fovea_renderer::passes::exposure::Exposure;
    match exposure {
        Exposure::Auto(a) if a.compensation_ev == 0.0 => "auto".into(),
        Exposure::Auto(a) => format!("auto{:+}", a.compensation_ev),
        Exposure::Manual(m) => format!("{}", m.log2()),
    }
}

/// `variant`: the profile's Visual-Polar, or a variant that sets the layout or the axis whatever
/// the profile says (`vp-paper`, `vp-screen-clipped`, `vp-screen-aware`, `vp-headset`).
fn vp_report(profile: &RenderProfile, variant: VpVariant) -> VpReport {
    use fovea_renderer::sampling::{InverseCdf, RadiusMode};
    let p = &profile.visual_polar;
    let headset = variant == VpVariant::Headset
        || profile.eccentricity == crate::render_profile::EccentricityMode::Headset;
    VpReport {
        axis_scale: p.axis_scale,
        clip_fraction: p.clip_fraction,
        fovea_deg: p.fovea_deg,
        density_exponent: p.density_exponent,
        // The headset axis always uses the exact inverse (the quartic is a fit for [0, 80]).
        inverse_cdf: match (p.inverse_cdf, headset) {
            (_, true) | (InverseCdf::Exact, _) => "exact".into(),
            (InverseCdf::Polynomial, false) => "polynomial".into(),
        },
        radius: match p.radius_mode {
            RadiusMode::FarthestCorner => "corner".into(),
            RadiusMode::Fixed(r) => format!("{r}"),
        },
        layout: match variant {
            VpVariant::ScreenClipped => "screen-clipped".into(),
            VpVariant::ScreenAware => "screen-aware".into(),
            VpVariant::Paper | VpVariant::Headset => "paper".into(),
            VpVariant::Profile => crate::render_profile::layout_name(p.layout).into(),
        },
        eccentricity: if headset {
            "headset".into()
        } else {
            crate::render_profile::eccentricity_name(profile.eccentricity).into()
        },
    }
}

/// `fovea render`'s length without `--frames`.
pub const DEFAULT_RENDER_FRAMES: u32 = 24;

// `fovea render` (its help is the variant's in `crate::cli::Command`).
#[derive(clap::Args)]
pub struct RenderCommand {
    // Boxed: the render options dwarf every other command's.
    #[command(flatten)]
    pub opts: Box<RenderOpts>,
    /// Skip overview.png (the last frame beside the same frame at full cost, every pixel
    /// traced, and the sample density with the gaze; the full-cost frame renders the last
    /// 8 frames again without foveation).
    #[arg(long)]
    pub no_overview: bool,
    #[command(flatten)]
    pub device: DeviceArgs,
}

impl RenderCommand {
    pub fn run(self) -> Result<()> {
        self.device.choose_traversal()?;
        let camera = self.opts.look.camera()?;
        let mut args = self.opts.args(
            &camera,
            &self.device,
            RenderDefaults {
                frames: DEFAULT_RENDER_FRAMES,
                gaze: "sim:1",
                out: "out/render",
                scale: DEFAULT_SCALE,
            },
        )?;
        args.overview = !self.no_overview;
        run(&args)
    }
}

impl RenderOpts {
    /// The flags `fovea render`, `view`, `xr` and `replay` share, checked, as the commands read
    /// them.
    pub fn args<'a>(
        &'a self,
        camera: &'a fovea_stage::look::CameraOptions,
        device: &'a DeviceArgs,
        defaults: RenderDefaults,
    ) -> Result<RenderArgs<'a>> {
        Ok(RenderArgs {
            scene: &self.scene,
            method: &self.method,
            width: self.width,
            height: self.height,
            scale: self.scale.unwrap_or(defaults.scale),
            headset: &self.headset,
            gaze: self.gaze.as_deref().unwrap_or(defaults.gaze),
            frames: self.frames.unwrap_or(defaults.frames),
            out: self
                .out
                .as_deref()
                .unwrap_or(std::path::Path::new(defaults.out)),
            exr: self.exr,
            camera_path: fovea_stage::camera_path::CameraMotion::from_flag(
                self.camera_path.as_deref(),
            )?,
            seed: self.seed,
            max_depth: self.max_depth,
            exposure: super::setup::parse_exposure(&self.exposure)?,
            tone: super::setup::parse_tone(&self.tone)?,
            overview: false,
            profile: self.profile()?,
            debug_views: self.debug_views,
            denoiser: &self.denoiser,
            taa: &self.taa,
            device: device.device.as_deref(),
            validation: device.validation,
            eyes: Eyes::parse(&self.eyes)?,
            frames_in_flight: self.frames_in_flight,
            camera,
        })
    }
}
