//! The path-tracing pass: one sample per sampling-grid texel, writing the per-sample G-buffer.
//! Its `*_gradients` kernel variants also re-shade A-SVGF's gradient samples (denoise/asvgf).

use super::grid::{GBuffer, GradientTargets, TileList};
use super::push_bytes;
use super::trace_clear::TraceClearPass;
use crate::error::Result;
use crate::gpu_scene::GpuScene;
use crate::graph::{read_buffer, read_texels, write_buffer, write_image, FrameRecorder};
use crate::layouts::TracePush;
use crate::vk::{Buffer, ComputePipeline, Context};
use glam::UVec4;
use std::sync::Arc;

pub struct TracePass {
    pipeline: std::sync::Arc<ComputePipeline>,
    clear: TraceClearPass,
}

/// Counters the trace kernel fills (one u32 each): primary, shadow and continuation rays, and
/// traced samples whose screen position lies off the screen, samples culled off the screen.
pub const RAY_COUNTERS: usize = 5;

impl TracePass {
    pub fn new(ctx: &Arc<Context>, sampling_variant: &str) -> Result<TracePass> {
        let shader = format!("passes/trace.{sampling_variant}");
        Ok(TracePass {
            pipeline: ComputePipeline::shared(
                ctx,
                &shader,
                std::mem::size_of::<TracePush>() as u32,
            )?,
            clear: TraceClearPass::new(ctx)?,
        })
    }

    /// Records one sample per grid texel. `sample_index` decorrelates several samples of one
    /// frame (reference accumulation); real-time frames use 0. `sampling_table` holds the space's
    /// `SamplingSpace::sampling_table` (Visual-Polar: its per-column arcs). `gradients`: A-SVGF's,
    /// for the `*_gradients` variants (which also write `out.visibility`). Only `tiles`' live tiles
    /// are traced; its idle ones are cleared to "not traced".
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        scene: &GpuScene,
        frame: &Buffer,
        sampling: &Buffer,
        sampling_table: &Buffer,
        ray_counters: &Buffer,
        out: &GBuffer,
        tiles: &TileList,
        sample_index: u32,
        gradients: Option<GradientTargets>,
    ) -> Result<()> {
        // The idle tiles hold the same not-traced values for every sample of a frame (or of a
        // reference): cleared, and their culled samples counted, with the first.
        if sample_index == 0 {
            self.clear.record(rec, tiles, ray_counters, out)?;
        }
        if tiles.live == 0 {
            return Ok(());
        }
        let s = scene.binds();
        // A fixed array sliced to what this kernel binds: no host allocation per frame.
        let gradient_binds = match (gradients, &out.visibility) {
            (Some(g), Some(visibility)) => Some([
                write_buffer("gradient_samples", g.samples),
                write_image("out_gradient", g.gradient),
                write_image("out_visibility", visibility),
            ]),
            _ => None,
        };
        let extra = gradient_binds.unwrap_or([s[0]; 3]);
        let g = out.write_binds();
        let binds = [
            s[0],
            s[1],
            s[2],
            s[3],
            s[4],
            s[5],
            s[6],
            s[7],
            s[8],
            s[9],
            read_buffer("frame", frame),
            read_buffer("sampling", sampling),
            read_texels("sampling_table", sampling_table),
            write_buffer("ray_counters", ray_counters),
            g[0],
            g[1],
            g[2],
            g[3],
            g[4],
            g[5],
            g[6],
            read_buffer("tiles", tiles.buffer),
            extra[0],
            extra[1],
            extra[2],
        ];
        let binds = &binds[..if gradient_binds.is_some() {
            binds.len()
        } else {
            binds.len() - 3
        }];
        // y = 0: the cameras' column base, a value lavapipe cannot fold (see trace.comp).
        let push = TracePush {
            config: UVec4::new(sample_index, 0, 0, 0),
        };
        rec.dispatch(
            "trace",
            &self.pipeline,
            binds,
            push_bytes(&push),
            tiles.live_threads(),
        )
    }
}
