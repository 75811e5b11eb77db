//! Environment lighting: an equirectangular radiance map (an HDR file, or the analytic sky baked
//! into one) and the piecewise-constant distribution next-event estimation samples it by.
//!
//! Mapping (the GLSL twin is `shaders/common/environment.glsl`; `tests/environment_map.rs` proves
//! they agree on the device): +Y up; texel column u ∈ [0, 1) left to right is the azimuth
//! φ = 2πu, row v ∈ [0, 1] top to bottom the polar angle θ = πv from +Y, and the map-local
//! direction is (−sin θ sin φ, cos θ, sin θ cos φ): the image centre faces −Z (where a default
//! glTF camera looks) and columns run to the right as seen from inside, so the map is not
//! mirrored. `rotation` turns the map about +Y (counter-clockwise seen from above).
//!
//! Lookups are nearest-texel: radiance is piecewise constant exactly like the sampling
//! distribution, so the pdf the sampler reports is the true one and MIS weights are consistent.

use crate::lights::{build_alias_table, luminance, AliasSlot};
use crate::Sky;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Largest accepted map (columns × rows): 2:1 equirectangular at 8K. The device may still get a
/// halved copy (`fits`), this bound keeps a file's decoded texels within ~400 MB of host memory.
pub const MAX_ENVIRONMENT_SIZE: (u32, u32) = (8192, 4096);
/// Largest radiance a map may give once scaled (a texel's brightest channel × the intensity).
/// Finite values of 1e20 and above give black frames (lavapipe: the estimator's products leave
/// f32); 1e12 still renders (a 32×36 Cornell box under a uniform 1e12 map, every denoiser and TAA
/// mode, 2026-12-07), and no picture needs more: the sun's luminance is 1.6e9 cd/m².
pub const MAX_ENVIRONMENT_RADIANCE: f32 = 1e12;
/// The baked analytic sky: it varies with elevation only, so few columns and many rows
/// (0.35° per row keeps the horizon-to-zenith gradient free of visible bands).
pub const SKY_BAKE_SIZE: (u32, u32) = (32, 512);

/// Linear RGB radiance per texel, row-major from the top row (+Y).
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentMap {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<Vec3>,
    /// Radians about +Y.
    pub rotation: f32,
    /// Radiance scale.
    pub intensity: f32,
}

impl EnvironmentMap {
    /// Checks what a file could get wrong: sizes (non-zero, within [`MAX_ENVIRONMENT_SIZE`], matching
    /// the texel count) and texels (finite, ≥ 0). The error names the first bad texel.
    pub fn new(width: u32, height: u32, texels: Vec<Vec3>) -> Result<EnvironmentMap, String> {
        check_size(width, height)?;
        if texels.len() != width as usize * height as usize {
            return Err(format!(
                "{} texels for a {width}×{height} map",
                texels.len()
            ));
        }
        if let Some(i) = texels
            .iter()
            .position(|t| !(t.is_finite() && t.min_element() >= 0.0))
        {
            let (x, y) = (i as u32 % width, i as u32 / width);
            return Err(format!(
                "texel ({x}, {y}) is {:?}: radiance must be finite and ≥ 0",
                texels[i].to_array()
            ));
        }
        Ok(EnvironmentMap {
            width,
            height,
            texels,
            rotation: 0.0,
            intensity: 1.0,
        })
    }

