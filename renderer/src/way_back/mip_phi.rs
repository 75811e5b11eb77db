//! φ-only mip chain of a Visual-Polar image (visual-polar.md §6): near the gaze one screen pixel
//! spans many φ rows of a column, so the remap samples trilinearly across levels that halve φ
//! only. All levels (level 0 = a copy of the traced image) live stacked in one image
//! (`PhiMips::image`), laid out by `shaders/sampling/phi_mips.glsl`, which `rows_at_level` and
//! `level_offset` mirror.

use crate::error::Result;
use crate::graph::{read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::{MipPhiPush, SamplingParams, PHI_MIP_LEVELS};
use crate::passes::{push_bytes, VpLayoutPipelines};
use crate::vk::{Buffer, Context, Image};
use ash::vk;
use glam::{UVec2, UVec4};
use std::sync::Arc;

/// φ rows a column with `rows0` traced rows keeps at `level` (halving, rounding up).
pub fn rows_at_level(rows0: u32, level: u32) -> u32 {
    rows0.div_ceil(1 << level)
}

/// First row of `level` in the stacked mip image of a grid `height` rows tall: blocks of
/// 2^(L−1)-padded height H' halving per level, level l at 2H' − 2H'/2^l.
pub fn level_offset(level: u32, height: u32) -> u32 {
    let padded2 = 2 * height.next_multiple_of(1 << (PHI_MIP_LEVELS - 1));
    padded2 - (padded2 >> level)
}

/// Levels worth building for a grid `height` rows tall (level 0 included): until a full column
/// is down to one row, at most `PHI_MIP_LEVELS`, at least 2 (building level 1 copies level 0).
pub fn level_count(height: u32) -> u32 {
    let mut levels = 2;
    while levels < PHI_MIP_LEVELS && rows_at_level(height, levels - 1) > 1 {
        levels += 1;
    }
    levels
}

/// All φ levels of one VP grid, stacked.
pub struct PhiMips {
    pub image: Image,
    pub levels: u32,
}

impl PhiMips {
    pub fn new(ctx: &Arc<Context>, grid: UVec2) -> Result<PhiMips> {
        let levels = level_count(grid.y);
        let height = level_offset(levels, grid.y);
        Ok(PhiMips {
            image: Image::new(
                ctx,
                "phi_mips",
                grid.x,
                height,
                vk::Format::R32G32B32A32_SFLOAT,
            )?,
            levels,
        })
    }
}

pub struct MipPhiPass {
    pipelines: VpLayoutPipelines,
}

impl MipPhiPass {
    pub fn new(ctx: &Arc<Context>) -> Result<MipPhiPass> {
        let size = std::mem::size_of::<MipPhiPush>() as u32;
        Ok(MipPhiPass {
            pipelines: VpLayoutPipelines::new(ctx, "passes/mip_phi", size)?,
        })
    }

    /// Copies `vp_color` (the VP grid of `vp`) into level 0 of `mips` and builds the levels above
    /// it, one dispatch per level. `columns` holds the space's `VisualPolar::column_table`: in the
    /// screen-clipped layout no level averages across the gap between two on-screen arcs.
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        vp: &SamplingParams,
        columns: &Buffer,
        vp_color: &Image,
        mips: &PhiMips,
    ) -> Result<()> {
        for src in 0..mips.levels - 1 {
            let binds = [
                read_image("vp_color", vp_color),
                write_image("mips", &mips.image),
                read_texels("vp_columns", columns),
            ];
            let push = MipPhiPush {
                space: *vp,
                config: UVec4::new(src, 0, 0, 0),
            };
            let rows = rows_at_level(vp_color.height, src + 1);
            rec.dispatch(
                "mip_phi",
                self.pipelines.for_space(vp),
                &binds,
                push_bytes(&push),
                [vp_color.width, rows, 1],
            )?;
        }
        Ok(())
    }
}
