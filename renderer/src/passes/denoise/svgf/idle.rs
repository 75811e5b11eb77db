//! SVGF's state in the trace's idle tiles: the other SVGF passes run over the live tiles only, so
//! this writes what they would write there and a later frame reads (moments, surfaces, the colour
//! history) — a texel there holds no sample or one culled off the screen.

use super::history::SvgfHistory;
use crate::error::Result;
use crate::graph::{read_buffer, read_texels, write_image, FrameRecorder};
use crate::layouts::SvgfIdlePush;
use crate::passes::grid::GridFrame;
use crate::passes::{Kernel, Pass};
use glam::UVec4;

pub struct Idle;

impl Kernel for Idle {
    const SHADER: &'static str = "passes/denoise/svgf_idle";
    type Push = SvgfIdlePush;
}

impl Pass<Idle> {
    /// Writes this frame's history half and the colour history in the frame's idle tiles
    /// (nothing to record without any). Recorded after the temporal pass, which reads the colour
    /// history.
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        frame: &GridFrame,
        h: &SvgfHistory,
    ) -> Result<()> {
        let tiles = &frame.tiles;
        if tiles.idle == 0 {
            return Ok(());
        }
        let cur = h.current();
        let binds = [
            write_image("moments", &h.moments[cur]),
            write_image("surface", &h.surface[cur]),
            write_image("history_color", &h.color),
            read_texels("grid_columns", frame.sampling_table),
            read_buffer("tiles", tiles.buffer),
        ];
        let push = SvgfIdlePush {
            space: frame.current,
            config: UVec4::new(tiles.live, 0, 0, 0),
        };
        self.dispatch(rec, "svgf_idle", &binds, &push, tiles.idle_threads())
    }
}
