//! The path-tracing pass: one sample per sampling-grid texel, writing the per-sample G-buffer.
//! Its `*_gradients` kernel variants also re-shade A-SVGF's gradient samples (denoise/asvgf), its
//! `*_resampled` variants leave the primary hit's direct light to the resampling passes, its
//! `*_resampled_gi` variants its bounce too.

use super::grid::{GradientTargets, GridFrame};
use super::trace_clear::TraceClearPass;
use super::{Kernel, Pass};
use crate::error::Result;
use crate::gpu_scene::scene_then;
use crate::gpu_scene::GpuScene;
use crate::graph::{read_buffer, read_texels, write_buffer, write_image, FrameRecorder};
use crate::layouts::TracePush;
use crate::vk::{Buffer, Context};
use glam::UVec4;
use std::sync::Arc;

/// The trace kernel (`shaders/passes/trace.comp`, a variant per trace space).
pub struct Trace;

impl Kernel for Trace {
    const SHADER: &'static str = "passes/trace";
    type Push = TracePush;
}

pub struct TracePass {
    trace: Pass<Trace>,
    clear: TraceClearPass,
}

/// Counters the trace kernel fills (one u32 each): primary, shadow and continuation rays, and
/// traced samples whose screen position lies off the screen, samples culled off the screen.
pub const RAY_COUNTERS: usize = 5;

impl TracePass {
    /// `trace_variant`: the space's (`SamplingSpace::trace_variant`).
    pub fn new(ctx: &Arc<Context>, trace_variant: &str) -> Result<TracePass> {
        Ok(TracePass {
            trace: Pass::new(ctx, trace_variant)?,
            clear: TraceClearPass::new(ctx)?,
        })
    }

    /// Records one sample per grid texel into `frame.gbuffer`, counting rays in `ray_counters`.
    /// `sample_index` decorrelates several samples of one frame (reference accumulation);
    /// real-time frames use 0. `gradients`: A-SVGF's, for the `*_gradients` variants (which also
    /// write the G-buffer's visibility). Only the frame's live tiles are traced; its idle ones
    /// are cleared to "not traced".
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        frame: &GridFrame,
        scene: &GpuScene,
        ray_counters: &Buffer,
        sample_index: u32,
        gradients: Option<GradientTargets>,
    ) -> Result<()> {
        let (out, tiles) = (frame.gbuffer, &frame.tiles);
        // The idle tiles hold the same not-traced values for every sample of a frame (or of a
        // reference): cleared, and their culled samples counted, with the first.
        if sample_index == 0 {
            self.clear.record(rec, tiles, ray_counters, out)?;
        }
        if tiles.live == 0 {
            return Ok(());
        }
        let s = scene.binds();
        // A fixed array sliced to what this kernel binds: no host allocation per frame. The
        // `*_gradients` variants write A-SVGF's gradient samples and visibility, the `*_resampled`
        // variants the primary hit (the G-buffer has its image only then), the `*_resampled_gi`
        // variants also the bounce's sample (ReSTIR GI); a variant may do all three.
        let mut extra = [s.bvh_nodes; 5];
        let mut extra_count = 0;
        let mut bind = |b| {
            extra[extra_count] = b;
            extra_count += 1;
        };
        if let (Some(g), Some(visibility)) = (gradients, &out.visibility) {
            bind(write_buffer("gradient_samples", g.samples));
            bind(write_image("out_gradient", g.gradient));
            bind(write_image("out_visibility", visibility));
        }
        if let Some(h) = &out.primary_hit {
            bind(write_image("out_primary_hit", h));
        }
        if let Some(b) = &out.gi_samples {
            bind(write_buffer("out_gi_samples", b));
        }
        let g = out.write_binds();
        let binds = scene_then!(s;
            read_buffer("frame", frame.frame_data),
            read_buffer("sampling", frame.sampling),
            read_texels("sampling_table", frame.sampling_table),
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
            extra[3],
            extra[4],
        );
        let binds = &binds[..binds.len() - extra.len() + extra_count];
        // y = 0: the cameras' column base, a value lavapipe cannot fold (see trace.comp).
        let push = TracePush {
            config: UVec4::new(sample_index, 0, 0, 0),
        };
        self.trace
            .dispatch(rec, "trace", binds, &push, tiles.live_threads())
    }
}
