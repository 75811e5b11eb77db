//! Traces an arbitrary list of rays: BVH correctness tests and ray-throughput benchmarks.

use super::push_bytes;
use crate::error::Result;
use crate::gpu_scene::GpuScene;
use crate::graph::{read_buffer, read_texels, write_buffer, FrameRecorder};
use crate::layouts::RaycastPush;
use crate::vk::{Buffer, ComputePipeline, Context};
use glam::UVec4;
use std::sync::Arc;

pub struct RaycastPass {
    pipeline: std::sync::Arc<ComputePipeline>,
}

impl RaycastPass {
    pub fn new(ctx: &Arc<Context>) -> Result<RaycastPass> {
        Ok(RaycastPass {
            pipeline: ComputePipeline::shared(
                ctx,
                "passes/raycast",
                std::mem::size_of::<RaycastPush>() as u32,
            )?,
        })
    }

    /// `rays` holds `count` RayGpu behind an RGBA32F texel view (`Buffer::device_texels`: texel
    /// reads are far cheaper than std430 reads on lavapipe); `hits` receives `count` HitGpu. `any_hit` stops at the first
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
            s[0],
            s[1],
            s[2],
            s[3],
            s[4],
            s[5],
            s[6],
            s[7],
            s[9],
            read_buffer("frame", frame),
            read_texels("rays", rays),
            write_buffer("hits", hits),
        ];
        let push = RaycastPush {
            config: UVec4::new(count, any_hit as u32, 0, 0),
        };
        rec.dispatch(
            pass_name,
            &self.pipeline,
            &binds,
            push_bytes(&push),
            [count, 1, 1],
        )
    }
}

/// Runs ray lists through the raycast pass outside a frame: owns the ray/hit buffers (grown as
/// needed) and reports the GPU time of the traversal alone.
pub struct RayCaster {
    ctx: Arc<Context>,
    pass: RaycastPass,
    frame: Buffer,
    rays: Option<Buffer>,
    hits: Option<Buffer>,
    recorder: crate::graph::FrameRecorder,
}

impl RayCaster {
    pub fn new(ctx: &Arc<Context>) -> Result<RayCaster> {
        let uniform = ash::vk::BufferUsageFlags::UNIFORM_BUFFER;
        Ok(RayCaster {
            ctx: ctx.clone(),
            pass: RaycastPass::new(ctx)?,
            frame: Buffer::with_data(
                ctx,
                "frame",
                &[crate::layouts::FrameData::default()],
                uniform,
            )?,
            rays: None,
            hits: None,
            recorder: crate::graph::FrameRecorder::new(ctx, 4)?,
        })
    }

    /// Traces `rays` (closest hit, or any hit for shadow rays); returns the hits and GPU ms.
    /// Rays and hits live in device-local memory, copied in and out outside the timed pass: on a
    /// discrete GPU the pass would otherwise time the bus, not the traversal.
    pub fn trace(
        &mut self,
        scene: &GpuScene,
        rays: &[crate::layouts::RayGpu],
        any_hit: bool,
    ) -> Result<(Vec<crate::layouts::HitGpu>, f64)> {
        use gpu_allocator::MemoryLocation;
        let usage =
            ash::vk::BufferUsageFlags::STORAGE_BUFFER | ash::vk::BufferUsageFlags::TRANSFER_SRC;
        let ray_bytes = (std::mem::size_of_val(rays) as u64).max(16);
        let hit_bytes = (rays.len() * std::mem::size_of::<crate::layouts::HitGpu>()) as u64;
        if self.rays.as_ref().is_none_or(|b| b.size < ray_bytes) {
            self.rays = Some(Buffer::device_texels(
                &self.ctx,
                "rays",
                bytemuck::cast_slice(rays),
            )?);
            self.hits = Some(Buffer::new(
                &self.ctx,
                "hits",
                hit_bytes.max(32),
                usage,
                MemoryLocation::GpuOnly,
            )?);
        } else {
            self.rays.as_ref().unwrap().upload(rays)?;
        }
        let (ray_buf, hit_buf) = (self.rays.as_ref().unwrap(), self.hits.as_ref().unwrap());
        // The instance level's slots are the scene's; everything else in the frame stays default.
        self.frame.write(&[crate::layouts::FrameData {
            instancing: scene.instancing_slots,
            ..Default::default()
        }])?;
        self.recorder.begin()?;
        let name = if any_hit {
            "raycast_any"
        } else {
            "raycast_closest"
        };
        self.pass.record(
            &mut self.recorder,
            name,
            scene,
            &self.frame,
            ray_buf,
            hit_buf,
            rays.len() as u32,
            any_hit,
        )?;
        let ms = self.recorder.submit_and_wait()?.iter().map(|t| t.ms).sum();
        let mut hits = vec![crate::layouts::HitGpu::default(); rays.len()];
        hit_buf.download(&mut hits)?;
        Ok((hits, ms))
    }
}