    /// The brightest texel's largest channel × the intensity must stay within
    /// [`MAX_ENVIRONMENT_RADIANCE`]; the error names the texel, its value and the product.
    pub fn check_radiance(&self) -> Result<(), String> {
        let Some((i, t)) = self
            .texels
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.max_element().total_cmp(&b.1.max_element()))
        else {
            return Ok(());
        };
        let scaled = t.max_element() as f64 * self.intensity as f64;
        if scaled > MAX_ENVIRONMENT_RADIANCE as f64 {
            let (x, y) = (i as u32 % self.width, i as u32 / self.width);
            return Err(format!(
                "texel ({x}, {y}) is {:?}; × intensity {} gives {scaled:e}, beyond the {MAX_ENVIRONMENT_RADIANCE:e} a frame can show (the frame would be black)",
                t.to_array(),
                self.intensity
            ));
        }
        Ok(())
    }

    /// The analytic sky ([`Sky`]) at each texel centre, so the default sky takes the same
    /// importance-sampled path as a loaded map.
    pub fn from_sky(sky: &Sky) -> EnvironmentMap {
        let (width, height) = SKY_BAKE_SIZE;
        let mut texels = Vec::with_capacity((width * height) as usize);
        for y in 0..height {
            let dir = uv_to_direction(Vec2::new(
                0.5 / width as f32,
                (y as f32 + 0.5) / height as f32,
            ));
            // Written as horizon + Δ·t so a uniform sky bakes to exactly its radiance.
            let l = if dir.y < 0.0 {
                sky.ground
            } else {
                sky.horizon + (sky.zenith - sky.horizon) * dir.y.sqrt()
            };
            texels.extend(std::iter::repeat_n(l, width as usize));
        }
        EnvironmentMap {
            width,
            height,
            texels,
            rotation: 0.0,
            intensity: 1.0,
        }
    }

    /// Radiance arriving from world direction `dir` (unit), intensity included.
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        self.texels[self.texel(direction_to_uv(self.to_local(dir)))] * self.intensity
    }

    /// Index of the texel holding `uv`.
    pub fn texel(&self, uv: Vec2) -> usize {
        texel_index(uv, self.width, self.height) as usize
    }

    /// World → map-local direction (the inverse of the map's rotation).
    pub fn to_local(&self, d: Vec3) -> Vec3 {
        let (s, c) = self.rotation.sin_cos();
        Vec3::new(c * d.x - s * d.z, d.y, s * d.x + c * d.z)
    }

    /// Map-local → world direction.
    pub fn to_world(&self, d: Vec3) -> Vec3 {
        let (s, c) = self.rotation.sin_cos();
        Vec3::new(c * d.x + s * d.z, d.y, -s * d.x + c * d.z)
    }

    /// Solid angle of every texel in row `y` (exact: the band between its two polar angles).
    pub fn row_solid_angle(&self, y: u32) -> f32 {
        let (t0, t1) = (
            PI * y as f32 / self.height as f32,
            PI * (y + 1) as f32 / self.height as f32,
        );
        2.0 * PI / self.width as f32 * (t0.cos() - t1.cos())
    }

    /// ∫ luminance(L) dω over the sphere, intensity included: the light table's power is this
    /// times the scene's cross-section (each direction is a parallel beam of illuminance L dω).
    pub fn luminance_integral(&self) -> f32 {
        let w = self.width as usize;
        let sum: f64 = (0..self.height)
            .map(|y| {
                self.texels[y as usize * w..(y as usize + 1) * w]
                    .iter()
                    .map(|t| luminance(*t) as f64)
                    .sum::<f64>()
                    * self.row_solid_angle(y) as f64
            })
            .sum();
        sum as f32 * self.intensity
    }

    /// Half the size per axis, each texel the solid-angle weighted mean of its 2×2 block (exact
    /// for even sizes; odd ones round up, repeating the last row/column, approximately): for maps
    /// larger than one storage buffer (see the renderer's upload).
    pub fn halved(&self) -> EnvironmentMap {
        let (w, h) = (self.width.div_ceil(2), self.height.div_ceil(2));
        let mut texels = Vec::with_capacity((w * h) as usize);
        for y in 0..h {
            for x in 0..w {
                let (mut sum, mut weight) = (Vec3::ZERO, 0.0);
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let (sx, sy) = (
                        (2 * x + dx).min(self.width - 1),
                        (2 * y + dy).min(self.height - 1),
                    );
                    let a = self.row_solid_angle(sy).max(1e-12);
                    sum += self.texels[(sy * self.width + sx) as usize] * a;
                    weight += a;
                }
                texels.push(sum / weight);
            }
        }
        EnvironmentMap {
            width: w,
            height: h,
            texels,
            rotation: self.rotation,
            intensity: self.intensity,
        }
    }
}

