//! The spatial passes (`shaders/passes/resample_spatial.comp` for ReSTIR DI,
//! `resample_gi_spatial.comp` for GI): grid neighbours' reservoirs combined, one visibility ray
//! to the chosen sample, its light added to the G-buffer's colour and demodulated radiance. Both
//! bind the same resources under the same names.

use super::settings::ResamplingSettings;
use crate::error::Result;
use crate::gpu_scene::scene_then;
use crate::gpu_scene::GpuScene;
use crate::graph::{
    read_buffer, read_image, read_texels, write_buffer, write_image, FrameRecorder,
};
use crate::layouts::ResampleSpatialPush;
use crate::passes::grid::GridFrame;
use crate::passes::{Kernel, Pass};
use crate::vk::{Buffer, Image};
use glam::Vec4;

/// ReSTIR DI's: light points.
pub struct Spatial;

impl Kernel for Spatial {
    const SHADER: &'static str = "passes/resample_spatial";
    type Push = ResampleSpatialPush;
}

/// ReSTIR GI's: secondary hits, reconnected.
pub struct GiSpatial;

impl Kernel for GiSpatial {
    const SHADER: &'static str = "passes/resample_gi_spatial";
    type Push = ResampleSpatialPush;
}

impl<K: Kernel<Push = ResampleSpatialPush>> Pass<K> {
    /// Reads this frame's reservoirs (`fresh`) and adds their light to `frame.gbuffer`'s colour
    /// and radiance, for every texel of the grid.
    pub fn record_spatial(
        &self,
        rec: &mut FrameRecorder,
        frame: &GridFrame,
        (scene, ray_counters, primary_hit): (&GpuScene, &Buffer, &Image),
        fresh: &Buffer,
        settings: &ResamplingSettings,
    ) -> Result<()> {
        let g = frame.gbuffer;
        let binds = scene_then!(scene.binds();
            read_buffer("frame", frame.frame_data),
            write_image("color", &g.color),
            write_image("radiance", &g.radiance),
            read_image("normal_depth", &g.normal_depth),
            read_image("position", &g.position),
            read_image("ids", &g.ids),
            read_image("primary_hit", primary_hit),
            read_buffer("fresh", fresh),
            write_buffer("ray_counters", ray_counters),
            read_texels("grid_columns", frame.sampling_table),
        );
        let push = ResampleSpatialPush {
            space: frame.current,
            params: Vec4::new(settings.neighbours as f32, settings.radius, 0.0, 0.0),
        };
        let size = g.size;
        let name = K::SHADER.trim_start_matches("passes/");
        self.dispatch(rec, name, &binds, &push, [size.x, size.y, 1])
    }
}
