//! The way back to the screen: from the sampling grid's radiance (after the denoiser and the
//! grid TAA) to the screen's, before the tone mapping. The sampling space chooses it
//! (`SpaceCapabilities::way_back`, a `sampling::WayBack`); `build` makes that choice's passes,
//! once per view, and they record each frame through `WayBackPasses`.
//!
//! One module per way back and the passes it owns: `remap` (the polar grids: φ-mips in
//! `mip_phi`, the remap, screen-space TAA, the foveated blur of `blur` or `blur_grid`), `upscale`,
//! `fill` (push-pull fill and the foveated blur), `splat` (then the fill's way back),
//! `block_fill`; the grid that is the screen needs none.

pub mod block_fill;
pub mod blur;
pub mod blur_grid;
pub mod fill;
mod frame;
pub mod mip_phi;
pub mod remap;
pub mod splat;
pub mod upscale;

pub use frame::{ScreenOut, WayBackFrame, WayBackPasses};

use crate::error::Result;
use crate::graph::FrameRecorder;
use crate::passes::taa::TaaSettings;
use crate::sampling::{SamplingSpace, WayBack};
use crate::vk::Context;
use block_fill::BlockFillWayBack;
use blur::BlurSpace;
use fill::FillWayBack;
use remap::RemapWayBack;
use splat::SplatWayBack;
use std::sync::Arc;
use upscale::UpscaleWayBack;

/// The passes of `space`'s way back. `screen_taa`: TAA after the remap (the remap's only);
/// `blur`: where the remap's foveated blur runs.
pub fn build(
    ctx: &Arc<Context>,
    space: &dyn SamplingSpace,
    screen_taa: Option<TaaSettings>,
    blur: BlurSpace,
) -> Result<Box<dyn WayBackPasses>> {
    let screen = space.screen_size();
    Ok(match space.capabilities().way_back {
        WayBack::Direct => Box::new(Direct),
        WayBack::Remap => Box::new(RemapWayBack::new(ctx, space, screen_taa, blur)?),
        WayBack::Upscale => Box::new(UpscaleWayBack::new(ctx, screen)?),
        WayBack::Fill => Box::new(FillWayBack::new(ctx, screen)?),
        WayBack::Splat => Box::new(SplatWayBack::new(ctx, space.trace_variant(), screen)?),
        WayBack::BlockFill => Box::new(BlockFillWayBack::new(ctx, space.shader_variant(), screen)?),
    })
}

/// The way back of a grid that is the screen (`WayBack::Direct`): none.
struct Direct;

impl WayBackPasses for Direct {
    fn record<'a>(
        &'a mut self,
        _: &mut FrameRecorder,
        frame: &WayBackFrame<'a>,
    ) -> Result<ScreenOut<'a>> {
        Ok(ScreenOut::Radiance(frame.radiance))
    }
}