/// Zero or beyond [`MAX_ENVIRONMENT_SIZE`] is an error (said before decoding where the format allows).
pub fn check_size(width: u32, height: u32) -> Result<(), String> {
    let (mw, mh) = MAX_ENVIRONMENT_SIZE;
    if width == 0 || height == 0 {
        return Err(format!(
            "the map is {width}×{height}: width and height must be at least 1"
        ));
    }
    if width > mw || height > mh {
        return Err(format!(
            "the map is {width}×{height}, larger than the supported {mw}×{mh}"
        ));
    }
    Ok(())
}

/// Map-local unit direction → (u, v) ∈ [0, 1)×[0, 1].
pub fn direction_to_uv(d: Vec3) -> Vec2 {
    let phi = (-d.x).atan2(d.z);
    let u = phi / (2.0 * PI);
    Vec2::new(
        if u < 0.0 { u + 1.0 } else { u },
        d.y.clamp(-1.0, 1.0).acos() / PI,
    )
}

/// (u, v) → map-local unit direction.
pub fn uv_to_direction(uv: Vec2) -> Vec3 {
    let (phi, theta) = (2.0 * PI * uv.x, PI * uv.y);
    let (st, ct) = theta.sin_cos();
    Vec3::new(-st * phi.sin(), ct, st * phi.cos())
}

/// The texel holding `uv` (clamped at the edges).
pub fn texel_index(uv: Vec2, width: u32, height: u32) -> u32 {
    let x = ((uv.x * width as f32) as u32).min(width - 1);
    let y = ((uv.y * height as f32) as u32).min(height - 1);
    y * width + x
}

/// Texel probabilities ∝ luminance × solid angle (luminance × sin θ per texel, exact per row), as an
/// alias table: the shader picks a texel in O(1), then a uniform point inside it.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentDistribution {
    pub width: u32,
    pub height: u32,
    /// One slot per texel; `pdf` is the texel's probability.
    pub alias: Vec<AliasSlot>,
}

impl EnvironmentDistribution {
    /// `None` for a black map (nothing to sample).
    pub fn new(map: &EnvironmentMap) -> Option<EnvironmentDistribution> {
        let w = map.width as usize;
        let weights: Vec<f64> = map
            .texels
            .iter()
            .enumerate()
            .map(|(i, t)| luminance(*t) as f64 * map.row_solid_angle((i / w) as u32) as f64)
            .collect();
        let alias = build_alias_table(&weights);
        (!alias.is_empty()).then_some(EnvironmentDistribution {
            width: map.width,
            height: map.height,
            alias,
        })
    }

    /// A texel and a point in it from four uniform numbers in [0, 1) (texel slot, alias choice,
    /// position in the texel) — the arithmetic `env_sample` in GLSL uses.
    pub fn sample_uv(&self, u: [f32; 4]) -> (u32, Vec2) {
        let n = self.alias.len();
        let slot = ((u[0] * n as f32) as usize).min(n - 1);
        let i = if u[1] < self.alias[slot].threshold {
            slot
        } else {
            self.alias[slot].alias as usize
        } as u32;
        let (x, y) = (i % self.width, i / self.width);
        (
            i,
            Vec2::new(
                (x as f32 + u[2]) / self.width as f32,
                (y as f32 + u[3]) / self.height as f32,
            ),
        )
    }

    /// Density per unit solid angle of map-local direction `d` (0 where sin θ vanishes).
    pub fn pdf(&self, d: Vec3) -> f32 {
        let uv = direction_to_uv(d);
        let p = self.alias[texel_index(uv, self.width, self.height) as usize].pdf;
        pdf_solid_angle(p, uv.y, self.width, self.height)
    }
}

/// A texel's probability `p` as a density per unit solid angle at polar coordinate `v`:
/// uniform in (u, v) inside the texel, and dω = 2π² sin θ du dv.
pub fn pdf_solid_angle(p: f32, v: f32, width: u32, height: u32) -> f32 {
    let sin_theta = (PI * v).sin();
    if sin_theta <= 1e-7 {
        return 0.0;
    }
    p * (width * height) as f32 / (2.0 * PI * PI * sin_theta)
}

#[cfg(test)]
#[path = "environment_tests.rs"]
mod tests;
