//! The environment map on the GPU (`shaders/common/environment.glsl`): one storage buffer of
//! texels, each with its radiance, probability and alias-table slot, and the two `FrameData`
//! slots that describe it. The CPU side (mapping, distribution) is `fovea_scene::environment`.

use crate::error::Result;
use crate::layouts::{EnvTexelGpu, LightGpu, LIGHT_KIND_ENVIRONMENT};
use crate::scene::{EnvironmentDistribution, EnvironmentMap, Scene};
use crate::vk::{Buffer, Context};
use ash::vk;
use glam::{UVec4, Vec4};
use std::sync::Arc;

/// The most texels the shader's slot draw reaches: it scales one 24-bit uniform number.
pub const MAX_GPU_TEXELS: usize = 1 << 24;

pub struct GpuEnvironment {
    /// `EnvTexelGpu` per texel (one black texel when there is no environment: bindings need a buffer).
    pub buffer: Buffer,
    /// Size as uploaded, rotation (radians) and radiance scale; `None`: no environment.
    pub map: Option<(u32, u32, f32, f32)>,
    /// How many times the map was halved to fit one storage buffer and the slot draw.
    pub halvings: u32,
}

impl GpuEnvironment {
    pub fn upload(ctx: &Arc<Context>, scene: &Scene) -> Result<GpuEnvironment> {
        let max_texels = (ctx.info.max_storage_buffer_range as usize
            / std::mem::size_of::<EnvTexelGpu>())
        .min(MAX_GPU_TEXELS);
        let Some(map) = scene.environment_map() else {
            return Self::black(ctx);
        };
        let (map, halvings) = fit(map.into_owned(), max_texels);
        let Some(dist) = EnvironmentDistribution::new(&map) else {
            return Self::black(ctx);
        };
        let buffer = Buffer::device_local(
            ctx,
            "environment",
            &gpu_texels(&map, &dist),
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )?;
        Ok(GpuEnvironment {
            buffer,
            map: Some((map.width, map.height, map.rotation, map.intensity)),
            halvings,
        })
    }

    fn black(ctx: &Arc<Context>) -> Result<GpuEnvironment> {
        let buffer = Buffer::with_data(
            ctx,
            "environment",
            &[EnvTexelGpu::default()],
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )?;
        Ok(GpuEnvironment {
            buffer,
            map: None,
            halvings: 0,
        })
    }

    /// `FrameData.environment` and `.environment_map`; `lights` is the uploaded light table (the
    /// environment's entry gives the probability that light selection picks it).
    pub fn frame_slots(&self, lights: &[LightGpu]) -> (Vec4, UVec4) {
        let Some((width, height, rotation, intensity)) = self.map else {
            return (Vec4::new(1.0, 0.0, 0.0, 0.0), UVec4::ZERO);
        };
        let select = lights
            .iter()
            .find(|l| l.kind_index.x == LIGHT_KIND_ENVIRONMENT)
            .map_or(0.0, |l| l.sampling.y);
        let (sin, cos) = rotation.sin_cos();
        (
            Vec4::new(cos, sin, intensity, select),
            UVec4::new(width, height, 1, 0),
        )
    }
}

/// `map` halved per axis until it has at most `max_texels` texels; returns the halvings.
pub fn fit(mut map: EnvironmentMap, max_texels: usize) -> (EnvironmentMap, u32) {
    let mut halvings = 0;
    while map.texels.len() > max_texels.max(1) && map.texels.len() > 1 {
        map = map.halved();
        halvings += 1;
    }
    (map, halvings)
}

/// The buffer's contents: radiance and probability per texel with its alias slot.
pub fn gpu_texels(map: &EnvironmentMap, dist: &EnvironmentDistribution) -> Vec<EnvTexelGpu> {
    map.texels
        .iter()
        .zip(&dist.alias)
        .map(|(t, slot)| EnvTexelGpu {
            radiance: t.extend(slot.pdf),
            alias: UVec4::new(slot.alias, slot.threshold.to_bits(), 0, 0),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn maps_beyond_the_budget_are_halved_until_they_fit() {
        let map = EnvironmentMap::new(
            64,
            32,
            (0..64 * 32).map(|i| Vec3::splat(i as f32)).collect(),
        )
        .unwrap();
        let (same, none) = fit(map.clone(), 64 * 32);
        assert_eq!((same.width, same.height, none), (64, 32, 0));
        let (small, n) = fit(map.clone(), 100);
        assert_eq!((small.width, small.height, n), (8, 4, 3));
        assert!(
            (small.luminance_integral() - map.luminance_integral()).abs()
                < 1e-3 * map.luminance_integral()
        );
        let dist = EnvironmentDistribution::new(&small).unwrap();
        let texels = gpu_texels(&small, &dist);
        assert_eq!(texels.len(), 32);
        assert_eq!(texels[5].radiance.w, dist.alias[5].pdf);
        assert_eq!(f32::from_bits(texels[5].alias.y), dist.alias[5].threshold);
    }
}
