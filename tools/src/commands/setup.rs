//! What `fovea render` and `fovea view` share: the flags checked and turned into render
//! settings, one sampling space per rendered eye, the scene, each eye's camera and the gaze per
//! frame. Both commands build frame `k` with `Setup::frame_input`, so the viewer's frames equal
//! the offline render's (same seeds, cameras and gaze).

pub use super::render_args::Eyes;
use super::render_args::RenderArgs;
use crate::render_profile::RenderProfile;
use anyhow::{bail, Context, Result};
use fovea_hal::{Eye, EyeView, HmdDescription};
use fovea_renderer::frame::{CameraPose, FrameInput, RenderSettings, ViewInput};
use fovea_renderer::passes::denoise::DenoiserSettings;
use fovea_renderer::passes::exposure::{AutoExposure, Exposure};
use fovea_renderer::passes::taa::TaaMode;
use fovea_renderer::passes::tonemap::ToneCurve;
use fovea_renderer::sampling::SamplingSpace;
use fovea_renderer::scene::Scene;
use fovea_stage::camera_path;
use fovea_stage::gaze::{FrameGaze, GazeDriver};
use fovea_stage::projection::EyeRig;
use glam::{UVec2, Vec3};

pub use super::methods::{method, names as method_names};
use super::methods::{ScreenNeeds, SpaceInputs};

pub struct Setup {
    pub hmd: HmdDescription,
    pub width: u32,
    pub height: u32,
    pub eyes: Eyes,
    pub settings: RenderSettings,
    pub denoiser: DenoiserSettings,
    pub taa: TaaMode,
    pub scene: Scene,
    pub gaze: GazeDriver,
    /// The scene camera fitted to the render size (the head; each eye is offset from it).
    pub start_pose: CameraPose,
    /// Turns the head into each eye's camera (`--projection`).
    pub rig: EyeRig,
    pub scene_centre: Vec3,
    frames: u32,
    camera_path: camera_path::CameraMotion,
}

impl Setup {
    /// Checks the flags and loads what the run needs. `frames`: the run's length (the camera
    /// path's period).
    pub fn new(args: &RenderArgs, frames: u32) -> Result<Setup> {
        let hmd = HmdDescription::resolve(args.headset)
            .with_context(|| format!("--headset {}", args.headset))?;
        check_common(args)?;
        let (scaled_width, scaled_height) = scaled_eye_size(hmd.eye(Eye::Left), args.scale);
        let width = args.width.unwrap_or(scaled_width);
        let height = args.height.unwrap_or(scaled_height);
        if width == 0 || height == 0 || frames == 0 {
            bail!("--width, --height and --frames must be at least 1");
        }
        // Before the device is opened; `space_for` checks again for the viewer's method switch.
        check_space(args.method, &args.profile, UVec2::new(width, height))?;
        let (denoiser, taa) =
            filters_for_method(args.denoiser, args.taa, args.method, &args.profile, &hmd)?;
        let timing = &args.profile.gaze_timing;
        let gaze = GazeDriver::open_timed(args.gaze, &hmd, width, height, timing)?;
        let rig = EyeRig {
            projection: args.camera.projection,
            hmd: hmd.clone(),
            stereo: args.eyes == Eyes::Both,
            width,
            height,
            metres_per_unit: args.camera.world_scale,
        };
        let (scene, camera) = fovea_stage::look::load(
            args.scene,
            args.camera,
            &args.profile.environment,
            rig.framing(),
        )?;
        let start_pose = rig.head(&camera);
        let settings = render_settings(args, denoiser, taa);
        Ok(Setup {
            scene_centre: scene.bounds().center(),
            eyes: args.eyes,
            hmd,
            width,
            height,
            settings,
            denoiser,
            taa,
            scene,
            gaze,
            start_pose,
            rig,
            frames,
            camera_path: args.camera_path.clone(),
        })
    }

