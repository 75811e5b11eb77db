//! SVGF variance: temporal where the history is long enough, else a 7×7 edge-stopped spatial
//! estimate from the moments.

use super::history::SvgfHistory;
use super::settings::SvgfSettings;
use crate::error::Result;
use crate::graph::{read_buffer, read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::SvgfVariancePush;
use crate::passes::grid::GridFrame;
use crate::passes::{Kernel, Pass};
use crate::vk::Image;
use glam::Vec4;

pub struct Variance;

impl Kernel for Variance {
    const SHADER: &'static str = "passes/denoise/svgf_variance";
    type Push = SvgfVariancePush;
}

impl Pass<Variance> {
    /// `accum` (colour, temporal variance) and this frame's moments → `dst` (colour, variance),
    /// live tiles.
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        frame: &GridFrame,
        h: &SvgfHistory,
        (accum, dst): (&Image, &Image),
        s: &SvgfSettings,
    ) -> Result<()> {
        let g = frame.gbuffer;
        let binds = [
            read_image("accum", accum),
            read_image("moments", &h.moments[h.current()]),
            read_image("normal_depth", &g.normal_depth),
            read_image("position", &g.position),
            write_image("dst", dst),
            read_texels("grid_columns", frame.sampling_table),
            read_buffer("tiles", frame.tiles.buffer),
        ];
        let push = SvgfVariancePush {
            space: frame.current,
            params: Vec4::new(
                s.sigma_luminance,
                s.sigma_depth,
                s.sigma_normal,
                s.variance_history as f32,
            ),
        };
        self.dispatch(
            rec,
            "svgf_variance",
            &binds,
            &push,
            frame.tiles.live_threads(),
        )
    }
}
