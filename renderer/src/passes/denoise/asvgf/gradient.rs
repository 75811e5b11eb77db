//! One iteration of A-SVGF's gradient reconstruction: joint-bilateral à-trous on the strata grid
//! (the first iteration reads the tracer's gradient image, the others the previous iteration).

use super::settings::AsvgfSettings;
use crate::error::Result;
use crate::graph::{read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::AsvgfGradientPush;
use crate::passes::grid::GridFrame;
use crate::passes::{Kernel, Pass};
use crate::vk::Image;
use glam::{UVec4, Vec4};

pub struct Gradient;

impl Kernel for Gradient {
    const SHADER: &'static str = "passes/denoise/asvgf_gradient";
    type Push = AsvgfGradientPush;
}

impl Pass<Gradient> {
    /// `src` → `dst` (strata-sized: δ, max f, confidence), taps `step` strata apart.
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        frame: &GridFrame,
        (src, dst): (&Image, &Image),
        step: u32,
        s: &AsvgfSettings,
    ) -> Result<()> {
        let g = frame.gbuffer;
        let binds = [
            read_image("src", src),
            read_image("normal_depth", &g.normal_depth),
            read_image("position", &g.position),
            write_image("dst", dst),
            read_texels("grid_columns", frame.sampling_table),
        ];
        let push = AsvgfGradientPush {
            space: frame.current,
            params: Vec4::new(s.gradient_sigma_depth, s.gradient_sigma_normal, 0.0, 0.0),
            config: UVec4::new(step, 0, 0, 0),
        };
        self.dispatch(
            rec,
            "asvgf_gradient",
            &binds,
            &push,
            [dst.width, dst.height, 1],
        )
    }
}
