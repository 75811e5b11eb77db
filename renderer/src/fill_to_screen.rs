//! Back to the screen from the screen's own pixels, not all traced (`WayBack::Fill`: linear
//! falloff): push-pull hole filling, then the foveated blur shaped by the space's eccentricity
//! axis — the blur Koskela et al. 2019 added to every comparator.

use crate::error::Result;
use crate::graph::FrameRecorder;
use crate::passes::fill::FillPass;
use crate::sampling::SamplingSpace;
use crate::to_screen::{BlurSettings, FoveatedBlur};
use crate::vk::{Context, Image};
use glam::UVec2;
use std::sync::Arc;

pub struct FillToScreen {
    fill: FillPass,
    blur: FoveatedBlur,
}

impl FillToScreen {
    pub fn new(ctx: &Arc<Context>, screen: UVec2) -> Result<FillToScreen> {
        Ok(FillToScreen {
            fill: FillPass::new(ctx, screen)?,
            blur: FoveatedBlur::new(ctx, screen)?,
        })
    }

    pub fn passes(&self) -> u32 {
        self.fill.passes() + 2
    }

    /// `sparse`: the traced colour (alpha 1 where traced); returns the image to show.
    pub fn record<'a>(
        &'a self,
        rec: &mut FrameRecorder,
        space: &dyn SamplingSpace,
        sparse: &'a Image,
        blur: &BlurSettings,
    ) -> Result<&'a Image> {
        let filled = self.fill.record(rec, sparse)?;
        match space.blur_axis() {
            Some(axis) => self.blur.record(rec, blur, axis, filled),
            None => Ok(filled),
        }
    }
}
