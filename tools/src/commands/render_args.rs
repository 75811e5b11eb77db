//! The flags every command that renders frames shares (`fovea render`, `view`, `xr`, `replay`,
//! `quality`), as the commands read them.

use crate::render_profile::RenderProfile;
use anyhow::{bail, Result};
use fovea_hal::Eye;
use std::path::Path;

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
