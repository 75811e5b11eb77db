//! One SVGF à-trous iteration: 5×5 B3-spline taps `step` texels apart, edge-stopped by depth,
//! normal and variance-scaled luminance; variance filtered with the squared weights.

use super::settings::SvgfSettings;
use crate::error::Result;
use crate::graph::{read_buffer, read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::SvgfAtrousPush;
use crate::passes::grid::GridFrame;
use crate::passes::{Kernel, Pass};
use crate::vk::Image;
use glam::{UVec4, Vec4};

pub struct Atrous;

impl Kernel for Atrous {
    const SHADER: &'static str = "passes/denoise/svgf_atrous";
    type Push = SvgfAtrousPush;
}

impl Pass<Atrous> {
    /// `src` → `dst` (both colour, variance) in the live tiles, taps `step` texels apart.
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        frame: &GridFrame,
        (src, dst): (&Image, &Image),
        step: u32,
        s: &SvgfSettings,
    ) -> Result<()> {
        let g = frame.gbuffer;
        let binds = [
            read_image("src", src),
            read_image("normal_depth", &g.normal_depth),
            read_image("position", &g.position),
            write_image("dst", dst),
            read_texels("grid_columns", frame.sampling_table),
            read_buffer("tiles", frame.tiles.buffer),
        ];
        let push = SvgfAtrousPush {
            space: frame.current,
            params: Vec4::new(s.sigma_luminance, s.sigma_depth, s.sigma_normal, 0.0),
            config: UVec4::new(step, 0, 0, 0),
        };
        self.dispatch(
            rec,
            "svgf_atrous",
            &binds,
            &push,
            frame.tiles.live_threads(),
        )
    }
}
