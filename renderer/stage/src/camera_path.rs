//! Camera motion for `--camera-path`: the scene's default path is a slow yaw orbit of the scene
//! camera around the point it looks at (where its view ray passes the scene centre), swinging
//! ±8° over the run, so temporal filters see parallax and disocclusion; `--camera-path FILE`
//! follows keyframes instead (`camera_keys`).

use crate::camera_keys::CameraKeys;
use anyhow::{Context, Result};
use fovea_renderer::frame::CameraPose;
use glam::{Mat4, Vec3};
use std::path::Path;
use std::sync::Arc;

const SWING_DEGREES: f32 = 8.0;

pub fn orbit(start: &CameraPose, scene_centre: Vec3, frame: u32, frames: u32) -> CameraPose {
    let eye = start.world_from_view.w_axis.truncate();
    let forward = -start.world_from_view.z_axis.truncate().normalize();
    let distance = (scene_centre - eye).dot(forward).max(0.1);
    let pivot = eye + forward * distance;
    let phase = frame as f32 / frames.max(1) as f32 * std::f32::consts::TAU;
    let yaw = (SWING_DEGREES.to_radians()) * phase.sin();
    let rotate =
        Mat4::from_translation(pivot) * Mat4::from_rotation_y(yaw) * Mat4::from_translation(-pivot);
    CameraPose {
        world_from_view: rotate * start.world_from_view,
        fov_tan: start.fov_tan,
    }
}

/// How the camera moves over a run (`--camera-path`).
#[derive(Clone, Debug, Default, PartialEq)]
pub enum CameraMotion {
    /// The start pose throughout.
    #[default]
    Still,
    /// The default path (`orbit`), one swing per run.
    Orbit,
    /// Keyframes from a file, frame i at i / refresh rate seconds.
    Keys(Arc<CameraKeys>),
}

impl CameraMotion {
    /// `--camera-path` given without a value means the orbit, with one a keyframe file.
    pub fn from_flag(flag: Option<&str>) -> Result<CameraMotion> {
        Ok(match flag {
            None => CameraMotion::Still,
            Some("orbit") => CameraMotion::Orbit,
            Some(file) => CameraMotion::Keys(Arc::new(
                CameraKeys::load(Path::new(file)).context("--camera-path")?,
            )),
        })
    }

    pub fn moves(&self) -> bool {
        *self != CameraMotion::Still
    }

    /// For report.json: `still`, `orbit` or `keys`.
    pub fn name(&self) -> &'static str {
        match self {
            CameraMotion::Still => "still",
            CameraMotion::Orbit => "orbit",
            CameraMotion::Keys(_) => "keys",
        }
    }
}

/// The camera of frame `frame` of `frames` (shown at frame / `refresh_hz` seconds).
pub fn pose(
    start: &CameraPose,
    scene_centre: Vec3,
    frame: u32,
    frames: u32,
    motion: &CameraMotion,
    refresh_hz: f32,
) -> CameraPose {
    match motion {
        CameraMotion::Still => *start,
        CameraMotion::Orbit => orbit(start, scene_centre, frame, frames),
        CameraMotion::Keys(keys) => keys.pose(frame as f64 / refresh_hz as f64, start),
    }
}
