//! The foveated blur in the Visual-Polar grid (`BlurSpace::Grid`): the screen blur's Gaussian,
//! σ(r) pixels, measured in each grid axis' own texels and applied along φ (within a column) and
//! along ρ (across columns) before the remap, so the way back needs no full-screen blur pass.
//! The paper's layout only (`supports`): a row is one angle in every full column.

use super::blur::BlurShape;
use crate::error::Result;
use crate::graph::{read_image, write_image, FrameRecorder};
use crate::layouts::{GridBlurPush, SamplingParams};
use crate::passes::{push_bytes, VpLayoutPipelines};
use crate::sampling::{VisualPolar, VpLayout};
use crate::vk::{Context, Image};
use ash::vk;
use glam::{UVec2, Vec4};
use std::sync::Arc;

pub struct GridBlurPass {
    along_phi: VpLayoutPipelines,
    along_rho: VpLayoutPipelines,
}

impl GridBlurPass {
    pub fn new(ctx: &Arc<Context>) -> Result<GridBlurPass> {
        let size = std::mem::size_of::<GridBlurPush>() as u32;
        Ok(GridBlurPass {
            along_phi: VpLayoutPipelines::with_prefix(ctx, "passes/blur_grid.phi_", size)?,
            along_rho: VpLayoutPipelines::with_prefix(ctx, "passes/blur_grid.rho_", size)?,
        })
    }

    /// Whether the grid blur can stand in for the screen blur in `vp`: the paper's layout (rows
    /// at one angle across columns) with a radius in pixels (not the headset's degrees).
    pub fn supports(vp: &VisualPolar) -> bool {
        vp.params().layout == VpLayout::Paper && vp.headset().is_none()
    }

    /// `src` → (φ) → `scratch` → (ρ) → `dst`, all of the grid's size.
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        vp: &SamplingParams,
        shape: &BlurShape,
        src: &Image,
        scratch: &Image,
        dst: &Image,
    ) -> Result<()> {
        let push = GridBlurPush {
            space: *vp,
            shape: Vec4::new(
                shape.gaze.x,
                shape.gaze.y,
                shape.fovea_radius,
                shape.sigma_slope,
            ),
        };
        let size = [src.width, src.height, 1];
        let binds = [read_image("src", src), write_image("dst", scratch)];
        rec.dispatch(
            "blur_grid_phi",
            self.along_phi.for_space(vp),
            &binds,
            push_bytes(&push),
            size,
        )?;
        let binds = [read_image("src", scratch), write_image("dst", dst)];
        rec.dispatch(
            "blur_grid_rho",
            self.along_rho.for_space(vp),
            &binds,
            push_bytes(&push),
            size,
        )
    }
}

/// The grid blur's pass and its two grid-sized images.
pub struct GridBlur {
    pass: GridBlurPass,
    scratch: Image,
    blurred: Image,
}

impl GridBlur {
    pub fn new(ctx: &Arc<Context>, grid: UVec2) -> Result<GridBlur> {
        let image =
            |name: &str| Image::new(ctx, name, grid.x, grid.y, vk::Format::R32G32B32A32_SFLOAT);
        Ok(GridBlur {
            pass: GridBlurPass::new(ctx)?,
            scratch: image("grid.blur_scratch")?,
            blurred: image("grid.blurred")?,
        })
    }

    /// Blurs `src` (the grid of `vp`) into the returned image.
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        vp: &SamplingParams,
        shape: &BlurShape,
        src: &Image,
    ) -> Result<&Image> {
        self.pass
            .record(rec, vp, shape, src, &self.scratch, &self.blurred)?;
        Ok(&self.blurred)
    }
}
