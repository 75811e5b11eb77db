//! The light-selection table: every emitter with its power, and a Walker/Vose alias table so the
//! tracer picks an emitter in O(1) with probability proportional to power.
//!
//! Powers (only their ratios matter; they set selection probabilities, not radiance):
//! - emissive triangle: luminance(emissive × mean linear emissive-texture colour) × area × π
//!   (one-sided Lambertian emitter; double-sided ones are not doubled — the ratio error is harmless);
//! - point: 4π · luminance(I);
//! - spot: 2π(1 − cos outer_cone) · luminance(I), the flux inside the outer cone (an upper bound
//!   of the emitted flux, tighter than 4π·lum(I));
//! - directional: luminance(E) · π r², r = radius of the scene's bounding sphere;
//! - environment (a loaded map or the baked sky, `Scene::environment_map`): ∫ luminance(L) dω · π r²
//!   (every direction is a parallel beam of illuminance L dω through the scene's cross-section).
//!
//! Emitters with zero power are left out (they could never be chosen).
//!
//! Sampling on the GPU: with u uniform in [0, 1) and n = entries, `i = floor(u·n)`,
//! `f = u·n − i`; choose `i` if `f < alias[i].threshold`, else `alias[i].alias`; the chosen
//! entry's probability is `alias[chosen].pdf`.

use crate::{PunctualLight, Scene, Texture};
use glam::Vec3;
use std::f32::consts::PI;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightKind {
    EmissiveTriangle,
    Point,
    Spot,
    Directional,
    /// The environment map (index 0); sampled by `environment::EnvironmentDistribution`.
    Environment,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightEntry {
    pub kind: LightKind,
    /// Triangle index for emissive triangles, index into `Scene::punctual_lights` otherwise.
    pub index: u32,
    pub power: f32,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AliasSlot {
    /// Keep this slot's own entry when the fractional part of u·n is below the threshold.
    pub threshold: f32,
    pub alias: u32,
    /// Probability of choosing THIS slot's entry (power / total power).
    pub pdf: f32,
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct LightTable {
    pub entries: Vec<LightEntry>,
    /// One slot per entry.
    pub alias: Vec<AliasSlot>,
    pub total_power: f32,
}

/// Rec. 709 luminance of linear RGB.
pub fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Mean linear RGB of an sRGB-encoded texture (emissive textures are sRGB).
fn mean_linear_colour(texture: &Texture) -> Vec3 {
    let lut: Vec<f32> = (0..256).map(|v| srgb_to_linear(v as f32 / 255.0)).collect();
    let texels = texture.rgba8.chunks_exact(4);
    let count = texels.len().max(1);
    let sum = texels.fold(Vec3::ZERO, |acc, t| {
        acc + Vec3::new(lut[t[0] as usize], lut[t[1] as usize], lut[t[2] as usize])
    });
    sum / count as f32
}

pub fn build_light_table(scene: &Scene) -> LightTable {
    build_light_table_scaled(scene, &[])
}

/// The light table with material i's emission scaled by `emission_scale[i]` (1 beyond the slice;
/// 0 drops its triangles): lights switched or dimmed at run time.
pub fn build_light_table_scaled(scene: &Scene, emission_scale: &[f32]) -> LightTable {
    let mut entries = Vec::new();
    // Mean texture colours are computed once per texture that some emissive material uses.
    let mut texture_means: Vec<Option<Vec3>> = vec![None; scene.textures.len()];
    let material_emission: Vec<Vec3> = scene
        .materials
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let texture_mean = m.emissive_texture.and_then(|t| {
                let texture = scene.textures.get(t as usize)?;
                Some(*texture_means[t as usize].get_or_insert_with(|| mean_linear_colour(texture)))
            });
            m.emissive
                * texture_mean.unwrap_or(Vec3::ONE)
                * emission_scale.get(i).copied().unwrap_or(1.0)
        })
        .collect();
    // Placed ids: an instanced emissive mesh is listed once per instance, in world space.
    for (i, ([a, b, c], tri)) in scene.placed_triangles().enumerate() {
        let emission = material_emission
            .get(tri.material as usize)
            .copied()
            .unwrap_or(Vec3::ZERO);
        let lum = luminance(emission);
        if lum <= 0.0 {
            continue;
        }
        let area = 0.5 * (b - a).cross(c - a).length();
        entries.push(LightEntry {
            kind: LightKind::EmissiveTriangle,
            index: i as u32,
            power: lum * area * PI,
        });
    }
    let scene_radius = scene.bounds().bounding_sphere_radius();
    for (i, light) in scene.punctual_lights.iter().enumerate() {
        let (kind, power) = match *light {
            PunctualLight::Point { intensity, .. } => {
                (LightKind::Point, 4.0 * PI * luminance(intensity))
            }
            PunctualLight::Spot {
                intensity,
                outer_cone,
                ..
            } => (
                LightKind::Spot,
                2.0 * PI * (1.0 - outer_cone.cos()) * luminance(intensity),
            ),
            PunctualLight::Directional { illuminance, .. } => (
                LightKind::Directional,
                luminance(illuminance) * PI * scene_radius * scene_radius,
            ),
        };
        entries.push(LightEntry {
            kind,
            index: i as u32,
            power,
        });
    }
    if let Some(map) = scene.environment_map() {
        let power = map.luminance_integral() * PI * scene_radius * scene_radius;
        entries.push(LightEntry {
            kind: LightKind::Environment,
            index: 0,
            power,
        });
    }
    entries.retain(|e| e.power > 0.0 && e.power.is_finite());
    let powers: Vec<f64> = entries.iter().map(|e| e.power as f64).collect();
    let alias = build_alias_table(&powers);
    let total_power = powers.iter().sum::<f64>() as f32;
    LightTable {
        entries,
        alias,
        total_power,
    }
}

/// Vose's alias method in f64 (exact up to the final rounding to f32).
/// Weights must be non-negative with a positive sum; an empty input gives an empty table.
pub fn build_alias_table(weights: &[f64]) -> Vec<AliasSlot> {
    let n = weights.len();
    let total: f64 = weights.iter().sum();
    if n == 0 || total <= 0.0 {
        return Vec::new();
    }
    let mut scaled: Vec<f64> = weights.iter().map(|w| w * n as f64 / total).collect();
    let mut slots: Vec<AliasSlot> = (0..n)
        .map(|i| AliasSlot {
            threshold: 1.0,
            alias: i as u32,
            pdf: (weights[i] / total) as f32,
        })
        .collect();
    let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| scaled[i] < 1.0);
    while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
        small.pop();
        slots[s].threshold = scaled[s] as f32;
        slots[s].alias = l as u32;
        scaled[l] -= 1.0 - scaled[s];
        if scaled[l] < 1.0 {
            large.pop();
            small.push(l);
        }
    }
    // Whatever remains is 1 up to rounding: those slots always keep their own entry.
    for i in small.into_iter().chain(large) {
        slots[i].threshold = 1.0;
        slots[i].alias = i as u32;
    }
    slots
}

/// Picks an entry with u uniform in [0, 1) — the same arithmetic the shader uses.
pub fn sample_alias(slots: &[AliasSlot], u: f32) -> usize {
    let n = slots.len();
    let scaled = u * n as f32;
    let i = (scaled as usize).min(n - 1);
    if scaled - (i as f32) < slots[i].threshold {
        i
    } else {
        slots[i].alias as usize
    }
}

#[cfg(test)]
#[path = "lights_tests.rs"]
mod tests;
