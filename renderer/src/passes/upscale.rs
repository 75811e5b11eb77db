//! A sampling grid coarser than the screen (`UniformBudget`) → the screen: bilinear between the
//! texel centres (shaders/passes/upscale.comp). No parameters: both sizes come from the images.

use crate::error::Result;
use crate::graph::{read_image, write_image, FrameRecorder};
use crate::vk::{ComputePipeline, Context, Image};
use std::sync::Arc;

pub struct UpscalePass {
    pipeline: Arc<ComputePipeline>,
}

impl UpscalePass {
    pub fn new(ctx: &Arc<Context>) -> Result<UpscalePass> {
        Ok(UpscalePass {
            pipeline: ComputePipeline::shared(ctx, "passes/upscale", 0)?,
        })
    }

    pub fn record(&self, rec: &mut FrameRecorder, grid: &Image, screen: &Image) -> Result<()> {
        let binds = [read_image("grid", grid), write_image("screen", screen)];
        rec.dispatch(
            "upscale",
            &self.pipeline,
            &binds,
            &[],
            [screen.width, screen.height, 1],
        )
    }
}
