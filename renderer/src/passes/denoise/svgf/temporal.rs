//! SVGF temporal accumulation: reprojection with bilinear same-surface taps (3×3 search when they
//! all fail), colour and luminance moments blended with α = max(α_min, 1/history).

use super::history::SvgfHistory;
use super::settings::SvgfSettings;
use crate::error::Result;
use crate::graph::{read_buffer, read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::SvgfTemporalPush;
use crate::passes::grid::GridFrame;
use crate::passes::{Kernel, Pass};
use crate::vk::Image;
use glam::Vec4;

pub struct Temporal;

impl Kernel for Temporal {
    const SHADER: &'static str = "passes/denoise/svgf_temporal";
    type Push = SvgfTemporalPush;
}

impl Pass<Temporal> {
    /// Reads the history's other half, writes this frame's half and `accum` (colour, variance)
    /// in the live tiles; `frame.previous` `None` starts every history afresh. `gradient`:
    /// A-SVGF's reconstructed gradient per stratum, for the `*_adaptive` kernel variants.
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        frame: &GridFrame,
        (h, accum): (&SvgfHistory, &Image),
        s: &SvgfSettings,
        gradient: Option<&Image>,
    ) -> Result<()> {
        let g = frame.gbuffer;
        let (cur, prev) = (h.current(), 1 - h.current());
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
            read_texels("grid_columns", frame.sampling_table),
            read_buffer("tiles", frame.tiles.buffer),
            read_image("gradient", gradient.unwrap_or(&g.radiance)),
        ];
        let binds = &binds[..if gradient.is_some() {
            binds.len()
        } else {
            binds.len() - 1
        }];
        // The grid and screen never change for one renderer: only the gaze-dependent slots travel.
        let current = &frame.current;
        let p = frame.previous.as_ref().unwrap_or(current);
        let reset = if frame.previous.is_none() { 1.0 } else { 0.0 };
        let push = SvgfTemporalPush {
            space: *current,
            prev: p.frame(),
            params: Vec4::new(s.alpha_color, s.alpha_moments, s.max_history as f32, reset),
        };
        self.dispatch(
            rec,
            "svgf_temporal",
            binds,
            &push,
            frame.tiles.live_threads(),
        )
    }
}
