//! φ-only mip chain of a Visual-Polar image (visual-polar.md §6): near the gaze one screen pixel
//! spans many φ rows of a column, so the remap samples trilinearly across levels that halve φ
//! only. Level 0 is the traced image; levels ≥ 1 live stacked in one image (`PhiMips::image`),
//! laid out by `shaders/sampling/phi_mips.glsl`, which `rows_at_level`/`level_offset` mirror.

use super::push_bytes;
use crate::error::Result;
use crate::graph::{read_buffer, read_image, write_image, FrameRecorder};
use crate::layouts::{MipPhiPush, PHI_MIP_LEVELS};
use crate::vk::{Buffer, ComputePipeline, Context, Image};
use ash::vk;
use glam::{UVec2, UVec4};
use std::sync::Arc;

/// φ rows a column with `rows0` traced rows keeps at `level` (halving, rounding up).
pub fn rows_at_level(rows0: u32, level: u32) -> u32 {
    (0..level).fold(rows0, |m, _| m.div_ceil(2))
}

/// First row of `level` (≥ 1) in the stacked mip image of a grid `height` rows tall.
pub fn level_offset(level: u32, height: u32) -> u32 {
    (1..level).map(|l| rows_at_level(height, l)).sum()
}

/// Levels worth building for a grid `height` rows tall (level 0 included): until a full column
/// is down to one row, at most `PHI_MIP_LEVELS`.
pub fn level_count(height: u32) -> u32 {
    let mut levels = 1;
    while levels < PHI_MIP_LEVELS && rows_at_level(height, levels - 1) > 1 {
        levels += 1;
    }
    levels
}

/// The stacked levels ≥ 1 of one VP grid.
pub struct PhiMips {
    pub image: Image,
    pub levels: u32,
}

impl PhiMips {
    pub fn new(ctx: &Arc<Context>, grid: UVec2) -> Result<PhiMips> {
        let levels = level_count(grid.y);
        let height = level_offset(levels, grid.y).max(1);
        Ok(PhiMips { image: Image::new(ctx, "phi_mips", grid.x, height, vk::Format::R32G32B32A32_SFLOAT)?, levels })
    }
}

pub struct MipPhiPass {
    pipeline: ComputePipeline,
}

impl MipPhiPass {
    pub fn new(ctx: &Arc<Context>) -> Result<MipPhiPass> {
        Ok(MipPhiPass { pipeline: ComputePipeline::new(ctx, "passes/mip_phi", std::mem::size_of::<MipPhiPush>() as u32)? })
    }

    /// Builds levels 1.. of `vp_color` (the VP grid described by `sampling`) into `mips`, one
    /// dispatch per level.
    pub fn record(&self, rec: &mut FrameRecorder, sampling: &Buffer, vp_color: &Image, mips: &PhiMips) -> Result<()> {
        for src in 0..mips.levels - 1 {
            let binds = [read_buffer("sampling", sampling), read_image("vp_color", vp_color), write_image("mips", &mips.image)];
            let push = MipPhiPush { config: UVec4::new(src, 0, 0, 0) };
            let rows = rows_at_level(vp_color.height, src + 1);
            rec.dispatch("mip_phi", &self.pipeline, &binds, push_bytes(&push), [vp_color.width, rows, 1])?;
        }
        Ok(())
    }
}
