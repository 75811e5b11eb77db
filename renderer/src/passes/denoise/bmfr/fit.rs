//! BMFR per-block fit: one workgroup per 32×32 block builds the 1024 × 13 least-squares matrix
//! (10 features with stochastic regularisation | RGB) and solves it by Householder QR into 10
//! weights per channel.

use super::history::BmfrHistory;
use crate::error::Result;
use crate::graph::{read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::{BmfrBlockPush, SamplingParams, BMFR_BLOCK, BMFR_FIT_LANES};
use crate::passes::grid::GridFrame;
use crate::passes::{Kernel, Pass};
use crate::vk::Image;
use glam::{IVec2, IVec4, UVec2, Vec4};

/// Block-grid offsets in texels, one per frame (frame % 16): every even value of [−16, 14] once
/// per axis, in an order that spreads consecutive offsets (x bit-reversed, y stepping by 5).
pub const BLOCK_OFFSETS: [[i32; 2]; 16] = block_offsets();

const fn block_offsets() -> [[i32; 2]; 16] {
    let mut table = [[0; 2]; 16];
    let mut i = 0;
    while i < 16 {
        let reversed = ((i & 1) << 3 | (i & 2) << 1 | (i & 4) >> 1 | (i & 8) >> 3) as i32;
        table[i] = [2 * reversed - 16, 2 * ((5 * i as i32 + 3) % 16) - 16];
        i += 1;
    }
    table
}

/// Blocks per axis of a grid: one more than the grid needs, so that every offset covers it.
pub fn block_count(grid: UVec2) -> UVec2 {
    grid.map(|v| v.div_ceil(BMFR_BLOCK) + 1)
}

pub struct Fit;

impl Kernel for Fit {
    const SHADER: &'static str = "passes/denoise/bmfr_fit";
    type Push = BmfrBlockPush;
}

/// One frame's block grid: its offset, and the fit's noise (its seed and amplitude; the
/// weighted sum uses none).
#[derive(Clone, Copy)]
pub(super) struct Blocks {
    pub offset: IVec2,
    pub seed: u32,
    pub noise: f32,
}

/// The push block of the fit and the weighted sum: the space and the block grid.
pub(super) fn block_push(space: &SamplingParams, blocks: &Blocks) -> BmfrBlockPush {
    BmfrBlockPush {
        space: *space,
        config: IVec4::new(blocks.offset.x, blocks.offset.y, blocks.seed as i32, 0),
        params: Vec4::new(blocks.noise, 0.0, 0.0, 0.0),
    }
}

impl Pass<Fit> {
    /// Features and noisy colour of this frame's history half → `weights`.
    pub(super) fn record(
        &self,
        rec: &mut FrameRecorder,
        frame: &GridFrame,
        h: &BmfrHistory,
        weights: &Image,
        blocks: &Blocks,
    ) -> Result<()> {
        let cur = h.current();
        let binds = [
            read_image("noisy", &h.noisy[cur]),
            read_image("normal", &h.normal[cur]),
            read_image("features_position", &h.position[cur]),
            write_image("weights", weights),
            read_texels("grid_columns", frame.sampling_table),
        ];
        let space = &frame.current;
        let push = block_push(space, blocks);
        let count = block_count(UVec2::new(space.grid.x, space.grid.y));
        self.dispatch(
            rec,
            "bmfr_fit",
            &binds,
            &push,
            [count.x * BMFR_FIT_LANES, count.y, 1],
        )
    }
}
