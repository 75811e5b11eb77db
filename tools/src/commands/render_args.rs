//! The flags every command that renders frames shares (`fovea render`, `view`, `xr`, `replay`,
//! `quality`), as the commands read them.

use super::flags::{LatencyFlags, SceneFlags};
use crate::render_profile::{ProfileOverrides, RenderProfile};
use anyhow::{bail, Result};
use fovea_hal::Eye;
use std::path::{Path, PathBuf};

/// Which eyes a run renders (`--eyes`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Eyes {
    Left,
    Right,
    Both,
}

impl Eyes {
    pub const NAMES: &'static [&'static str] = &["left", "right", "both"];

    pub fn parse(name: &str) -> Result<Eyes> {
        Ok(match name {
            "left" => Eyes::Left,
            "right" => Eyes::Right,
            "both" => Eyes::Both,
            _ => bail!("--eyes {name}: expected one of {}", Eyes::NAMES.join(", ")),
        })
    }

    pub fn list(self) -> &'static [Eye] {
        match self {
            Eyes::Left => &[Eye::Left],
            Eyes::Right => &[Eye::Right],
            Eyes::Both => &[Eye::Left, Eye::Right],
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Eyes::Left => "left",
            Eyes::Right => "right",
            Eyes::Both => "both",
        }
    }
}

#[derive(Clone)]
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
    /// Still, the default orbit, or keyframes (`--camera-path [FILE]`).
    pub camera_path: fovea_stage::camera_path::CameraMotion,
    pub seed: u32,
    pub max_depth: u32,
    /// `--exposure`: automatic (the default) or fixed.
    pub exposure: fovea_renderer::passes::exposure::Exposure,
    /// Write `overview.png` (the last frame, the same frame at full cost, the sample density).
    pub overview: bool,
    /// `--tone`: the display transform.
    pub tone: fovea_renderer::passes::tonemap::ToneCurve,
    /// Visual-Polar parameters, blur and SVGF parameters (profile file + flags, already merged).
    pub profile: RenderProfile,
    /// Per frame: the sampling-grid image and a sample-density heat map; once: density plot.
    pub debug_views: bool,
    /// `auto` (`setup::AUTO`), `none`, `svgf`, `asvgf` or `bmfr` (`DenoiserSettings::NAMES`).
    pub denoiser: &'a str,
    /// `auto`, `off`, `vp` or `screen` (`TaaMode::NAMES`).
    pub taa: &'a str,
    pub device: Option<&'a str>,
    pub validation: bool,
    /// `--eyes`: left (the default, plain frame names), right, or both (one submit per frame).
    pub eyes: Eyes,
    /// Frames kept on the GPU at once (a frame's images are written while later ones render).
    pub frames_in_flight: usize,
    /// `--camera`, `--camera-pos/--camera-look`, `--fov` (the environment is in `profile`).
    pub camera: &'a fovea_stage::look::CameraOptions,
}

