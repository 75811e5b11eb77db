//! Running mean of traced colour over many samples (reference renders).

use super::push_bytes;
use crate::error::Result;
use crate::graph::{read_image, write_image, FrameRecorder};
use crate::layouts::AccumulatePush;
use crate::vk::{ComputePipeline, Context, Image};
use glam::UVec4;
use std::sync::Arc;

pub struct AccumulatePass {
    pipeline: std::sync::Arc<ComputePipeline>,
}

impl AccumulatePass {
    pub fn new(ctx: &Arc<Context>) -> Result<AccumulatePass> {
        Ok(AccumulatePass {
            pipeline: ComputePipeline::shared(
                ctx,
                "passes/accumulate",
                std::mem::size_of::<AccumulatePush>() as u32,
            )?,
        })
    }

    /// Blends `sample` into `accum`, which already holds the mean of `samples_so_far` samples.
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        sample: &Image,
        accum: &Image,
        samples_so_far: u32,
    ) -> Result<()> {
        self.dispatch(rec, sample, accum, samples_so_far, false)
    }

    /// As `record`, but texels whose sample was not traced (alpha 0) keep their mean: the mean
    /// of a space whose texels trace different sample counts (`samples_so_far` = the sample
    /// index, which every still-traced texel has had).
    pub fn record_traced(
        &self,
        rec: &mut FrameRecorder,
        sample: &Image,
        accum: &Image,
        samples_so_far: u32,
    ) -> Result<()> {
        self.dispatch(rec, sample, accum, samples_so_far, true)
    }

    fn dispatch(
        &self,
        rec: &mut FrameRecorder,
        sample: &Image,
        accum: &Image,
        samples_so_far: u32,
        traced_only: bool,
    ) -> Result<()> {
        let binds = [
            read_image("sample_color", sample),
            write_image("accum", accum),
        ];
        let push = AccumulatePush {
            config: UVec4::new(samples_so_far, traced_only as u32, 0, 0),
        };
        rec.dispatch(
            "accumulate",
            &self.pipeline,
            &binds,
            push_bytes(&push),
            [accum.width, accum.height, 1],
        )
    }
}
