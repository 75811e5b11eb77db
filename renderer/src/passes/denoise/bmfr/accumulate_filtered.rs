//! BMFR accumulation after the fit: the fitted colour blended with its history through the same
//! reprojection as before the fit (α = max(α_floor, 1/history)), then re-modulated by albedo.

use super::accumulate::temporal_push;
use super::history::{FrameTargets, Reprojection};
use crate::error::Result;
use crate::graph::{read_buffer, read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::BmfrTemporalPush;
use crate::passes::grid::GridFrame;
use crate::passes::{Kernel, Pass};

pub struct AccumulateFiltered;

impl Kernel for AccumulateFiltered {
    const SHADER: &'static str = "passes/denoise/bmfr_accumulate_filtered";
    type Push = BmfrTemporalPush;
}

impl Pass<AccumulateFiltered> {
    /// `t.fitted` + the history's other half → this frame's half and `t.output` (re-modulated),
    /// live tiles.
    pub(super) fn record(
        &self,
        rec: &mut FrameRecorder,
        frame: &GridFrame,
        t: &FrameTargets,
        r: &Reprojection,
        alpha_floor: f32,
    ) -> Result<()> {
        let (g, h) = (frame.gbuffer, t.history);
        let (cur, prev) = (h.current(), 1 - h.current());
        let binds = [
            read_image("fitted", t.fitted),
            read_image("normal_depth", &g.normal_depth),
            read_image("position", &g.position),
            read_image("motion", &g.motion),
            read_image("noisy", &h.noisy[cur]),
            read_image("prev_normal", &h.normal[prev]),
            read_image("prev_position", &h.position[prev]),
            read_image("prev_filtered", &h.filtered[prev]),
            read_image("albedo", &g.albedo),
            write_image("filtered", &h.filtered[cur]),
            write_image("dst", t.output),
            read_image("features_position", &h.position[cur]),
            read_texels("grid_columns", frame.sampling_table),
            read_buffer("tiles", frame.tiles.buffer),
        ];
        let push = temporal_push(&frame.current, r, alpha_floor);
        self.dispatch(
            rec,
            "bmfr_accumulate_filtered",
            &binds,
            &push,
            frame.tiles.live_threads(),
        )
    }
}
