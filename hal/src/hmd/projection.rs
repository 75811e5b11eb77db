//! Pixel ↔ direction ↔ eccentricity for one eye, through tangent space (hal.md "Pixels ↔ eccentricity").
//!
//! Pixels are Vulkan y-down with pixel centres at +0.5; directions are OpenXR view space (−Z forward).

use super::{EyeView, HmdDescription};
use crate::sample::Eye;
use glam::{Vec2, Vec3};

/// Directions closer than this to the image plane's horizon have no finite pixel.
const MIN_FORWARD: f32 = 1e-6;

impl EyeView {
    fn tangents(&self) -> (f32, f32, f32, f32) {
        let f = &self.fov;
        (
            f.angle_left.tan(),
            f.angle_right.tan(),
            f.angle_down.tan(),
            f.angle_up.tan(),
        )
    }

    /// Unit view-space direction through the centre of pixel `px` (may lie outside the image).
    pub fn pixel_to_direction(&self, px: Vec2) -> Vec3 {
        let (l, r, d, u) = self.tangents();
        let (w, h) = (
            self.recommended_width as f32,
            self.recommended_height as f32,
        );
        let tx = l + (px.x + 0.5) / w * (r - l);
        let ty = u - (px.y + 0.5) / h * (u - d);
        Vec3::new(tx, ty, -1.0).normalize()
    }

    /// Pixel position where `dir` lands, or `None` when `dir` does not point forward (z ≥ 0) or is
    /// not finite. Positions outside the image are returned as is (gaze may leave the display).
    pub fn direction_to_pixel(&self, dir: Vec3) -> Option<Vec2> {
        if !dir.is_finite() || dir.z > -MIN_FORWARD {
            return None;
        }
        let (l, r, d, u) = self.tangents();
        let (w, h) = (
            self.recommended_width as f32,
            self.recommended_height as f32,
        );
        let tx = dir.x / -dir.z;
        let ty = dir.y / -dir.z;
        let px = (tx - l) / (r - l) * w - 0.5;
        let py = (u - ty) / (u - d) * h - 0.5;
        Some(Vec2::new(px, py))
    }

    /// Angle (degrees) between pixel `px`'s direction and the gaze direction.
    pub fn eccentricity_deg(&self, px: Vec2, gaze_dir: Vec3) -> f32 {
        angle_between_deg(
            self.pixel_to_direction(px),
            gaze_dir.normalize_or(Vec3::NEG_Z),
        )
    }

    /// Pixel of the straight-ahead direction (not the image centre when the FOV is asymmetric).
    pub fn forward_pixel(&self) -> Vec2 {
        self.direction_to_pixel(Vec3::NEG_Z).unwrap_or(Vec2::ZERO)
    }
}

/// Angle between two unit vectors in degrees; atan2 form stays accurate for tiny angles.
pub fn angle_between_deg(a: Vec3, b: Vec3) -> f32 {
    a.cross(b).length().atan2(a.dot(b)).to_degrees()
}

impl HmdDescription {
    pub fn pixel_to_direction(&self, eye: Eye, px: Vec2) -> Vec3 {
        self.eye(eye).pixel_to_direction(px)
    }

    pub fn direction_to_pixel(&self, eye: Eye, dir: Vec3) -> Option<Vec2> {
        self.eye(eye).direction_to_pixel(dir)
    }

    pub fn eccentricity_deg(&self, eye: Eye, px: Vec2, gaze_dir: Vec3) -> f32 {
        self.eye(eye).eccentricity_deg(px, gaze_dir)
    }
}
