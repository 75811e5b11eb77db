//! BMFR per-block fit: one workgroup per 32×32 block builds the 1024 × 13 least-squares matrix
//! (10 features with stochastic regularisation | RGB) and solves it by Householder QR into 10
//! weights per channel.

use super::history::BmfrHistory;
use crate::error::Result;
use crate::graph::{read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::{BmfrBlockPush, SamplingParams, BMFR_BLOCK, BMFR_FIT_LANES};
use crate::passes::push_bytes;
use crate::vk::{Buffer, ComputePipeline, Context, Image};
use glam::{IVec2, IVec4, UVec2, Vec4};
use std::sync::Arc;

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

pub struct FitPass {
    pipeline: std::sync::Arc<ComputePipeline>,
}

/// The push block of the fit and the weighted sum: the space and the block-grid offset.
pub(super) fn block_push(
    space: &SamplingParams,
    offset: IVec2,
    seed: u32,
    noise: f32,
) -> BmfrBlockPush {
    BmfrBlockPush {
        space: *space,
        config: IVec4::new(offset.x, offset.y, seed as i32, 0),
        params: Vec4::new(noise, 0.0, 0.0, 0.0),
    }
}

impl FitPass {
    pub fn new(ctx: &Arc<Context>, variant: &str) -> Result<FitPass> {
        let shader = format!("passes/denoise/bmfr_fit.{variant}");
        Ok(FitPass {
            pipeline: ComputePipeline::shared(
                ctx,
                &shader,
                std::mem::size_of::<BmfrBlockPush>() as u32,
            )?,
        })
    }

    /// Features and noisy colour from history half `cur` → `weights`.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        h: &BmfrHistory,
        cur: usize,
        weights: &Image,
        space: &SamplingParams,
        table: &Buffer,
        offset: IVec2,
        seed: u32,
        noise: f32,
    ) -> Result<()> {
        let binds = [
            read_image("noisy", &h.noisy[cur]),
            read_image("normal", &h.normal[cur]),
            read_image("features_position", &h.position[cur]),
            write_image("weights", weights),
            read_texels("grid_columns", table),
        ];
        let push = block_push(space, offset, seed, noise);
        let blocks = block_count(UVec2::new(space.grid.x, space.grid.y));
        rec.dispatch(
            "bmfr_fit",
            &self.pipeline,
            &binds,
            push_bytes(&push),
            [blocks.x * BMFR_FIT_LANES, blocks.y, 1],
        )
    }
}