    pub fn screen(&self) -> UVec2 {
        UVec2::new(self.width, self.height)
    }

    /// One sampling space per rendered eye, centred on the screen until the first gaze.
    pub fn spaces(
        &self,
        method: &str,
        profile: &RenderProfile,
    ) -> Result<Vec<Box<dyn SamplingSpace>>> {
        self.eyes
            .list()
            .iter()
            .map(|&eye| space_for(method, profile, &self.hmd, eye, self.screen()))
            .collect()
    }

    /// Frame `frame`'s input: each eye's camera (the head pose on the camera path, offset by the
    /// eye's position) and gaze (the combined gaze direction projected into that eye).
    pub fn frame_input(&mut self, frame: u32) -> Result<(FrameInput, FrameGaze)> {
        self.frame_input_from(frame, None)
    }

    /// As `frame_input`, the head at `head` instead of on the camera path when given (the
    /// viewer's free camera).
    pub fn frame_input_from(
        &mut self,
        frame: u32,
        head: Option<CameraPose>,
    ) -> Result<(FrameInput, FrameGaze)> {
        let gaze = self.gaze.frame(frame, self.eyes.list())?;
        let head = head.unwrap_or_else(|| {
            camera_path::pose(
                &self.start_pose,
                self.scene_centre,
                frame,
                self.frames,
                &self.camera_path,
                self.hmd.refresh_hz,
            )
        });
        let mut views = [ViewInput {
            camera: head,
            gaze: None,
        }; 2];
        let eyes = self.eyes.list();
        for (view, &eye) in views.iter_mut().zip(eyes) {
            *view = ViewInput {
                camera: self.rig.eye(&head, eye),
                gaze: Some(gaze.pixels[eye.index()]),
            };
        }
        let mut input = FrameInput::views(&views[..eyes.len()], frame)?;
        // Frames follow each other at the headset's refresh (the camera path's clock too).
        input.frame_seconds = 1.0 / self.hmd.refresh_hz;
        Ok((input, gaze))
    }
}

/// The longest path `--max-depth` takes (vertices). There is no Russian roulette and a path in a
/// closed room never escapes, so each vertex costs another trace of the whole frame: a huge value
/// never finishes a frame (and trips a GPU watchdog). 64 is 20× the real-time default of 3.
pub const MAX_DEPTH_LIMIT: u32 = 64;
/// `--exposure` range in stops: ±13 (multipliers 10⁻⁴ to 10⁴). Beyond it the tonemapped frame is
/// all black or blown out.
pub const EXPOSURE_STOPS: f32 = 13.0;
/// The smallest Visual-Polar screen and grid per axis: one grid column would put every sample on
/// one ring around the gaze (all of the screen at one eccentricity), one row every sample on one
/// ray from it, either a flat, meaningless frame; a screen one pixel across has no periphery on
/// that axis to foveate. With the default --vp-scale (2/3) the grid rule needs a 3×3 screen.
pub const MIN_VP_GRID: u32 = 2;
/// `--vp-radius PIXELS` at most this many screen diagonals: beyond it the whole screen lies inside
/// the first 8° of the 80° axis (mostly the fovea) and most samples land off the screen.
pub const MAX_VP_RADIUS_DIAGONALS: f32 = 10.0;

/// `--max-depth` and `--exposure` (`fovea render`, `view` and `xr`).
pub fn check_settings(max_depth: u32, exposure: &Exposure) -> Result<()> {
    if !(1..=MAX_DEPTH_LIMIT).contains(&max_depth) {
        bail!("--max-depth {max_depth} must be in 1..={MAX_DEPTH_LIMIT} (path vertices: 1 = emission seen directly)");
    }
    let within = |stops: f32| stops.is_finite() && stops.abs() <= EXPOSURE_STOPS;
    match exposure {
        Exposure::Manual(m) if !(*m > 0.0 && within(m.log2())) => {
            bail!("--exposure: a multiplier of {m:?} is outside ±{EXPOSURE_STOPS} stops (the frame would be all black or blown out)")
        }
        Exposure::Auto(a) if !within(a.compensation_ev) => bail!(
            "--exposure auto{:+}: the compensation must be within ±{EXPOSURE_STOPS} stops",
            a.compensation_ev
        ),
        Exposure::Auto(a) => a.validate().context("--exposure")?,
        Exposure::Manual(_) => {}
    }
    Ok(())
}

