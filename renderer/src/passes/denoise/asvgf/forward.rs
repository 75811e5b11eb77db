//! A-SVGF forward projection: last frame's brightest sample per 3×3 stratum, carried into this
//! frame's grid, claims the stratum it lands in for the tracer to re-shade; also clears the
//! strata's gradient image the tracer writes.

use crate::error::{Error, Result};
use crate::graph::{
    read_buffer, read_image, read_texels, write_buffer, write_image, FrameRecorder,
};
use crate::layouts::{AsvgfForwardPush, SamplingParams};
use crate::passes::grid::GBuffer;
use crate::passes::push_bytes;
use crate::vk::{Buffer, ComputePipeline, Context, Image};
use glam::UVec4;
use std::sync::Arc;

pub struct ForwardPass {
    pipeline: std::sync::Arc<ComputePipeline>,
}

impl ForwardPass {
    pub fn new(ctx: &Arc<Context>, variant: &str) -> Result<ForwardPass> {
        let shader = format!("passes/denoise/asvgf_forward.{variant}");
        Ok(ForwardPass {
            pipeline: ComputePipeline::shared(
                ctx,
                &shader,
                std::mem::size_of::<AsvgfForwardPush>() as u32,
            )?,
        })
    }

    /// Reads last frame's samples from `g` (before the tracer overwrites it) and the cameras from
    /// `frame_data`; fills `samples` (cleared before) and clears `gradient` (strata-sized).
    /// `project: false` (no usable last frame) only clears.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        g: &GBuffer,
        frame_data: &Buffer,
        samples: &Buffer,
        gradient: &Image,
        space: &SamplingParams,
        table: &Buffer,
        project: bool,
    ) -> Result<()> {
        let visibility = g
            .visibility
            .as_ref()
            .ok_or_else(|| Error::Invalid("A-SVGF needs a G-buffer with visibility".into()))?;
        let binds = [
            read_buffer("frame", frame_data),
            read_image("radiance", &g.radiance),
            read_image("ids", &g.ids),
            read_image("position", &g.position),
            read_image("visibility", visibility),
            write_buffer("gradient_samples", samples),
            write_image("gradient", gradient),
            read_texels("grid_columns", table),
        ];
        let push = AsvgfForwardPush {
            space: *space,
            config: UVec4::new(project as u32, 0, 0, 0),
        };
        rec.dispatch(
            "asvgf_forward",
            &self.pipeline,
            &binds,
            push_bytes(&push),
            [gradient.width, gradient.height, 1],
        )
    }
}
