//! Push-pull hole filling (shaders/passes/fill.comp) of a screen image whose alpha marks the
//! pixels holding a sample: pulled down a pyramid of half-size levels to 1×1, then pushed back up
//! with every level's own samples over the filled level below.

use super::blur::{BlurSettings, FoveatedBlur};
use super::frame::{ScreenOut, WayBackFrame, WayBackPasses};
use crate::error::Result;
use crate::graph::{read_image, write_image, FrameRecorder};
use crate::layouts::FillPush;
use crate::passes::push_bytes;
use crate::sampling::VisualPolar;
use crate::vk::{ComputePipeline, Context, Image};
use ash::vk;
use glam::{UVec2, UVec4};
use std::sync::Arc;

const PULL: u32 = 0;
const PUSH: u32 = 1;

pub struct FillPass {
    pipeline: Arc<ComputePipeline>,
    /// Levels 1.. as pulled (level 0 is the sparse input).
    pulled: Vec<Image>,
    /// Levels 0..n-1 filled; level 0 is the result.
    filled: Vec<Image>,
}

/// Sizes of the levels below `screen` (each half, rounded up) down to 1×1.
pub fn pyramid_levels(screen: UVec2) -> Vec<UVec2> {
    let mut levels = Vec::new();
    let mut size = screen;
    while size.x > 1 || size.y > 1 {
        size = (size + 1) / 2;
        levels.push(size);
    }
    levels
}

impl FillPass {
    pub fn new(ctx: &Arc<Context>, screen: UVec2) -> Result<FillPass> {
        let image =
            |name: &str, s: UVec2| Image::new(ctx, name, s.x, s.y, vk::Format::R32G32B32A32_SFLOAT);
        let levels = pyramid_levels(screen);
        let pulled = levels
            .iter()
            .map(|&s| image("fill.pulled", s))
            .collect::<Result<Vec<_>>>()?;
        let mut filled = vec![image("fill.result", screen)?];
        for &s in levels.iter().take(levels.len().saturating_sub(1)) {
            filled.push(image("fill.filled", s)?);
        }
        Ok(FillPass {
            pipeline: ComputePipeline::shared(
                ctx,
                "passes/fill",
                std::mem::size_of::<FillPush>() as u32,
            )?,
            pulled,
            filled,
        })
    }

    /// Dispatches per frame.
    pub fn passes(&self) -> u32 {
        2 * self.pulled.len() as u32
    }

    /// Fills `sparse` (screen-sized, alpha 1 where a sample lies) into the returned image.
    pub fn record<'a>(&'a self, rec: &mut FrameRecorder, sparse: &'a Image) -> Result<&'a Image> {
        let n = self.pulled.len();
        if n == 0 {
            return Ok(sparse);
        }
        let fine = |l: usize| if l == 0 { sparse } else { &self.pulled[l - 1] };
        for l in 0..n {
            self.dispatch(rec, "fill_pull", PULL, fine(l), fine(l), &self.pulled[l])?;
        }
        for l in (0..n).rev() {
            let coarse = if l + 1 == n {
                &self.pulled[l]
            } else {
                &self.filled[l + 1]
            };
            self.dispatch(rec, "fill_push", PUSH, fine(l), coarse, &self.filled[l])?;
        }
        Ok(&self.filled[0])
    }

    fn dispatch(
        &self,
        rec: &mut FrameRecorder,
        name: &'static str,
        mode: u32,
        fine: &Image,
        coarse: &Image,
        dst: &Image,
    ) -> Result<()> {
        let binds = [
            read_image("fine", fine),
            read_image("coarse", coarse),
            write_image("dst", dst),
        ];
        let push = FillPush {
            config: UVec4::new(mode, 0, 0, 0),
        };
        rec.dispatch(
            name,
            &self.pipeline,
            &binds,
            push_bytes(&push),
            [dst.width, dst.height, 1],
        )
    }
}

/// The way back of the screen's own pixels, not all traced (`WayBack::Fill`: linear falloff):
/// push-pull hole filling, then the foveated blur shaped by the space's eccentricity axis — the
/// blur Koskela et al. 2019 added to every comparator.
pub struct FillWayBack {
    fill: FillPass,
    blur: FoveatedBlur,
}

impl FillWayBack {
    pub fn new(ctx: &Arc<Context>, screen: UVec2) -> Result<FillWayBack> {
        Ok(FillWayBack {
            fill: FillPass::new(ctx, screen)?,
            blur: FoveatedBlur::new(ctx, screen)?,
        })
    }

    /// Fills `sparse` (the traced colour on the screen, alpha 1 where traced) and blurs it
    /// around `axis`; returns the image to show.
    pub fn fill_and_blur<'a>(
        &'a self,
        rec: &mut FrameRecorder,
        sparse: &'a Image,
        axis: Option<&VisualPolar>,
        blur: &BlurSettings,
    ) -> Result<&'a Image> {
        let filled = self.fill.record(rec, sparse)?;
        match axis {
            Some(axis) => self.blur.record(rec, blur, axis, filled),
            None => Ok(filled),
        }
    }
}

impl WayBackPasses for FillWayBack {
    fn record<'a>(
        &'a mut self,
        rec: &mut FrameRecorder,
        frame: &WayBackFrame<'a>,
    ) -> Result<ScreenOut<'a>> {
        let screen =
            self.fill_and_blur(rec, frame.radiance, frame.space.blur_axis(), frame.blur)?;
        Ok(ScreenOut::Radiance(screen))
    }

    /// The pyramid's pulls and pushes and the blur's two axes.
    fn extra_passes(&self) -> u32 {
        self.fill.passes() + 2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pyramid_halves_down_to_one_texel() {
        assert_eq!(
            pyramid_levels(UVec2::new(5, 3)),
            vec![UVec2::new(3, 2), UVec2::new(2, 1), UVec2::new(1, 1)]
        );
        assert!(pyramid_levels(UVec2::new(1, 1)).is_empty());
    }
}
