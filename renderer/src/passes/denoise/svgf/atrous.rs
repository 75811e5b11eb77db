//! One SVGF à-trous iteration: 5×5 B3-spline taps `step` texels apart, edge-stopped by depth,
//! normal and variance-scaled luminance; variance filtered with the squared weights.

use super::settings::SvgfSettings;
use crate::error::Result;
use crate::graph::{read_buffer, read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::{SamplingParams, SvgfAtrousPush};
use crate::passes::grid::{GBuffer, TileList};
use crate::passes::push_bytes;
use crate::vk::{Buffer, ComputePipeline, Context, Image};
use glam::{UVec4, Vec4};
use std::sync::Arc;

pub struct AtrousPass {
    pipeline: std::sync::Arc<ComputePipeline>,
}

impl AtrousPass {
    pub fn new(ctx: &Arc<Context>, variant: &str) -> Result<AtrousPass> {
        let shader = format!("passes/denoise/svgf_atrous.{variant}");
        Ok(AtrousPass {
            pipeline: ComputePipeline::shared(
                ctx,
                &shader,
                std::mem::size_of::<SvgfAtrousPush>() as u32,
            )?,
        })
    }

    /// `src` → `dst` (both colour, variance) in the live tiles, taps `step` texels apart.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        g: &GBuffer,
        src: &Image,
        dst: &Image,
        step: u32,
        space: &SamplingParams,
        table: &Buffer,
        tiles: &TileList,
        s: &SvgfSettings,
    ) -> Result<()> {
        let binds = [
            read_image("src", src),
            read_image("normal_depth", &g.normal_depth),
            read_image("position", &g.position),
            write_image("dst", dst),
            read_texels("grid_columns", table),
            read_buffer("tiles", tiles.buffer),
        ];
        let push = SvgfAtrousPush {
            space: *space,
            params: Vec4::new(s.sigma_luminance, s.sigma_depth, s.sigma_normal, 0.0),
            config: UVec4::new(step, 0, 0, 0),
        };
        rec.dispatch(
            "svgf_atrous",
            &self.pipeline,
            &binds,
            push_bytes(&push),
            tiles.live_threads(),
        )
    }
}
