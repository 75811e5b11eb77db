//! SVGF's state in the trace's idle tiles: the other SVGF passes run over the live tiles only, so
//! this writes what they would write there and a later frame reads (moments, surfaces, the colour
//! history) — a texel there holds no sample or one culled off the screen.

use super::history::SvgfHistory;
use crate::error::Result;
use crate::graph::{read_buffer, read_texels, write_image, FrameRecorder};
use crate::layouts::{SamplingParams, SvgfIdlePush};
use crate::passes::grid::TileList;
use crate::passes::push_bytes;
use crate::vk::{Buffer, ComputePipeline, Context};
use glam::UVec4;
use std::sync::Arc;

pub struct IdlePass {
    pipeline: std::sync::Arc<ComputePipeline>,
}

impl IdlePass {
    pub fn new(ctx: &Arc<Context>, variant: &str) -> Result<IdlePass> {
        let shader = format!("passes/denoise/svgf_idle.{variant}");
        Ok(IdlePass {
            pipeline: ComputePipeline::shared(
                ctx,
                &shader,
                std::mem::size_of::<SvgfIdlePush>() as u32,
            )?,
        })
    }

    /// Writes history half `cur` and the colour history in `tiles`' idle tiles (nothing to record
    /// without any). Recorded after the temporal pass, which reads the colour history.
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        h: &SvgfHistory,
        cur: usize,
        space: &SamplingParams,
        table: &Buffer,
        tiles: &TileList,
    ) -> Result<()> {
        if tiles.idle == 0 {
            return Ok(());
        }
        let binds = [
            write_image("moments", &h.moments[cur]),
            write_image("surface", &h.surface[cur]),
            write_image("history_color", &h.color),
            read_texels("grid_columns", table),
            read_buffer("tiles", tiles.buffer),
        ];
        let push = SvgfIdlePush {
            space: *space,
            config: UVec4::new(tiles.live, 0, 0, 0),
        };
        rec.dispatch(
            "svgf_idle",
            &self.pipeline,
            &binds,
            push_bytes(&push),
            tiles.idle_threads(),
        )
    }
}
