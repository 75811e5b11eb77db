//! BMFR accumulation before the fit: noisy demodulated radiance, normal and camera-relative
//! position blended with their reprojected history (α = max(α_floor, 1/history)).

use super::history::{BmfrHistory, Reprojection};
use crate::error::Result;
use crate::graph::{read_buffer, read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::{BmfrTemporalPush, SamplingParams};
use crate::passes::grid::{GBuffer, TileList};
use crate::passes::push_bytes;
use crate::vk::{Buffer, ComputePipeline, Context};
use std::sync::Arc;

pub struct AccumulatePass {
    pipeline: std::sync::Arc<ComputePipeline>,
}

/// The push block both temporal passes share: this frame's space, the previous frame's
/// gaze-dependent slots, the camera shift and the α floor (1 when the history is dropped).
pub(super) fn temporal_push(
    current: &SamplingParams,
    r: &Reprojection,
    alpha_floor: f32,
) -> BmfrTemporalPush {
    let p = r.previous.unwrap_or(current);
    let alpha = if r.previous.is_none() {
        1.0
    } else {
        alpha_floor
    };
    BmfrTemporalPush {
        space: *current,
        prev: p.frame(),
        params: r.camera_shift.extend(alpha),
    }
}

impl AccumulatePass {
    pub fn new(ctx: &Arc<Context>, variant: &str) -> Result<AccumulatePass> {
        let shader = format!("passes/denoise/bmfr_accumulate.{variant}");
        Ok(AccumulatePass {
            pipeline: ComputePipeline::shared(
                ctx,
                &shader,
                std::mem::size_of::<BmfrTemporalPush>() as u32,
            )?,
        })
    }

    /// Reads history half `prev`, writes half `cur` (noisy, normal, position) in the live tiles.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        g: &GBuffer,
        materials: &Buffer,
        h: &BmfrHistory,
        prev: usize,
        cur: usize,
        current: &SamplingParams,
        table: &Buffer,
        tiles: &TileList,
        r: &Reprojection,
        alpha_floor: f32,
    ) -> Result<()> {
        let binds = [
            read_image("radiance", &g.radiance),
            read_image("normal_depth", &g.normal_depth),
            read_image("position", &g.position),
            read_image("motion", &g.motion),
            read_image("ids", &g.ids),
            read_buffer("materials", materials),
            read_image("prev_noisy", &h.noisy[prev]),
            read_image("prev_normal", &h.normal[prev]),
            read_image("prev_position", &h.position[prev]),
            write_image("noisy", &h.noisy[cur]),
            write_image("normal", &h.normal[cur]),
            write_image("features_position", &h.position[cur]),
            read_texels("grid_columns", table),
            read_buffer("tiles", tiles.buffer),
        ];
        let push = temporal_push(current, r, alpha_floor);
        rec.dispatch(
            "bmfr_accumulate",
            &self.pipeline,
            &binds,
            push_bytes(&push),
            tiles.live_threads(),
        )
    }
}
