//! Traces an arbitrary list of rays: BVH correctness tests and ray-throughput benchmarks.

use super::push_bytes;
use crate::error::Result;
use crate::gpu_scene::GpuScene;
use crate::graph::{read_buffer, write_buffer, FrameRecorder};
use crate::layouts::RaycastPush;
use crate::vk::{Buffer, ComputePipeline, Context};
use glam::UVec4;
use std::sync::Arc;

pub struct RaycastPass {
    pipeline: ComputePipeline,
}

impl RaycastPass {
    pub fn new(ctx: &Arc<Context>) -> Result<RaycastPass> {
        Ok(RaycastPass { pipeline: ComputePipeline::new(ctx, "passes/raycast", std::mem::size_of::<RaycastPush>() as u32)? })
    }

    /// `rays` holds `count` RayGpu; `hits` receives `count` HitGpu. `any_hit` stops at the first
    /// hit found (shadow rays).
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        pass_name: &'static str,
        scene: &GpuScene,
        frame: &Buffer,
        rays: &Buffer,
        hits: &Buffer,
        count: u32,
        any_hit: bool,
    ) -> Result<()> {
        let s = scene.binds();
        let binds = [
            s[0], s[1], s[2], s[3], s[4], s[5], s[6], s[7],
            read_buffer("frame", frame),
            read_buffer("rays", rays),
            write_buffer("hits", hits),
        ];
        let push = RaycastPush { config: UVec4::new(count, any_hit as u32, 0, 0) };
        rec.dispatch(pass_name, &self.pipeline, &binds, push_bytes(&push), [count, 1, 1])
    }
}
