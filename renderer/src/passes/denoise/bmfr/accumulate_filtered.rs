//! BMFR accumulation after the fit: the fitted colour blended with its history through the same
//! reprojection as before the fit (α = max(α_floor, 1/history)), then re-modulated by albedo.

use super::accumulate::temporal_push;
use super::history::{BmfrHistory, Reprojection};
use crate::error::Result;
use crate::graph::{read_buffer, read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::{BmfrTemporalPush, SamplingParams};
use crate::passes::grid::{GBuffer, TileList};
use crate::passes::push_bytes;
use crate::vk::{Buffer, ComputePipeline, Context, Image};
use std::sync::Arc;

pub struct AccumulateFilteredPass {
    pipeline: std::sync::Arc<ComputePipeline>,
}

impl AccumulateFilteredPass {
    pub fn new(ctx: &Arc<Context>, variant: &str) -> Result<AccumulateFilteredPass> {
        let shader = format!("passes/denoise/bmfr_accumulate_filtered.{variant}");
        Ok(AccumulateFilteredPass {
            pipeline: ComputePipeline::shared(
                ctx,
                &shader,
                std::mem::size_of::<BmfrTemporalPush>() as u32,
            )?,
        })
    }

    /// `fitted` + history half `prev` → history half `cur` and `dst` (re-modulated), live tiles.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        g: &GBuffer,
        h: &BmfrHistory,
        prev: usize,
        cur: usize,
        fitted: &Image,
        dst: &Image,
        current: &SamplingParams,
        table: &Buffer,
        tiles: &TileList,
        r: &Reprojection,
        alpha_floor: f32,
    ) -> Result<()> {
        let binds = [
            read_image("fitted", fitted),
            read_image("normal_depth", &g.normal_depth),
            read_image("position", &g.position),
            read_image("motion", &g.motion),
            read_image("noisy", &h.noisy[cur]),
            read_image("prev_normal", &h.normal[prev]),
            read_image("prev_position", &h.position[prev]),
            read_image("prev_filtered", &h.filtered[prev]),
            read_image("albedo", &g.albedo),
            write_image("filtered", &h.filtered[cur]),
            write_image("dst", dst),
            read_image("features_position", &h.position[cur]),
            read_texels("grid_columns", table),
            read_buffer("tiles", tiles.buffer),
        ];
        let push = temporal_push(current, r, alpha_floor);
        rec.dispatch(
            "bmfr_accumulate_filtered",
            &self.pipeline,
            &binds,
            push_bytes(&push),
            tiles.live_threads(),
        )
    }
}
