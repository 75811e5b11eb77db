//! Camera motion for `--camera-path`: the scene's default path is a slow yaw orbit of the scene
//! camera around the point it looks at (where its view ray passes the scene centre), swinging
//! ±8° over the run, so temporal filters see parallax and disocclusion.

use fovea_renderer::pipeline::CameraPose;
use glam::{Mat4, Vec3};

const SWING_DEGREES: f32 = 8.0;

pub fn orbit(start: &CameraPose, scene_centre: Vec3, frame: u32, frames: u32) -> CameraPose {
    let eye = start.world_from_view.w_axis.truncate();
    let forward = -start.world_from_view.z_axis.truncate().normalize();
    let distance = (scene_centre - eye).dot(forward).max(0.1);
    let pivot = eye + forward * distance;
    let phase = frame as f32 / frames.max(1) as f32 * std::f32::consts::TAU;
    let yaw = (SWING_DEGREES.to_radians()) * phase.sin();
    let rotate = Mat4::from_translation(pivot) * Mat4::from_rotation_y(yaw) * Mat4::from_translation(-pivot);
    CameraPose { world_from_view: rotate * start.world_from_view, fov_tan: start.fov_tan }
}

/// The camera of frame `frame` of `frames`: the start pose, or on the default path when `moving`.
pub fn pose(start: &CameraPose, scene_centre: Vec3, frame: u32, frames: u32, moving: bool) -> CameraPose {
    if moving {
        orbit(start, scene_centre, frame, frames)
    } else {
        *start
    }
}
