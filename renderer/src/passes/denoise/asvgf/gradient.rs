//! One iteration of A-SVGF's gradient reconstruction: joint-bilateral à-trous on the strata grid
//! (the first iteration reads the tracer's gradient image, the others the previous iteration).

use super::settings::AsvgfSettings;
use crate::error::Result;
use crate::graph::{read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::{AsvgfGradientPush, SamplingParams};
use crate::passes::grid::GBuffer;
use crate::passes::push_bytes;
use crate::vk::{Buffer, ComputePipeline, Context, Image};
use glam::{UVec4, Vec4};
use std::sync::Arc;

pub struct GradientPass {
    pipeline: std::sync::Arc<ComputePipeline>,
}

impl GradientPass {
    pub fn new(ctx: &Arc<Context>, variant: &str) -> Result<GradientPass> {
        let shader = format!("passes/denoise/asvgf_gradient.{variant}");
        Ok(GradientPass {
            pipeline: ComputePipeline::shared(
                ctx,
                &shader,
                std::mem::size_of::<AsvgfGradientPush>() as u32,
            )?,
        })
    }

    /// `src` → `dst` (strata-sized: δ, max f, confidence), taps `step` strata apart.
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
        s: &AsvgfSettings,
    ) -> Result<()> {
        let binds = [
            read_image("src", src),
            read_image("normal_depth", &g.normal_depth),
            read_image("position", &g.position),
            write_image("dst", dst),
            read_texels("grid_columns", table),
        ];
        let push = AsvgfGradientPush {
            space: *space,
            params: Vec4::new(s.gradient_sigma_depth, s.gradient_sigma_normal, 0.0, 0.0),
            config: UVec4::new(step, 0, 0, 0),
        };
        rec.dispatch(
            "asvgf_gradient",
            &self.pipeline,
            &binds,
            push_bytes(&push),
            [dst.width, dst.height, 1],
        )
    }
}
