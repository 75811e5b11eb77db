//! BMFR's per-texel state in the trace's idle tiles: the accumulations and the weighted sum run
//! over the live tiles only, so this writes what they would write there — the history a later
//! frame reads, the features the fit reads over whole blocks, the fitted colour and the output.

use super::history::BmfrHistory;
use crate::error::Result;
use crate::graph::{read_buffer, read_texels, write_image, FrameRecorder};
use crate::layouts::{BmfrIdlePush, SamplingParams};
use crate::passes::grid::TileList;
use crate::passes::push_bytes;
use crate::vk::{Buffer, ComputePipeline, Context, Image};
use glam::UVec4;
use std::sync::Arc;

pub struct IdlePass {
    pipeline: Arc<ComputePipeline>,
}

/// The images BMFR writes per texel in a frame.
pub(super) struct IdleTargets<'a> {
    pub history: &'a BmfrHistory,
    pub cur: usize,
    pub fitted: &'a Image,
    pub output: &'a Image,
}

impl IdlePass {
    pub fn new(ctx: &Arc<Context>, variant: &str) -> Result<IdlePass> {
        let shader = format!("passes/denoise/bmfr_idle.{variant}");
        Ok(IdlePass {
            pipeline: ComputePipeline::shared(
                ctx,
                &shader,
                std::mem::size_of::<BmfrIdlePush>() as u32,
            )?,
        })
    }

    /// Writes `targets` in `tiles`' idle tiles (nothing to record without any). Recorded before
    /// the fit, which reads the accumulated features of every texel of a block.
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        targets: &IdleTargets,
        space: &SamplingParams,
        table: &Buffer,
        tiles: &TileList,
    ) -> Result<()> {
        if tiles.idle == 0 {
            return Ok(());
        }
        let (h, cur) = (targets.history, targets.cur);
        let binds = [
            write_image("noisy", &h.noisy[cur]),
            write_image("normal", &h.normal[cur]),
            write_image("features_position", &h.position[cur]),
            write_image("fitted", targets.fitted),
            write_image("filtered", &h.filtered[cur]),
            write_image("dst", targets.output),
            read_texels("grid_columns", table),
            read_buffer("tiles", tiles.buffer),
        ];
        let push = BmfrIdlePush {
            space: *space,
            config: UVec4::new(tiles.live, 0, 0, 0),
        };
        rec.dispatch(
            "bmfr_idle",
            &self.pipeline,
            &binds,
            push_bytes(&push),
            tiles.idle_threads(),
        )
    }
}
