//! The temporal passes (`shaders/passes/resample_temporal.comp` for ReSTIR DI,
//! `resample_gi_temporal.comp` for GI): this frame's candidates (DI: light candidates drawn here;
//! GI: the tracer's bounce) and the previous frame's reservoir reprojected into this frame's.
//! Both bind the same resources under the same names, GI the tracer's bounce samples besides.

use super::settings::ResamplingSettings;
use crate::error::Result;
use crate::gpu_scene::scene_then;
use crate::gpu_scene::GpuScene;
use crate::graph::{read_buffer, read_image, read_texels, write_buffer, FrameRecorder};
use crate::layouts::ResampleTemporalPush;
use crate::passes::grid::GridFrame;
use crate::passes::{Kernel, Pass};
use crate::vk::{Buffer, Image};
use glam::Vec4;

/// ReSTIR DI's: `candidates` light points per texel.
pub struct Temporal;

impl Kernel for Temporal {
    const SHADER: &'static str = "passes/resample_temporal";
    type Push = ResampleTemporalPush;
}

/// ReSTIR GI's: the traced bounce, one candidate per texel.
pub struct GiTemporal;

impl Kernel for GiTemporal {
    const SHADER: &'static str = "passes/resample_gi_temporal";
    type Push = ResampleTemporalPush;
}

/// This frame's candidates: drawn by the pass (DI) or the tracer's bounce samples (GI).
pub enum Candidates<'a> {
    Drawn(u32),
    Traced(&'a Buffer),
}

impl<K: Kernel<Push = ResampleTemporalPush>> Pass<K> {
    /// Reads `history` (last frame's reservoirs, unless `frame.previous` is `None` or
    /// `fresh_start`) and writes `fresh` for every texel of the grid.
    pub fn record_temporal(
        &self,
        rec: &mut FrameRecorder,
        frame: &GridFrame,
        (scene, ray_counters, primary_hit): (&GpuScene, &Buffer, &Image),
        (candidates, history, fresh, fresh_start): (Candidates, &Buffer, &Buffer, bool),
        settings: &ResamplingSettings,
    ) -> Result<()> {
        let g = frame.gbuffer;
        let (count, traced) = match candidates {
            Candidates::Drawn(n) => (n, None),
            Candidates::Traced(samples) => (1, Some(read_buffer("gi_samples", samples))),
        };
        let binds = scene_then!(scene.binds();
            read_buffer("frame", frame.frame_data),
            read_image("normal_depth", &g.normal_depth),
            read_image("position", &g.position),
            read_image("ids", &g.ids),
            read_image("motion", &g.motion),
            read_image("primary_hit", primary_hit),
            read_buffer("history", history),
            write_buffer("fresh", fresh),
            write_buffer("ray_counters", ray_counters),
            read_texels("grid_columns", frame.sampling_table),
            traced.unwrap_or(read_buffer("history", history)),
        );
        // DI binds no bounce samples: the last entry is left off.
        let binds = &binds[..binds.len() - usize::from(traced.is_none())];
        let current = &frame.current;
        let previous = frame.previous.filter(|_| !fresh_start);
        let p = previous.as_ref().unwrap_or(current);
        // The previous reservoir's M is capped at temporal_cap × this frame's candidates.
        let push = ResampleTemporalPush {
            space: *current,
            prev: p.frame(),
            params: Vec4::new(
                count as f32,
                settings.temporal_cap,
                if previous.is_none() { 1.0 } else { 0.0 },
                0.0,
            ),
        };
        let size = g.size;
        let name = K::SHADER.trim_start_matches("passes/");
        self.dispatch(rec, name, binds, &push, [size.x, size.y, 1])
    }
}
