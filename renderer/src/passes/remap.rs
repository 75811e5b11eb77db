//! Visual-Polar image → screen by backward mapping (visual-polar.md §6): bilinear along ρ,
//! wrapped trilinear along φ over the φ-only mips.

use super::mip_phi::PhiMips;
use super::push_bytes;
use crate::error::Result;
use crate::graph::{read_image, write_image, FrameRecorder};
use crate::layouts::{RemapPush, SamplingParams};
use crate::vk::{ComputePipeline, Context, Image};
use glam::UVec4;
use std::sync::Arc;

pub struct RemapPass {
    pipeline: ComputePipeline,
}

impl RemapPass {
    pub fn new(ctx: &Arc<Context>) -> Result<RemapPass> {
        Ok(RemapPass { pipeline: ComputePipeline::new(ctx, "passes/remap", std::mem::size_of::<RemapPush>() as u32)? })
    }

    /// Fills `screen` (screen size) from the mip stack of a VP image; `vp` holds the same VP
    /// parameters (gaze included) the image was traced with.
    pub fn record(&self, rec: &mut FrameRecorder, vp: &SamplingParams, mips: &PhiMips, screen: &Image) -> Result<()> {
        let binds = [read_image("mips", &mips.image), write_image("screen_color", screen)];
        let push = RemapPush {
            vp_grid: vp.grid,
            vp_gaze: vp.gaze,
            vp_shape0: vp.shape0,
            vp_shape1: vp.shape1,
            config: UVec4::new(mips.levels, 0, 0, 0),
        };
        rec.dispatch("remap", &self.pipeline, &binds, push_bytes(&push), [screen.width, screen.height, 1])
    }
}