/// `--exposure`: `auto` (metered from every frame, adapted over time), `auto+EV` / `auto-EV`
/// (metered, then EV stops brighter or darker), or a fixed exposure of EV stops (0: radiance
/// displayed as it is; each stop doubles it).
pub fn parse_exposure(text: &str) -> Result<Exposure> {
    let stops = |s: &str| -> Result<f32> {
        let ev: f32 = s.trim().parse().map_err(|_| {
            anyhow::anyhow!(
                "--exposure {text:?}: expected auto, auto+EV, auto-EV or EV (stops, a number)"
            )
        })?;
        if !(ev.is_finite() && ev.abs() <= EXPOSURE_STOPS) {
            bail!(
                "--exposure {text:?}: EV must be a finite number of stops within ±{EXPOSURE_STOPS}"
            );
        }
        Ok(ev)
    };
    let exposure = match text.trim().strip_prefix("auto") {
        Some("") => Exposure::auto(),
        Some(rest) if rest.starts_with(['+', '-']) => Exposure::Auto(AutoExposure {
            compensation_ev: stops(rest)?,
            ..AutoExposure::default()
        }),
        Some(_) => bail!("--exposure {text:?}: expected auto, auto+EV, auto-EV or EV (stops)"),
        None => Exposure::stops(stops(text)?),
    };
    Ok(exposure)
}

/// `--tone`: the display transform's name (`ToneCurve::NAMES`).
pub fn parse_tone(text: &str) -> Result<ToneCurve> {
    ToneCurve::from_name(text).ok_or_else(|| {
        anyhow::anyhow!(
            "--tone {text:?}: expected one of {}",
            ToneCurve::NAMES.join(", ")
        )
    })
}

/// What the Visual-Polar mapping needs of the screen `method` renders: a screen and a grid of at
/// least `MIN_VP_GRID` texels per axis and a fixed radius within `MAX_VP_RADIUS_DIAGONALS`
/// diagonals. Cartesian takes any size from 1×1.
pub fn check_space(method_name: &str, profile: &RenderProfile, screen: UVec2) -> Result<()> {
    match method(method_name)?.screen {
        ScreenNeeds::Any => return Ok(()),
        ScreenNeeds::LogPolarBuffer => return check_log_polar(profile, screen),
        ScreenNeeds::CompositeDisc if screen.x < 16 || screen.y < 16 => {
            bail!("--method {method_name}: a {}×{} screen is too small for a gaze disc and a log-polar buffer (at least 16×16)", screen.x, screen.y)
        }
        ScreenNeeds::CompositeDisc => return Ok(()),
        // VP, and the methods sized by its sample count or placed on its eccentricity axis.
        ScreenNeeds::VisualPolarGrid => {}
    }
    if screen.x < MIN_VP_GRID || screen.y < MIN_VP_GRID {
        bail!(
            "--method vp: a {}×{} screen has no periphery to foveate; Visual-Polar needs at least {MIN_VP_GRID}×{MIN_VP_GRID} pixels \
             (raise --width/--height or --scale, or use --method cartesian)",
            screen.x,
            screen.y
        );
    }
    let p = &profile.visual_polar;
    // As `VisualPolar::new` rounds it.
    let grid = (screen.as_vec2() * p.axis_scale).round().as_uvec2();
    if grid.x < MIN_VP_GRID || grid.y < MIN_VP_GRID {
        let min = (MIN_VP_GRID as f32 - 0.5) / p.axis_scale;
        bail!(
            "--method vp: a {}×{} screen at --vp-scale {} gives a {}×{} Visual-Polar grid; it needs at least {MIN_VP_GRID}×{MIN_VP_GRID} \
             (a screen of at least {}×{} at this --vp-scale): raise --width/--height (or --scale), raise --vp-scale, or use --method cartesian",
            screen.x,
            screen.y,
            p.axis_scale,
            grid.x,
            grid.y,
            min.ceil(),
            min.ceil()
        );
    }
    if let fovea_renderer::sampling::RadiusMode::Fixed(r) = p.radius_mode {
        let limit = MAX_VP_RADIUS_DIAGONALS * screen.as_vec2().length();
        if r > limit {
            bail!(
                "--vp-radius (or the profile's visual_polar.radius) {r} px: at most {MAX_VP_RADIUS_DIAGONALS} × the {}×{} screen's diagonal ({limit:.0} px); \
                 a larger radius puts the whole screen in the fovea and most samples off the screen",
                screen.x,
                screen.y
            );
        }
    }
    Ok(())
}

