//! A sampling grid coarser than the screen (`UniformBudget`) → the screen: bilinear between the
//! texel centres (shaders/passes/upscale.comp). No parameters: both sizes come from the images.

use super::frame::{ScreenOut, WayBackFrame, WayBackPasses};
use crate::error::Result;
use crate::graph::{read_image, write_image, FrameRecorder};
use crate::vk::{ComputePipeline, Context, Image};
use ash::vk;
use glam::UVec2;
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

/// The way back of a regular grid coarser than the screen (`WayBack::Upscale`): the upscale
/// into a screen-sized image.
pub struct UpscaleWayBack {
    pass: UpscalePass,
    screen: Image,
}

impl UpscaleWayBack {
    pub fn new(ctx: &Arc<Context>, screen: UVec2) -> Result<UpscaleWayBack> {
        Ok(UpscaleWayBack {
            pass: UpscalePass::new(ctx)?,
            screen: Image::new(
                ctx,
                "upscaled",
                screen.x,
                screen.y,
                vk::Format::R32G32B32A32_SFLOAT,
            )?,
        })
    }
}

impl WayBackPasses for UpscaleWayBack {
    fn record<'a>(
        &'a mut self,
        rec: &mut FrameRecorder,
        frame: &WayBackFrame<'a>,
    ) -> Result<ScreenOut<'a>> {
        self.pass.record(rec, frame.grid, &self.screen)?;
        Ok(ScreenOut::Radiance(&self.screen))
    }
}
