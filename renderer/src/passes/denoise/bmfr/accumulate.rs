//! BMFR accumulation before the fit: noisy demodulated radiance, normal and camera-relative
//! position blended with their reprojected history (α = max(α_floor, 1/history)).

use super::history::{BmfrHistory, Reprojection};
use crate::error::Result;
use crate::graph::{read_buffer, read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::{BmfrTemporalPush, SamplingParams};
use crate::passes::grid::GridFrame;
use crate::passes::{Kernel, Pass};

pub struct Accumulate;

impl Kernel for Accumulate {
    const SHADER: &'static str = "passes/denoise/bmfr_accumulate";
    type Push = BmfrTemporalPush;
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

impl Pass<Accumulate> {
    /// Reads the history's other half, writes this frame's (noisy, normal, position) in the
    /// live tiles.
    pub(super) fn record(
        &self,
        rec: &mut FrameRecorder,
        frame: &GridFrame,
        h: &BmfrHistory,
        r: &Reprojection,
        alpha_floor: f32,
    ) -> Result<()> {
        let g = frame.gbuffer;
        let (cur, prev) = (h.current(), 1 - h.current());
        let binds = [
            read_image("radiance", &g.radiance),
            read_image("normal_depth", &g.normal_depth),
            read_image("position", &g.position),
            read_image("motion", &g.motion),
            read_image("ids", &g.ids),
            read_buffer("materials", frame.materials),
            read_image("prev_noisy", &h.noisy[prev]),
            read_image("prev_normal", &h.normal[prev]),
            read_image("prev_position", &h.position[prev]),
            write_image("noisy", &h.noisy[cur]),
            write_image("normal", &h.normal[cur]),
            write_image("features_position", &h.position[cur]),
            read_texels("grid_columns", frame.sampling_table),
            read_buffer("tiles", frame.tiles.buffer),
        ];
        let push = temporal_push(&frame.current, r, alpha_floor);
        self.dispatch(
            rec,
            "bmfr_accumulate",
            &binds,
            &push,
            frame.tiles.live_threads(),
        )
    }
}
