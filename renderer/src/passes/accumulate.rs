//! Running mean of traced colour over many samples (reference renders).

use super::{Kernel, Pass};
use crate::error::Result;
use crate::graph::{read_image, write_image, FrameRecorder};
use crate::layouts::AccumulatePush;
use crate::vk::Image;
use glam::UVec4;

pub struct Accumulate;

impl Kernel for Accumulate {
    const SHADER: &'static str = "passes/accumulate";
    type Push = AccumulatePush;
}

pub type AccumulatePass = Pass<Accumulate>;

impl Pass<Accumulate> {
    /// Blends `sample` into `accum`, which already holds the mean of `samples_so_far` samples.
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        sample: &Image,
        accum: &Image,
        samples_so_far: u32,
    ) -> Result<()> {
        self.blend(rec, sample, accum, samples_so_far, false)
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
        self.blend(rec, sample, accum, samples_so_far, true)
    }

    fn blend(
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
        let size = [accum.width, accum.height, 1];
        self.dispatch(rec, "accumulate", &binds, &push, size)
    }
}
