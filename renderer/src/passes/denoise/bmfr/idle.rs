//! BMFR's per-texel state in the trace's idle tiles: the accumulations and the weighted sum run
//! over the live tiles only, so this writes what they would write there — the history a later
//! frame reads, the features the fit reads over whole blocks, the fitted colour and the output.

use super::history::FrameTargets;
use crate::error::Result;
use crate::graph::{read_buffer, read_texels, write_image, FrameRecorder};
use crate::layouts::BmfrIdlePush;
use crate::passes::grid::GridFrame;
use crate::passes::{Kernel, Pass};
use glam::UVec4;

pub struct Idle;

impl Kernel for Idle {
    const SHADER: &'static str = "passes/denoise/bmfr_idle";
    type Push = BmfrIdlePush;
}

impl Pass<Idle> {
    /// Writes `t` in the frame's idle tiles (nothing to record without any). Recorded before the
    /// fit, which reads the accumulated features of every texel of a block.
    pub(super) fn record(
        &self,
        rec: &mut FrameRecorder,
        frame: &GridFrame,
        t: &FrameTargets,
    ) -> Result<()> {
        let tiles = &frame.tiles;
        if tiles.idle == 0 {
            return Ok(());
        }
        let (h, cur) = (t.history, t.history.current());
        let binds = [
            write_image("noisy", &h.noisy[cur]),
            write_image("normal", &h.normal[cur]),
            write_image("features_position", &h.position[cur]),
            write_image("fitted", t.fitted),
            write_image("filtered", &h.filtered[cur]),
            write_image("dst", t.output),
            read_texels("grid_columns", frame.sampling_table),
            read_buffer("tiles", tiles.buffer),
        ];
        let push = BmfrIdlePush {
            space: frame.current,
            config: UVec4::new(tiles.live, 0, 0, 0),
        };
        self.dispatch(rec, "bmfr_idle", &binds, &push, tiles.idle_threads())
    }
}
