//! Splat (shaders/passes/splat.comp): a grid whose samples lie anywhere on the screen (random
//! acuity) → a sparse screen image, each pixel the mean of the samples that fell in it, alpha 1
//! where one did. The push-pull fill and the foveated blur take it from there.

use super::fill::FillWayBack;
use super::frame::{ScreenOut, WayBackFrame, WayBackPasses};
use crate::error::Result;
use crate::graph::{
    read_buffer, read_image, read_texels, write_buffer, write_image, FrameRecorder,
};
use crate::layouts::SplatPush;
use crate::passes::push_bytes;
use crate::vk::{Buffer, ComputePipeline, Context, Image};
use ash::vk;
use glam::{UVec2, UVec4};
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

const SCATTER: u32 = 0;
const RESOLVE: u32 = 1;

pub struct SplatPass {
    pipeline: Arc<ComputePipeline>,
    /// Per pixel: fixed-point r, g, b sums and the count (4 × u32).
    sums: Buffer,
    sparse: Image,
}

/// The per-frame inputs the space's mapping reads (the trace's own buffers).
pub struct SplatInputs<'a> {
    pub frame_data: &'a Buffer,
    pub sampling: &'a Buffer,
    pub sampling_table: &'a Buffer,
}

impl SplatPass {
    /// `variant`: the space's kernel (`passes/splat.<variant>`).
    pub fn new(ctx: &Arc<Context>, variant: &str, screen: UVec2) -> Result<SplatPass> {
        let bytes = screen.x as u64 * screen.y as u64 * 16;
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
        Ok(SplatPass {
            pipeline: ComputePipeline::shared(
                ctx,
                &format!("passes/splat.{variant}"),
                std::mem::size_of::<SplatPush>() as u32,
            )?,
            sums: Buffer::new(ctx, "splat.sums", bytes, usage, MemoryLocation::GpuOnly)?,
            sparse: Image::new(
                ctx,
                "splat.sparse",
                screen.x,
                screen.y,
                vk::Format::R32G32B32A32_SFLOAT,
            )?,
        })
    }

    /// Dispatches (and the clear) per frame.
    pub fn passes(&self) -> u32 {
        3
    }

    pub fn record<'a>(
        &'a self,
        rec: &mut FrameRecorder,
        inputs: &SplatInputs,
        grid_color: &'a Image,
    ) -> Result<&'a Image> {
        rec.fill_buffer("splat_clear", &self.sums, 0)?;
        let binds = [
            read_buffer("frame", inputs.frame_data),
            read_buffer("sampling", inputs.sampling),
            read_texels("sampling_table", inputs.sampling_table),
            read_image("grid_color", grid_color),
            write_buffer("sums", &self.sums),
            write_image("sparse", &self.sparse),
        ];
        let push = |mode: u32| SplatPush {
            config: UVec4::new(mode, 0, 0, 0),
        };
        rec.dispatch(
            "splat_scatter",
            &self.pipeline,
            &binds,
            push_bytes(&push(SCATTER)),
            [grid_color.width, grid_color.height, 1],
        )?;
        rec.dispatch(
            "splat_resolve",
            &self.pipeline,
            &binds,
            push_bytes(&push(RESOLVE)),
            [self.sparse.width, self.sparse.height, 1],
        )?;
        Ok(&self.sparse)
    }
}

/// The way back of samples anywhere on the screen (`WayBack::Splat`: random acuity, the packed
/// variable-rate tiles): each splatted to its pixel, then as `FillWayBack`.
pub struct SplatWayBack {
    splat: SplatPass,
    fill: FillWayBack,
}

impl SplatWayBack {
    /// `variant`: the space's trace kernel variant (the splat recomputes each sample's position
    /// with the trace's own mapping).
    pub fn new(ctx: &Arc<Context>, variant: &str, screen: UVec2) -> Result<SplatWayBack> {
        Ok(SplatWayBack {
            splat: SplatPass::new(ctx, variant, screen)?,
            fill: FillWayBack::new(ctx, screen)?,
        })
    }
}

impl WayBackPasses for SplatWayBack {
    fn record<'a>(
        &'a mut self,
        rec: &mut FrameRecorder,
        frame: &WayBackFrame<'a>,
    ) -> Result<ScreenOut<'a>> {
        let inputs = SplatInputs {
            frame_data: frame.grid.frame_data,
            sampling: frame.grid.sampling,
            sampling_table: frame.grid.sampling_table,
        };
        let sparse = self.splat.record(rec, &inputs, frame.radiance)?;
        let screen = self
            .fill
            .fill_and_blur(rec, sparse, frame.space.blur_axis(), frame.blur)?;
        Ok(ScreenOut::Radiance(screen))
    }

    fn extra_passes(&self) -> u32 {
        self.splat.passes() + self.fill.extra_passes()
    }
}
