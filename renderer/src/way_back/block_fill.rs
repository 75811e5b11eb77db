//! Pixel blocks → the screen (shaders/passes/block_fill.comp): each pixel from its level's
//! units in the atlas — its own pixel in the fovea, bilinear between the four nearest block
//! centres beyond.

use super::frame::{ScreenOut, WayBackFrame, WayBackPasses};
use crate::error::Result;
use crate::graph::{read_buffer, read_image, write_image, FrameRecorder};
use crate::passes::{Kernel, Pass};
use crate::vk::{Buffer, Context, Image};
use ash::vk;
use glam::UVec2;
use std::sync::Arc;

pub struct BlockFill;

impl Kernel for BlockFill {
    const SHADER: &'static str = "passes/block_fill";
    type Push = ();
}

/// The block fill, made for a space's kernel variant (`BlockFillPass::new(ctx, variant)`).
pub type BlockFillPass = Pass<BlockFill>;

impl Pass<BlockFill> {
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
        let size = [screen.width, screen.height, 1];
        self.dispatch(rec, "block_fill", &binds, &(), size)
    }
}

/// The way back of an atlas of pixel blocks (`WayBack::BlockFill`): the block fill into a
/// screen-sized image, no blur.
pub struct BlockFillWayBack {
    pass: BlockFillPass,
    screen: Image,
}

impl BlockFillWayBack {
    /// `variant`: the space's kernel variant.
    pub fn new(ctx: &Arc<Context>, variant: &str, screen: UVec2) -> Result<BlockFillWayBack> {
        Ok(BlockFillWayBack {
            pass: Pass::new(ctx, variant)?,
            screen: Image::new(
                ctx,
                "block_filled",
                screen.x,
                screen.y,
                vk::Format::R32G32B32A32_SFLOAT,
            )?,
        })
    }
}

impl WayBackPasses for BlockFillWayBack {
    fn record<'a>(
        &'a mut self,
        rec: &mut FrameRecorder,
        frame: &WayBackFrame<'a>,
    ) -> Result<ScreenOut<'a>> {
        self.pass
            .record(rec, frame.grid.sampling, frame.radiance, &self.screen)?;
        Ok(ScreenOut::Radiance(&self.screen))
    }
}
