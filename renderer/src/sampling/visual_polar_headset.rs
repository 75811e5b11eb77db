//! The headset-aware eccentricity axis of the Visual-Polar space (beyond the paper): the
//! paper's ρ axis is a normalised screen distance (80 ↦ r_max); this one is the true angle in
//! degrees between a pixel's view direction and the gaze direction, through the eye's FOV
//! tangents. `visual_polar_math.glsl` mirrors `HeadsetAxis::{eccentricity, distance}` op for op
//! (`vp_headset_eccentricity`, `vp_headset_distance`).
//!
//! Tangent space: the image plane at z = 1; pixel s ↦ T = s ⊙ scale − (left, up) (y down, so the
//! sign flip against the usual up-positive convention changes no angle). Everything is written
//! relative to the gaze: T − G = (s − gaze) ⊙ scale, with G the gaze in tangent space.
//!
//! Inverse (e, φ) → pixel, closed form: the ray leaving the gaze point at pixel angle φ is
//! T(t) = G + t·D, D = (cos φ, sin φ) ⊙ scale, t in pixels. With Ĝ = (G, 1) and D̂ = (D, 0),
//! Ĝ × T̂(t) = t·(Ĝ × D̂) and Ĝ·T̂(t) = |Ĝ|² + t·(G·D), so tan e = t·h / (a + t·b) with a = |Ĝ|²,
//! b = G·D, h = |Ĝ × D̂|; hence t = a·sin e / (h·cos e − b·sin e). Where the denominator is ≤ 0
//! the ray never reaches eccentricity e (the cone lies beyond its horizon): such a sample is far off
//! the screen anyway and is parked at `FAR_PIXELS_PER_SCREEN` screen sizes along its ray.

use glam::{UVec2, Vec2};

/// Degree/radian factors spelled as the GLSL twin spells them (op-for-op agreement).
const DEG_PER_RAD: f32 = 57.295_78;
const RAD_PER_DEG: f32 = 0.017_453_292;

/// How far (in screen sizes, w + h) a sample beyond its ray's horizon is parked: off the screen,
/// finite, and the same on both sides.
pub const FAR_PIXELS_PER_SCREEN: f32 = 4.0;

/// Tangents of the four half-angles of an eye's field of view (positive when the edge lies on its
/// own side of the optical axis, e.g. FOVE 0: 1, 1, 1.127, 1.127). A plain type: the renderer
/// does not know the HMD description; the CLI converts it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FovTangents {
    pub left: f32,
    pub right: f32,
    pub up: f32,
    pub down: f32,
}

impl FovTangents {
    /// From the four edge angles in degrees, OpenXR convention (left and down negative).
    pub fn from_angles_deg(left: f32, right: f32, down: f32, up: f32) -> FovTangents {
        FovTangents {
            left: -left.to_radians().tan(),
            right: right.to_radians().tan(),
            up: up.to_radians().tan(),
            down: -down.to_radians().tan(),
        }
    }

    /// Every tangent finite and each axis spanning a positive width.
    pub fn check(&self) -> Result<(), String> {
        let all = [self.left, self.right, self.up, self.down];
        if !all.iter().all(|t| t.is_finite())
            || self.left + self.right <= 0.0
            || self.up + self.down <= 0.0
        {
            return Err(format!(
                "eccentricity = headset needs finite FOV tangents spanning a positive width and height \
                 (every half-angle below 90°), got left {} right {} up {} down {}",
                self.left, self.right, self.up, self.down
            ));
        }
        Ok(())
    }
}

/// atan on [0, 1] in plain f32 arithmetic, mirrored op for op by `vp_atan_unit` in the GLSL:
/// lavapipe's atan is ~1e-5 relative off, i.e. ~3e-3 texels of ρ at 1280×1440. Reduction by
/// atan z = π/4 + atan((z − 1)/(z + 1)) above tan(π/8), one angle halving (atan w =
/// 2·atan(w / (1 + √(1 + w²))), |v| ≤ tan(π/16)), then the series to v¹³ (truncation < 1e-11).
// 0.785_398_2 is π/4 spelled as the GLSL twin spells it (the point is op-for-op agreement).
#[allow(clippy::approx_constant)]
fn atan_unit(z: f32) -> f32 {
    let (base, w) = if z > 0.414_213_57 {
        (0.785_398_2, (z - 1.0) / (z + 1.0))
    } else {
        (0.0, z)
    };
    let v = w / (1.0 + (1.0 + w * w).sqrt());
    let v2 = v * v;
    let q = (((((-0.076_923_08 * v2 + 0.090_909_09) * v2 - 0.111_111_11) * v2 + 0.142_857_15)
        * v2
        - 0.2)
        * v2
        + 0.333_333_34)
        * v2;
    base + 2.0 * (v - v * q)
}

