//! SVGF variance: temporal where the history is long enough, else a 7×7 edge-stopped spatial
//! estimate from the moments.

use super::settings::SvgfSettings;
use crate::error::Result;
use crate::graph::{read_buffer, read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::{SamplingParams, SvgfVariancePush};
use crate::passes::grid::{GBuffer, TileList};
use crate::passes::push_bytes;
use crate::vk::{Buffer, ComputePipeline, Context, Image};
use glam::Vec4;
use std::sync::Arc;

pub struct VariancePass {
    pipeline: std::sync::Arc<ComputePipeline>,
}

impl VariancePass {
    pub fn new(ctx: &Arc<Context>, variant: &str) -> Result<VariancePass> {
        let shader = format!("passes/denoise/svgf_variance.{variant}");
        Ok(VariancePass {
            pipeline: ComputePipeline::shared(
                ctx,
                &shader,
                std::mem::size_of::<SvgfVariancePush>() as u32,
            )?,
        })
    }

    /// `accum` (colour, temporal variance) and `moments` → `dst` (colour, variance), live tiles.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        g: &GBuffer,
        accum: &Image,
        moments: &Image,
        dst: &Image,
        space: &SamplingParams,
        table: &Buffer,
        tiles: &TileList,
        s: &SvgfSettings,
    ) -> Result<()> {
        let binds = [
            read_image("accum", accum),
            read_image("moments", moments),
            read_image("normal_depth", &g.normal_depth),
            read_image("position", &g.position),
            write_image("dst", dst),
            read_texels("grid_columns", table),
            read_buffer("tiles", tiles.buffer),
        ];
        let push = SvgfVariancePush {
            space: *space,
            params: Vec4::new(
                s.sigma_luminance,
                s.sigma_depth,
                s.sigma_normal,
                s.variance_history as f32,
            ),
        };
        rec.dispatch(
            "svgf_variance",
            &self.pipeline,
            &binds,
            push_bytes(&push),
            tiles.live_threads(),
        )
    }
}