#[derive(clap::Args)]
pub struct RenderOpts {
    #[command(flatten)]
    pub look: SceneFlags,
    #[command(flatten)]
    pub latency: LatencyFlags,
    /// Scene name (cornell-box, stress, large; sponza, breakfast-room, flight-helmet from the
    /// shared scene folder, $FOVEA_SCENES or ../shared/data/scenes) or a .gltf/.glb path.
    #[arg(long, default_value = fovea_stage::scenes::DEFAULT_SCENE)]
    pub scene: String,
    /// Sampling method: vp (Visual-Polar, Koskela et al. 2019) or cartesian (uniform, 1 spp).
    #[arg(long, default_value = "vp")]
    pub method: String,
    /// Headset profile: a name from `fovea headsets` or a TOML path.
    #[arg(long, default_value = "fove0")]
    pub headset: String,
    /// Gaze: center | X,Y (render pixels) | sim[:seed] (simulated FOVE 0 eye) | a trace file |
    /// degrees:FILE (t_s,x_deg,y_deg,valid) | gazebase:FILE (render: default sim:1; view: default
    /// the mouse).
    #[arg(long)]
    pub gaze: Option<String>,
    /// Render width (default: the headset's per-eye width × --scale).
    #[arg(long)]
    pub width: Option<u32>,
    /// Render height (default: the headset's per-eye height × --scale).
    #[arg(long)]
    pub height: Option<u32>,
    /// Fraction of the headset's per-eye resolution when --width/--height are not given
    /// (render, view: default 0.25, which keeps the default run near a minute on a CPU driver;
    /// xr: default 1, the runtime's recommended size).
    #[arg(long)]
    pub scale: Option<f32>,
    /// Frames to render (render: default 24; view: default until the window is closed).
    #[arg(long)]
    pub frames: Option<u32>,
    /// Eyes: left (default; files frame_NNNN.png), right, or both (one scene upload, both eyes
    /// in one submit per frame; files frame_NNNN_left.png and frame_NNNN_right.png).
    #[arg(long, default_value = "left")]
    pub eyes: String,
    /// Frames kept on the GPU at once (1 waits for every frame).
    #[arg(long, default_value_t = 2)]
    pub frames_in_flight: usize,
    /// Output folder (created; must hold only fovea's own outputs if it exists; default
    /// out/render, for fovea xr out/xr).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Also write linear EXR frames.
    #[arg(long)]
    pub exr: bool,
    /// Move the camera: without a value along the scene's default path (a slow orbit), with a TOML
    /// file along its keyframes (time, position, look, optional fov; see docs/guide/scenes.md).
    #[arg(long, num_args = 0..=1, default_missing_value = "orbit", value_name = "FILE")]
    pub camera_path: Option<String>,
    #[arg(long, default_value_t = 1)]
    pub seed: u32,
    /// Path vertices: 1 = emission seen directly, 2 = + direct light, 3 = + one indirect bounce.
    #[arg(long, default_value_t = 3)]
    pub max_depth: u32,
    /// Exposure: auto (metered from each frame's radiance with more weight around the gaze,
    /// adapted over time like an eye, one exposure for both eyes), auto+EV / auto-EV (metered,
    /// then compensated by EV stops), or EV (fixed, in stops: 0 displays radiance as it is).
    #[arg(long, default_value = "auto", allow_hyphen_values = true)]
    pub exposure: String,
    /// Display transform: neutral (Khronos PBR Neutral: base colours as authored, highlights
    /// compressed), aces (fitted ACES filmic) or clamp.
    #[arg(long, default_value = "neutral")]
    pub tone: String,
    /// Render profile TOML (Visual-Polar parameters, blur); see config/render/default.toml.
    #[arg(long)]
    pub profile: Option<PathBuf>,
    /// Visual-Polar grid size per axis relative to the screen (default 2/3).
    #[arg(long)]
    pub vp_scale: Option<f32>,
    /// Share of the VP grid removed by the fovea's triangular clip (default 0.12).
    #[arg(long)]
    pub vp_clip: Option<f32>,
    /// Fovea radius in the paper's normalised degrees (default 5.79).
    #[arg(long)]
    pub vp_fovea_deg: Option<f32>,
    /// Sample density ∝ acuity^k (default 1).
    #[arg(long)]
    pub vp_density_exponent: Option<f32>,
    /// Inverse CDF: polynomial (the paper's Eq. 3, default) or exact.
    #[arg(long)]
    pub vp_inverse_cdf: Option<String>,
    /// VP radius: corner (largest gaze-to-corner distance, default) or pixels.
    #[arg(long)]
    pub vp_radius: Option<String>,
    /// VP layout: screen-clipped (the default: each column's rows on its on-screen arcs, so the
    /// budget holds when the eye looks toward a corner), paper (every column's rows on its whole
    /// circle; samples far off the screen are culled) or screen-aware (screen-clipped rows,
    /// columns placed by the on-screen acuity mass).
    #[arg(long)]
    pub vp_layout: Option<String>,
    /// VP eccentricity axis: normalized (the paper's, 80 ↦ farthest corner; default) or headset
    /// (true degrees through the --headset eye's FOV).
    #[arg(long)]
    pub vp_eccentricity: Option<String>,
    /// --method log-polar: L from the farthest corner (Meng et al. 2018, default) or the screen
    /// diagonal (Andersson & Hansson 2020); σ and α from the profile's [log_polar].
    #[arg(long)]
    pub log_polar_extent: Option<String>,
    /// --method composite: Andersson & Hansson 2020's mode, fov|kernel|composite|composite-kernel
    /// (default composite).
    #[arg(long)]
    pub composite_mode: Option<String>,
    /// Foveated blur σ in pixels at 30° for a 1280×1440 eye, scaled with resolution (default 0:
    /// off, the perceptual evaluation's choice; Koskela et al.'s is 6.8).
    #[arg(long)]
    pub blur_sigma: Option<f32>,
    /// Where the foveated blur runs: screen (after the remap, the paper's) | grid (in the VP grid
    /// before the remap, no full-screen blur pass; the paper layout without screen-space TAA).
    #[arg(long)]
    pub blur_space: Option<String>,
    /// Also write per-frame grid images and density heat maps, and a density-vs-eccentricity plot.
    #[arg(long)]
    pub debug_views: bool,
    /// Denoiser in the sampling grid: auto (bmfr where the method's grid runs denoisers, none
    /// where it cannot: the method table's best for Visual-Polar, docs/quality.md) | none | svgf
    /// (Schied et al. 2017) | asvgf (Schied et al. 2018: SVGF with temporal gradients) | bmfr
    /// (Koskela et al. 2019); parameters from the profile's [svgf] / [asvgf] / [bmfr] sections.
    #[arg(long, default_value = "auto")]
    pub denoiser: String,
    /// TAA (Karis 2014) after the denoiser: auto (vp where the method's grid runs it, off where it
    /// cannot) | off | vp (in the sampling grid; the screen for Cartesian) | screen (after the
    /// remap to the screen, neighbourhood sized by the local VP texel footprint; for Cartesian the
    /// same as vp).
    #[arg(long, default_value = "auto")]
    pub taa: String,
}