/// `--method log-polar` needs a buffer (screen / σ) of at least `MIN_VP_GRID` texels per axis.
fn check_log_polar(profile: &RenderProfile, screen: UVec2) -> Result<()> {
    let sigma = profile.log_polar.sigma;
    // As `VisualPolar::new` rounds it.
    let grid = (screen.as_vec2() / sigma).round().as_uvec2();
    if grid.x < MIN_VP_GRID || grid.y < MIN_VP_GRID {
        bail!(
            "--method log-polar: a {}×{} screen at [log_polar] sigma {sigma} gives a {}×{} buffer; it needs at least {MIN_VP_GRID}×{MIN_VP_GRID} \
             (raise --width/--height or --scale, lower sigma, or use --method cartesian)",
            screen.x,
            screen.y,
            grid.x,
            grid.y
        );
    }
    Ok(())
}

/// The checks every command that renders frames makes of `--scale`, `--method`, `--max-depth`
/// and `--exposure` (render, view and xr).
pub fn check_common(args: &RenderArgs) -> Result<()> {
    if !(args.scale > 0.0 && args.scale <= 4.0) {
        bail!("--scale {} must be in (0, 4]", args.scale);
    }
    if !(1..=MAX_FRAMES_IN_FLIGHT).contains(&args.frames_in_flight) {
        bail!(
            "--frames-in-flight {} must be in 1..={MAX_FRAMES_IN_FLIGHT} (each frame in flight holds its own images and read-back buffers)",
            args.frames_in_flight
        );
    }
    for (flag, side) in [("--width", args.width), ("--height", args.height)] {
        if let Some(side) = side.filter(|&s| s > MAX_RENDER_SIDE) {
            bail!("{flag} {side} must be at most {MAX_RENDER_SIDE} pixels (the largest image side Vulkan devices promise)");
        }
    }
    method(args.method)?;
    check_settings(args.max_depth, &args.exposure)
}

/// Most frames kept on the GPU at once (`--frames-in-flight`); a run of fewer frames keeps that
/// many. Past three the CPU only waits longer for the first image.
pub const MAX_FRAMES_IN_FLIGHT: usize = 8;
/// The largest `--width` / `--height` (also `fovea reference`): the `maxImageDimension2D` every
/// desktop Vulkan device offers.
pub const MAX_RENDER_SIDE: u32 = 16384;

/// Frames in flight for a run of `frames` frames: `--frames-in-flight` (checked by
/// [`check_common`]), never more than the frames rendered.
pub fn frames_in_flight(requested: usize, frames: u32) -> usize {
    requested
        .clamp(1, MAX_FRAMES_IN_FLIGHT)
        .min(frames.max(1) as usize)
}

/// A headset eye's recommended size × `--scale`, at least one pixel per axis.
pub fn scaled_eye_size(eye: &EyeView, scale: f32) -> (u32, u32) {
    let axis = |n: u32| ((n as f32 * scale).round() as u32).max(1);
    (axis(eye.recommended_width), axis(eye.recommended_height))
}

