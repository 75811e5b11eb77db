//! SVGF temporal accumulation: reprojection with bilinear same-surface taps (3×3 search when they
//! all fail), colour and luminance moments blended with α = max(α_min, 1/history).

use super::history::SvgfHistory;
use super::settings::SvgfSettings;
use crate::error::Result;
use crate::graph::{read_buffer, read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::{SamplingParams, SvgfTemporalPush};
use crate::passes::grid::{GBuffer, TileList};
use crate::passes::push_bytes;
use crate::vk::{Buffer, ComputePipeline, Context, Image};
use glam::Vec4;
use std::sync::Arc;

pub struct TemporalPass {
    pipeline: std::sync::Arc<ComputePipeline>,
}

impl TemporalPass {
    pub fn new(ctx: &Arc<Context>, variant: &str) -> Result<TemporalPass> {
        let shader = format!("passes/denoise/svgf_temporal.{variant}");
        Ok(TemporalPass {
            pipeline: ComputePipeline::shared(
                ctx,
                &shader,
                std::mem::size_of::<SvgfTemporalPush>() as u32,
            )?,
        })
    }

    /// Reads history half `prev`, writes half `cur` and `accum` (colour, variance) in the live tiles. `previous`:
    /// the previous frame's space, `None` to start every history afresh. `gradient`: A-SVGF's
    /// reconstructed gradient per stratum, for the `*_adaptive` kernel variants.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        g: &GBuffer,
        h: &SvgfHistory,
        prev: usize,
        cur: usize,
        accum: &Image,
        current: &SamplingParams,
        table: &Buffer,
        tiles: &TileList,
        previous: Option<&SamplingParams>,
        s: &SvgfSettings,
        gradient: Option<&Image>,
    ) -> Result<()> {
        // A fixed array sliced to what this kernel binds: no host allocation per frame.
        let binds = [
            read_image("radiance", &g.radiance),
            read_image("normal_depth", &g.normal_depth),
            read_image("position", &g.position),
            read_image("ids", &g.ids),
            read_image("motion", &g.motion),
            read_image("prev_color", &h.color),
            read_image("prev_moments", &h.moments[prev]),
            read_image("prev_surface", &h.surface[prev]),
            write_image("accum", accum),
            write_image("moments", &h.moments[cur]),
            write_image("surface", &h.surface[cur]),
            read_texels("grid_columns", table),
            read_buffer("tiles", tiles.buffer),
            read_image("gradient", gradient.unwrap_or(&g.radiance)),
        ];
        let binds = &binds[..if gradient.is_some() {
            binds.len()
        } else {
            binds.len() - 1
        }];
        // The grid and screen never change for one renderer: only the gaze-dependent slots travel.
        let p = previous.unwrap_or(current);
        let reset = if previous.is_none() { 1.0 } else { 0.0 };
        let push = SvgfTemporalPush {
            space: *current,
            prev: p.frame(),
            params: Vec4::new(s.alpha_color, s.alpha_moments, s.max_history as f32, reset),
        };
        rec.dispatch(
            "svgf_temporal",
            &self.pipeline,
            binds,
            push_bytes(&push),
            tiles.live_threads(),
        )
    }
}
