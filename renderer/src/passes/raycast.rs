//! Traces an arbitrary list of rays: BVH correctness tests and ray-throughput benchmarks.

use super::{Kernel, Pass};
use crate::error::Result;
use crate::gpu_scene::GpuScene;
use crate::graph::{read_buffer, read_texels, write_buffer, FrameRecorder};
use crate::layouts::RaycastPush;
use crate::vk::{Buffer, Context};
use glam::UVec4;
use std::sync::Arc;

pub struct Raycast;

impl Kernel for Raycast {
    const SHADER: &'static str = "passes/raycast";
    type Push = RaycastPush;
}

pub type RaycastPass = Pass<Raycast>;

/// A list of rays and where their hits go.
pub struct RayBatch<'a> {
    /// `count` RayGpu behind an RGBA32F texel view (`Buffer::device_texels`: texel reads are far
    /// cheaper than std430 reads on lavapipe).
    pub rays: &'a Buffer,
    /// Receives `count` HitGpu.
    pub hits: &'a Buffer,
    pub count: u32,
}

impl Pass<Raycast> {
    /// Traces `batch`; `any_hit` stops at the first hit found (shadow rays). The pass is named
    /// `raycast_any` or `raycast_closest` in the timings.
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        scene: &GpuScene,
        frame: &Buffer,
        batch: &RayBatch,
        any_hit: bool,
    ) -> Result<()> {
        let s = scene.binds();
        let binds = [
            s.bvh_nodes,
            s.bvh_triangles,
            s.vertices,
            s.triangles,
            s.materials,
            s.textures,
            s.texels,
            s.lights,
            s.instances,
            read_buffer("frame", frame),
            read_texels("rays", batch.rays),
            write_buffer("hits", batch.hits),
        ];
        let push = RaycastPush {
            config: UVec4::new(batch.count, any_hit as u32, 0, 0),
        };
        let name = if any_hit {
            "raycast_any"
        } else {
            "raycast_closest"
        };
        self.dispatch(rec, name, &binds, &push, [batch.count, 1, 1])
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
            pass: Pass::single(ctx)?,
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
        let batch = RayBatch {
            rays: ray_buf,
            hits: hit_buf,
            count: rays.len() as u32,
        };
        self.pass
            .record(&mut self.recorder, scene, &self.frame, &batch, any_hit)?;
        let ms = self.recorder.submit_and_wait()?.iter().map(|t| t.ms).sum();
        let mut hits = vec![crate::layouts::HitGpu::default(); rays.len()];
        hit_buf.download(&mut hits)?;
        Ok((hits, ms))
    }
}