/// The engine settings the render flags give, with the filters already chosen (`filters`).
pub fn render_settings(
    args: &RenderArgs,
    denoiser: DenoiserSettings,
    taa: TaaMode,
) -> RenderSettings {
    RenderSettings {
        max_depth: args.max_depth,
        seed: args.seed,
        exposure: args.exposure,
        tone_curve: args.tone,
        blur: args.profile.blur,
        denoiser,
        taa,
        texture_lod: args.profile.texture_lod,
        path_regularisation: args.profile.path_regularisation(),
        offscreen_samples: args.profile.offscreen_samples,
        resampling: args.profile.resampling,
        stereo_noise: args.profile.stereo_noise,
        surface_cell: args.profile.surface_cell(),
        cross_eye_reuse: args.profile.cross_eye_reuse,
        ..Default::default()
    }
}

/// `--denoiser` and `--taa` with their parameters from the profile (`fovea render`, `fovea view`'s
/// live switching and `fovea xr` share it); whether the method's space runs them is checked by
/// the renderer.
pub fn filters(
    denoiser: &str,
    taa: &str,
    profile: &RenderProfile,
) -> Result<(DenoiserSettings, TaaMode)> {
    let denoiser_settings = profile.denoisers.get(denoiser).context("--denoiser")?;
    let taa_mode = TaaMode::parse(taa)
        .context("--taa")?
        .with_settings(profile.taa);
    Ok((denoiser_settings, taa_mode))
}

/// `--denoiser auto` / `--taa auto` (the defaults): what the method table shows best for
/// Visual-Polar (docs/quality.md: BMFR with TAA in the sampling grid), where the method's grid
/// runs temporal filters; none and off where it cannot.
pub const AUTO: &str = "auto";
pub const AUTO_DENOISER: &str = "bmfr";
pub const AUTO_TAA: &str = "vp";

/// `filters` with `auto` resolved for `method` (see `AUTO`).
pub fn filters_for_method(
    denoiser: &str,
    taa: &str,
    method_name: &str,
    profile: &RenderProfile,
    hmd: &HmdDescription,
) -> Result<(DenoiserSettings, TaaMode)> {
    let runs_filters = || -> Result<bool> {
        // The capabilities do not depend on the size: a small probe screen.
        let probe = space_for(method_name, profile, hmd, Eye::Left, UVec2::new(64, 72))?;
        Ok(probe.capabilities().temporal_filters)
    };
    let auto = (denoiser == AUTO || taa == AUTO) && runs_filters()?;
    let pick = |given: &'static str, off: &'static str| if auto { given } else { off };
    let denoiser = match denoiser {
        AUTO => pick(AUTO_DENOISER, "none"),
        name => name,
    };
    let taa = match taa {
        AUTO => pick(AUTO_TAA, "off"),
        name => name,
    };
    filters(denoiser, taa, profile)
}

/// The sampling space of `method_name` for one eye of `hmd` (its FOV drives the headset ρ axis).
pub fn space_for(
    method_name: &str,
    profile: &RenderProfile,
    hmd: &HmdDescription,
    eye: Eye,
    screen: UVec2,
) -> Result<Box<dyn SamplingSpace>> {
    check_space(method_name, profile, screen)?;
    let fov = crate::render_profile::fov_tangents(&hmd.eye(eye).fov);
    let vp = profile
        .visual_polar_for(fov)
        .with_context(|| format!("--headset {}", hmd.id))?;
    method(method_name)?.space(&SpaceInputs {
        profile,
        hmd,
        fov,
        vp,
        screen,
    })
}

/// The eye's name in file names and reports.
pub fn eye_name(eye: Eye) -> &'static str {
    match eye {
        Eye::Left => "left",
        Eye::Right => "right",
    }
}
