//! Pixel blocks → the screen (shaders/passes/block_fill.comp): each pixel from its level's
//! units in the atlas — its own pixel in the fovea, bilinear between the four nearest block
//! centres beyond.

use crate::error::Result;
use crate::graph::{read_buffer, read_image, write_image, FrameRecorder};
use crate::vk::{Buffer, ComputePipeline, Context, Image};
use std::sync::Arc;

pub struct BlockFillPass {
    pipeline: Arc<ComputePipeline>,
}

impl BlockFillPass {
    /// `variant`: the space's kernel (`passes/block_fill.<variant>`).
    pub fn new(ctx: &Arc<Context>, variant: &str) -> Result<BlockFillPass> {
        Ok(BlockFillPass {
            pipeline: ComputePipeline::shared(ctx, &format!("passes/block_fill.{variant}"), 0)?,
        })
    }

    /// `grid`: the atlas (each unit's mean colour, alpha 1 where traced); `sampling`: the
    /// space's parameters.
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        sampling: &Buffer,
        grid: &Image,
        screen: &Image,
    ) -> Result<()> {
        let binds = [
            read_buffer("sampling", sampling),
            read_image("grid", grid),
            write_image("screen", screen),
        ];
        rec.dispatch(
            "block_fill",
            &self.pipeline,
            &binds,
            &[],
            [screen.width, screen.height, 1],
        )
    }
}