/// atan2(y, x) for y ≥ 0, in [0, π] (GLSL `vp_angle_of`).
#[allow(clippy::approx_constant)]
fn angle_of(y: f32, x: f32) -> f32 {
    let ax = x.abs();
    let a = if y <= ax {
        atan_unit(if ax > 0.0 { y / ax } else { 0.0 })
    } else {
        1.570_796_4 - atan_unit(ax / y)
    };
    if x < 0.0 {
        3.141_592_7 - a
    } else {
        a
    }
}

/// One gaze's tangent-space geometry on one screen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeadsetAxis {
    /// The gaze in tangent space.
    pub gaze_tan: Vec2,
    /// Tangent units per pixel along x and y.
    pub scale: Vec2,
    /// Largest true eccentricity (degrees) of a screen corner: the ρ axis ends there.
    pub e_max: f32,
    /// Distance (pixels) where samples beyond their ray's horizon are parked.
    pub far: f32,
}

impl HeadsetAxis {
    pub fn new(fov: FovTangents, screen: UVec2, gaze: Vec2) -> HeadsetAxis {
        let size = screen.as_vec2();
        let scale = Vec2::new(
            (fov.left + fov.right) / size.x,
            (fov.up + fov.down) / size.y,
        );
        let gaze_tan = gaze * scale - Vec2::new(fov.left, fov.up);
        let far = FAR_PIXELS_PER_SCREEN * (size.x + size.y);
        let mut axis = HeadsetAxis {
            gaze_tan,
            scale,
            e_max: 0.0,
            far,
        };
        axis.e_max = [
            Vec2::ZERO,
            Vec2::new(size.x, 0.0),
            Vec2::new(0.0, size.y),
            size,
        ]
        .iter()
        .map(|&corner| axis.eccentricity(corner - gaze))
        .fold(0.0, f32::max);
        axis
    }

    /// True eccentricity (degrees) of the pixel at offset `d` (pixels) from the gaze:
    /// atan2(|Ĝ × T̂|, Ĝ·T̂), accurate at small and large angles alike.
    pub fn eccentricity(&self, d: Vec2) -> f32 {
        let g = self.gaze_tan;
        let t = d * self.scale;
        let cx = -t.y;
        let cy = t.x;
        let cz = g.x * t.y - g.y * t.x;
        let cross = (cx * cx + cy * cy + cz * cz).sqrt();
        let dot = g.x * g.x + g.y * g.y + 1.0 + (g.x * t.x + g.y * t.y);
        angle_of(cross, dot) * DEG_PER_RAD
    }

    /// Distance in pixels from the gaze, along unit pixel direction `dir`, of the point at true
    /// eccentricity `e` degrees (the module docs' closed form).
    pub fn distance(&self, e: f32, dir: Vec2) -> f32 {
        let g = self.gaze_tan;
        let dd = dir * self.scale;
        let a = g.x * g.x + g.y * g.y + 1.0;
        let b = g.x * dd.x + g.y * dd.y;
        let hz = g.x * dd.y - g.y * dd.x;
        let h = (dd.x * dd.x + dd.y * dd.y + hz * hz).sqrt();
        let rad = e * RAD_PER_DEG;
        let (s, c) = (rad.sin(), rad.cos());
        let den = h * c - b * s;
        if den > 0.0 {
            (a * s / den).min(self.far)
        } else {
            self.far
        }
    }

    /// Mean pixel distance of eccentricity `e` over 8 directions: a radius for pixel-based code
    /// (the foveated blur, density tools) where the true iso-eccentricity curve is not a circle.
    pub fn mean_distance(&self, e: f32) -> f32 {
        (0..8)
            .map(|i| {
                let a = i as f32 * std::f32::consts::FRAC_PI_4;
                self.distance(e, Vec2::new(a.cos(), a.sin()))
            })
            .sum::<f32>()
            / 8.0
    }
}
