//! Re-modulation by albedo, the last step of every denoiser that filters demodulated radiance
//! (SVGF, and A-SVGF/BMFR alike): filtered × albedo → radiance for the way back.

use crate::error::Result;
use crate::graph::{read_image, write_image, FrameRecorder};
use crate::passes::{Kernel, Pass};
use crate::vk::Image;

pub struct Modulate;

impl Kernel for Modulate {
    const SHADER: &'static str = "passes/denoise/modulate";
    type Push = ();
}

impl Pass<Modulate> {
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
        self.dispatch(rec, pass, &binds, &(), [dst.width, dst.height, 1])
    }
}
