//! Re-modulation by albedo, the last step of every denoiser that filters demodulated radiance
//! (SVGF, and A-SVGF/BMFR alike): filtered × albedo → radiance for the remap / tonemap.

use crate::error::Result;
use crate::graph::{read_image, write_image, FrameRecorder};
use crate::vk::{ComputePipeline, Context, Image};
use std::sync::Arc;

pub struct ModulatePass {
    pipeline: std::sync::Arc<ComputePipeline>,
}

impl ModulatePass {
    pub fn new(ctx: &Arc<Context>) -> Result<ModulatePass> {
        Ok(ModulatePass {
            pipeline: ComputePipeline::shared(ctx, "passes/denoise/modulate", 0)?,
        })
    }

    /// `pass` names the dispatch in the timing report (e.g. "svgf_modulate").
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        pass: &'static str,
        filtered: &Image,
        albedo: &Image,
        dst: &Image,
    ) -> Result<()> {
        let binds = [
            read_image("filtered", filtered),
            read_image("albedo", albedo),
            write_image("dst", dst),
        ];
        rec.dispatch(
            pass,
            &self.pipeline,
            &binds,
            &[],
            [dst.width, dst.height, 1],
        )
    }
}
