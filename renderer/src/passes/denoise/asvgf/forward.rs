//! A-SVGF forward projection: last frame's brightest source sample per 3×3 stratum (as the tracer
//! marked them in the visibility image), carried into this
//! frame's grid, claims the stratum it lands in for the tracer to re-shade; also clears the
//! strata's gradient image the tracer writes.

use crate::error::{Error, Result};
use crate::graph::{
    read_buffer, read_image, read_texels, write_buffer, write_image, FrameRecorder,
};
use crate::layouts::AsvgfForwardPush;
use crate::passes::grid::{GradientTargets, GridFrame};
use crate::passes::{Kernel, Pass};
use glam::UVec4;

pub struct Forward;

impl Kernel for Forward {
    const SHADER: &'static str = "passes/denoise/asvgf_forward";
    type Push = AsvgfForwardPush;
}

impl Pass<Forward> {
    /// Reads last frame's samples from the G-buffer (before the tracer overwrites it) and the
    /// cameras from the frame data; fills `targets.samples` (cleared before) and clears
    /// `targets.gradient` (strata-sized). `project: false` (no usable last frame) only clears.
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        frame: &GridFrame,
        targets: &GradientTargets,
        project: bool,
    ) -> Result<()> {
        let g = frame.gbuffer;
        let visibility = g
            .visibility
            .as_ref()
            .ok_or_else(|| Error::Invalid("A-SVGF needs a G-buffer with visibility".into()))?;
        let binds = [
            read_buffer("frame", frame.frame_data),
            read_image("ids", &g.ids),
            read_image("position", &g.position),
            read_image("visibility", visibility),
            write_buffer("gradient_samples", targets.samples),
            write_image("gradient", targets.gradient),
            read_texels("grid_columns", frame.sampling_table),
        ];
        let push = AsvgfForwardPush {
            space: frame.current,
            config: UVec4::new(project as u32, 0, 0, 0),
        };
        let size = [targets.gradient.width, targets.gradient.height, 1];
        self.dispatch(rec, "asvgf_forward", &binds, &push, size)
    }
}
