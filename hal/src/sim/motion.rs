//! Geometry helpers for the eye model: angles ↔ directions, slerp, minimum-jerk profile.

use glam::{DVec2, DVec3};

/// View-space direction for azimuth (+ right) and elevation (+ up) in degrees.
pub fn direction_from_angles(azimuth_deg: f64, elevation_deg: f64) -> DVec3 {
    let (az, el) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
    DVec3::new(el.cos() * az.sin(), el.sin(), -el.cos() * az.cos())
}

/// Angle between unit vectors, radians (atan2 form: accurate for tiny angles).
pub fn angle(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// Great-circle interpolation, so angular speed is exactly proportional to ds/dt.
pub fn slerp(a: DVec3, b: DVec3, s: f64) -> DVec3 {
    let theta = angle(a, b);
    if theta < 1e-9 {
        return a.lerp(b, s).normalize();
    }
    let sin = theta.sin();
    a * (((1.0 - s) * theta).sin() / sin) + b * ((s * theta).sin() / sin)
}

/// Minimum-jerk position profile 10τ³ − 15τ⁴ + 6τ⁵; its peak slope is 1.875 at τ = ½.
pub fn min_jerk(tau: f64) -> f64 {
    let t = tau.clamp(0.0, 1.0);
    t * t * t * (10.0 + t * (-15.0 + 6.0 * t))
}

pub const MIN_JERK_PEAK_SLOPE: f64 = 1.875;

/// Right and up unit vectors perpendicular to `d` (view-space +Y keeps "up" meaningful).
pub fn tangent_basis(d: DVec3) -> (DVec3, DVec3) {
    let right = d.cross(DVec3::Y).try_normalize().unwrap_or(DVec3::X);
    (right, right.cross(d))
}

/// `centre` displaced by a small angular offset (degrees, right/up) in its tangent plane.
pub fn offset_direction(centre: DVec3, offset_deg: DVec2) -> DVec3 {
    if offset_deg == DVec2::ZERO {
        return centre;
    }
    let (right, up) = tangent_basis(centre);
    (centre + right * offset_deg.x.to_radians().tan() + up * offset_deg.y.to_radians().tan())
        .normalize()
}

/// A timed great-circle movement with a minimum-jerk profile (saccades).
#[derive(Debug, Clone, Copy)]
pub struct Move {
    pub start: f64,
    pub duration: f64,
    pub from: DVec3,
    pub to: DVec3,
}

impl Move {
    pub fn end(&self) -> f64 {
        self.start + self.duration
    }
    pub fn at(&self, t: f64) -> DVec3 {
        slerp(
            self.from,
            self.to,
            min_jerk((t - self.start) / self.duration),
        )
    }
}

/// A target gliding along a great circle at constant speed (smooth-pursuit stimulus).
#[derive(Debug, Clone, Copy)]
pub struct Glide {
    pub start: f64,
    pub end: f64,
    pub from: DVec3,
    pub to: DVec3,
}

impl Glide {
    pub fn at(&self, t: f64) -> DVec3 {
        let span = self.end - self.start;
        let s = if span > 0.0 {
            ((t - self.start) / span).clamp(0.0, 1.0)
        } else {
            1.0
        };
        slerp(self.from, self.to, s)
    }
    /// Angular speed (rad/s) and rotation axis; `None` when the target does not move.
    pub fn velocity(&self) -> Option<(f64, DVec3)> {
        let span = self.end - self.start;
        let axis = self.from.cross(self.to).try_normalize()?;
        (span > 0.0).then(|| (angle(self.from, self.to) / span, axis))
    }
}
