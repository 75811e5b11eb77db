//! Visual-Polar image → screen by backward mapping (visual-polar.md §6): bilinear along ρ,
//! wrapped trilinear along φ over the φ-only mips (clamped to the pixel's on-screen arc in the
//! screen-clipped layout).

use super::mip_phi::PhiMips;
use super::{push_bytes, VpLayoutPipelines};
use crate::error::Result;
use crate::graph::{read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::{RemapPush, SamplingParams};
use crate::vk::{Buffer, Context, Image};
use glam::{UVec4, Vec2, Vec4};
use std::sync::Arc;

pub struct RemapPass {
    pipelines: VpLayoutPipelines,
}

impl RemapPass {
    pub fn new(ctx: &Arc<Context>) -> Result<RemapPass> {
        let size = std::mem::size_of::<RemapPush>() as u32;
        Ok(RemapPass {
            pipelines: VpLayoutPipelines::new(ctx, "passes/remap", size)?,
        })
    }

    /// Fills `screen` (screen size) from the mip stack of a VP image; `vp` and `columns` (its
    /// `VisualPolar::column_table`) hold the same space (gaze included) the image was traced with.
    /// `sample_offset`: where the samples sit in their texel minus ½ (a TAA jitter; zero for
    /// samples read as if centred).
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        vp: &SamplingParams,
        columns: &Buffer,
        mips: &PhiMips,
        screen: &Image,
        sample_offset: Vec2,
    ) -> Result<()> {
        let binds = [
            read_image("mips", &mips.image),
            write_image("screen_color", screen),
            read_texels("vp_columns", columns),
        ];
        let push = RemapPush {
            space: *vp,
            config: UVec4::new(mips.levels, 0, 0, 0),
            sample_offset: Vec4::new(sample_offset.x, sample_offset.y, 0.0, 0.0),
        };
        rec.dispatch(
            "remap",
            self.pipelines.for_space(vp),
            &binds,
            push_bytes(&push),
            [screen.width, screen.height, 1],
        )
    }
}