impl RenderOpts {
    /// The profile file (or the built-in defaults) with the flags applied.
    pub fn profile(&self) -> Result<RenderProfile> {
        let base = match &self.profile {
            Some(path) => RenderProfile::load(path)?,
            None => RenderProfile::default(),
        };
        base.override_with(&ProfileOverrides {
            axis_scale: self.vp_scale,
            clip_fraction: self.vp_clip,
            fovea_deg: self.vp_fovea_deg,
            density_exponent: self.vp_density_exponent,
            inverse_cdf: self.vp_inverse_cdf.clone(),
            radius: self.vp_radius.clone(),
            layout: self.vp_layout.clone(),
            eccentricity: self.vp_eccentricity.clone(),
            log_polar_extent: self.log_polar_extent.clone(),
            composite_mode: self.composite_mode.clone(),
            blur_sigma: self.blur_sigma,
            blur_space: self.blur_space.clone(),
            environment: self.look.environment()?,
            texture_lod: self.look.texture_lod.clone(),
            path_regularisation: self.look.path_regularisation,
            offscreen_samples: self.look.offscreen_samples.clone(),
            resampling: self.look.resampling.clone(),
            stereo_noise: self.look.stereo_noise.clone(),
            cross_eye_reuse: self.look.cross_eye_reuse.clone(),
            gaze_timing: self.latency.timing()?,
        })
    }
}

/// What a command takes when a render flag is not given.
pub struct RenderDefaults {
    pub frames: u32,
    pub gaze: &'static str,
    pub out: &'static str,
    pub scale: f32,
}

/// `--scale` of `fovea render`, `view` and `replay` without the flag.
pub const DEFAULT_SCALE: f32 = 0.25;
