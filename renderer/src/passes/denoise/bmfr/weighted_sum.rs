//! BMFR weighted sum: each texel evaluates its block's fit on its own features, clamped ≥ 0.

use super::fit::{block_push, Blocks};
use super::history::BmfrHistory;
use crate::error::Result;
use crate::graph::{read_buffer, read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::BmfrBlockPush;
use crate::passes::grid::GridFrame;
use crate::passes::{Kernel, Pass};
use crate::vk::Image;

pub struct WeightedSum;

impl Kernel for WeightedSum {
    const SHADER: &'static str = "passes/denoise/bmfr_weighted_sum";
    type Push = BmfrBlockPush;
}

impl Pass<WeightedSum> {
    /// Features of this frame's history half and the blocks' `weights` → `fitted`, live tiles.
    pub(super) fn record(
        &self,
        rec: &mut FrameRecorder,
        frame: &GridFrame,
        h: &BmfrHistory,
        (weights, fitted): (&Image, &Image),
        blocks: &Blocks,
    ) -> Result<()> {
        let cur = h.current();
        let binds = [
            read_image("noisy", &h.noisy[cur]),
            read_image("normal", &h.normal[cur]),
            read_image("features_position", &h.position[cur]),
            read_image("weights", weights),
            write_image("fitted", fitted),
            read_texels("grid_columns", frame.sampling_table),
            read_buffer("tiles", frame.tiles.buffer),
        ];
        let blocks = Blocks {
            seed: 0,
            noise: 0.0,
            ..*blocks
        };
        let push = block_push(&frame.current, &blocks);
        self.dispatch(
            rec,
            "bmfr_weighted_sum",
            &binds,
            &push,
            frame.tiles.live_threads(),
        )
    }
}
