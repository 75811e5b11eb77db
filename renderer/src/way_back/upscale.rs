//! A sampling grid coarser than the screen (`UniformBudget`) → the screen: bilinear between the
//! texel centres (shaders/passes/upscale.comp). No parameters: both sizes come from the images.

use super::frame::{ScreenOut, WayBackFrame, WayBackPasses};
use crate::error::Result;
use crate::graph::{read_image, write_image, FrameRecorder};
use crate::passes::{Kernel, Pass};
use crate::vk::{Context, Image};
use ash::vk;
use glam::UVec2;
use std::sync::Arc;

pub struct Upscale;

impl Kernel for Upscale {
    const SHADER: &'static str = "passes/upscale";
    type Push = ();
}

pub type UpscalePass = Pass<Upscale>;

impl Pass<Upscale> {
    pub fn record(&self, rec: &mut FrameRecorder, grid: &Image, screen: &Image) -> Result<()> {
        let binds = [read_image("grid", grid), write_image("screen", screen)];
        let size = [screen.width, screen.height, 1];
        self.dispatch(rec, "upscale", &binds, &(), size)
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
            pass: Pass::single(ctx)?,
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
        self.pass.record(rec, frame.radiance, &self.screen)?;
        Ok(ScreenOut::Radiance(&self.screen))
    }
}
