//! BMFR weighted sum: each texel evaluates its block's fit on its own features, clamped ≥ 0.

use super::fit::block_push;
use super::history::BmfrHistory;
use crate::error::Result;
use crate::graph::{read_buffer, read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::{BmfrBlockPush, SamplingParams};
use crate::passes::grid::TileList;
use crate::passes::push_bytes;
use crate::vk::{Buffer, ComputePipeline, Context, Image};
use glam::IVec2;
use std::sync::Arc;

pub struct WeightedSumPass {
    pipeline: std::sync::Arc<ComputePipeline>,
}

impl WeightedSumPass {
    pub fn new(ctx: &Arc<Context>, variant: &str) -> Result<WeightedSumPass> {
        let shader = format!("passes/denoise/bmfr_weighted_sum.{variant}");
        Ok(WeightedSumPass {
            pipeline: ComputePipeline::shared(
                ctx,
                &shader,
                std::mem::size_of::<BmfrBlockPush>() as u32,
            )?,
        })
    }

    /// Features of history half `cur` and the blocks' `weights` → `fitted`, live tiles.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        h: &BmfrHistory,
        cur: usize,
        weights: &Image,
        fitted: &Image,
        space: &SamplingParams,
        table: &Buffer,
        tiles: &TileList,
        offset: IVec2,
    ) -> Result<()> {
        let binds = [
            read_image("noisy", &h.noisy[cur]),
            read_image("normal", &h.normal[cur]),
            read_image("features_position", &h.position[cur]),
            read_image("weights", weights),
            write_image("fitted", fitted),
            read_texels("grid_columns", table),
            read_buffer("tiles", tiles.buffer),
        ];
        let push = block_push(space, offset, 0, 0.0);
        rec.dispatch(
            "bmfr_weighted_sum",
            &self.pipeline,
            &binds,
            push_bytes(&push),
            tiles.live_threads(),
        )
    }
}
