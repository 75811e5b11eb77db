//! ReSTIR DI's first pass (`shaders/passes/resample_temporal.comp`): initial candidates, the
//! chosen one's visibility, and the previous frame's reservoir reprojected into this frame's.

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

pub struct Temporal;

impl Kernel for Temporal {
    const SHADER: &'static str = "passes/resample_temporal";
    type Push = ResampleTemporalPush;
}

impl Pass<Temporal> {
    /// Reads `history` (last frame's reservoirs, unless `frame.previous` is `None` or
    /// `fresh_start`) and writes `fresh` for every texel of the grid.
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        frame: &GridFrame,
        (scene, ray_counters, primary_hit): (&GpuScene, &Buffer, &Image),
        (history, fresh, fresh_start): (&Buffer, &Buffer, bool),
        settings: &ResamplingSettings,
    ) -> Result<()> {
        let g = frame.gbuffer;
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
        );
        let current = &frame.current;
        let previous = frame.previous.filter(|_| !fresh_start);
        let p = previous.as_ref().unwrap_or(current);
        let push = ResampleTemporalPush {
            space: *current,
            prev: p.frame(),
            params: Vec4::new(
                settings.candidates as f32,
                settings.temporal_cap,
                if previous.is_none() { 1.0 } else { 0.0 },
                0.0,
            ),
        };
        let size = g.size;
        self.dispatch(rec, "resample_temporal", &binds, &push, [size.x, size.y, 1])
    }
}
