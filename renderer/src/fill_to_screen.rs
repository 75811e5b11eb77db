//! Back to the screen from the screen's own pixels, not all traced (`WayBack::Fill`: linear
//! falloff): push-pull hole filling, then the foveated blur shaped by the space's eccentricity
//! axis — the blur Koskela et al. 2019 added to every comparator.

use crate::error::Result;
use crate::graph::FrameRecorder;
use crate::passes::blur::BlurPass;
use crate::passes::fill::FillPass;
use crate::sampling::SamplingSpace;
use crate::to_screen::BlurSettings;
use crate::vk::{Context, Image};
use ash::vk;
use glam::UVec2;
use std::sync::Arc;

pub struct FillToScreen {
    fill: FillPass,
    blur: BlurPass,
    scratch: Image,
    blurred: Image,
}

impl FillToScreen {
    pub fn new(ctx: &Arc<Context>, screen: UVec2) -> Result<FillToScreen> {
        let image = |name: &str| Image::new(ctx, name, screen.x, screen.y, vk::Format::R32G32B32A32_SFLOAT);
        Ok(FillToScreen { fill: FillPass::new(ctx, screen)?, blur: BlurPass::new(ctx)?, scratch: image("fill.blur_scratch")?, blurred: image("fill.blurred")? })
    }

    pub fn passes(&self) -> u32 {
        self.fill.passes() + 2
    }

    /// `sparse`: the traced colour (alpha 1 where traced); returns the image to show.
    pub fn record<'a>(&'a self, rec: &mut FrameRecorder, space: &dyn SamplingSpace, sparse: &'a Image, blur: &BlurSettings) -> Result<&'a Image> {
        let filled = self.fill.record(rec, sparse)?;
        match space.blur_axis() {
            Some(axis) if blur.sigma_at_30 > 0.0 => {
                self.blur.record(rec, &blur.shape(axis), filled, &self.scratch, &self.blurred)?;
                Ok(&self.blurred)
            }
            _ => Ok(filled),
        }
    }
}
