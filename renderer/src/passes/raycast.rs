//! Traces an arbitrary list of rays: BVH correctness tests and ray-throughput benchmarks, and
//! (the `counters` variant) what each ray's traversal read.

use super::{Kernel, Pass};
use crate::error::Result;
use crate::gpu_scene::GpuScene;
use crate::graph::{read_buffer, read_texels, write_buffer, FrameRecorder};
use crate::layouts::RaycastPush;
use crate::traversal::Traversal;
use crate::vk::{Buffer, Context};
use glam::UVec4;
use std::sync::Arc;

pub struct Raycast;

impl Kernel for Raycast {
    const SHADER: &'static str = "passes/raycast";
    type Push = RaycastPush;
}

/// What one ray's traversal read (the `counters` variant; `shaders/common/bvh.glsl`'s
/// BVH_COUNTERS): nodes opened, leaf triangles tested, alpha tests and bytes of node + triangle
/// (+ instance) data.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct RayCounts {
    pub nodes: u32,
    pub triangles: u32,
    pub alpha_tests: u32,
    pub bytes: u32,
}

/// A list of rays and where their hits go.
pub struct RayBatch<'a> {
    /// `count` RayGpu behind an RGBA32F texel view (`Buffer::device_texels`: texel reads are far
    /// cheaper than std430 reads on lavapipe).
    pub rays: &'a Buffer,
    /// Receives `count` HitGpu.
    pub hits: &'a Buffer,
    /// Receives `count` [`RayCounts`] (the counting kernel), or `None` (the plain one).
    pub counts: Option<&'a Buffer>,
    pub count: u32,
}

/// The raycast kernels: `hits` and `counters`, each for the traversal of the scene it traces
/// (built on first use).
pub struct RaycastPass {
    ctx: Arc<Context>,
    passes: Vec<(Traversal, bool, Pass<Raycast>)>,
}

impl RaycastPass {
    pub fn new(ctx: &Arc<Context>) -> RaycastPass {
        RaycastPass {
            ctx: ctx.clone(),
            passes: Vec::new(),
        }
    }

    fn pass(&mut self, traversal: Traversal, counted: bool) -> Result<&Pass<Raycast>> {
        let at = match self
            .passes
            .iter()
            .position(|(t, c, _)| *t == traversal && *c == counted)
        {
            Some(at) => at,
            None => {
                let variant = if counted { "counters" } else { "hits" };
                let pass = Pass::for_traversal(&self.ctx, variant, traversal)?;
                self.passes.push((traversal, counted, pass));
                self.passes.len() - 1
            }
        };
        Ok(&self.passes[at].2)
    }

    /// Traces `batch` with the kernel of `scene`'s traversal; `any_hit` stops at the first hit
    /// found (shadow rays). The pass is named `raycast_any` or `raycast_closest` in the timings
    /// (`_counted` with counts).
    pub fn record(
        &mut self,
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
            write_buffer("counts", batch.counts.unwrap_or(batch.hits)),
        ];
        // The plain kernel declares no `counts`: its bind is left off.
        let binds = &binds[..if batch.counts.is_some() { 13 } else { 12 }];
        let push = RaycastPush {
            config: UVec4::new(batch.count, any_hit as u32, 0, 0),
        };
        let name = match (any_hit, batch.counts.is_some()) {
            (false, false) => "raycast_closest",
            (true, false) => "raycast_any",
            (false, true) => "raycast_closest_counted",
            (true, true) => "raycast_any_counted",
        };
        self.pass(scene.traversal, batch.counts.is_some())?
            .dispatch(rec, name, binds, &push, [batch.count, 1, 1])
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
    counts: Option<Buffer>,
    recorder: crate::graph::FrameRecorder,
}

impl RayCaster {
    pub fn new(ctx: &Arc<Context>) -> Result<RayCaster> {
        let uniform = ash::vk::BufferUsageFlags::UNIFORM_BUFFER;
        Ok(RayCaster {
            ctx: ctx.clone(),
            pass: RaycastPass::new(ctx),
            frame: Buffer::with_data(
                ctx,
                "frame",
                &[crate::layouts::FrameData::default()],
                uniform,
            )?,
            rays: None,
            hits: None,
            counts: None,
            recorder: crate::graph::FrameRecorder::new(ctx, 4)?,
        })
    }

    /// Traces `rays` (closest hit, or any hit for shadow rays) with the traversal `scene` was
    /// uploaded for; returns the hits and GPU ms. Rays and hits live in device-local memory,
    /// copied in and out outside the timed pass: on a discrete GPU the pass would otherwise time
    /// the bus, not the traversal. Alpha-masked scenes are traced with their alpha tests, as the
    /// renderer traces them.
    pub fn trace(
        &mut self,
        scene: &GpuScene,
        rays: &[crate::layouts::RayGpu],
        any_hit: bool,
    ) -> Result<(Vec<crate::layouts::HitGpu>, f64)> {
        self.run(scene, rays, any_hit, false)
            .map(|(hits, _, ms)| (hits, ms))
    }

    /// [`RayCaster::trace`] with the counting kernel: the hits and what each ray's traversal
    /// read (not timed: counting costs time).
    pub fn trace_counted(
        &mut self,
        scene: &GpuScene,
        rays: &[crate::layouts::RayGpu],
        any_hit: bool,
    ) -> Result<(Vec<crate::layouts::HitGpu>, Vec<RayCounts>)> {
        self.run(scene, rays, any_hit, true)
            .map(|(hits, counts, _)| (hits, counts))
    }

    fn run(
        &mut self,
        scene: &GpuScene,
        rays: &[crate::layouts::RayGpu],
        any_hit: bool,
        counted: bool,
    ) -> Result<(Vec<crate::layouts::HitGpu>, Vec<RayCounts>, f64)> {
        use gpu_allocator::MemoryLocation;
        let usage =
            ash::vk::BufferUsageFlags::STORAGE_BUFFER | ash::vk::BufferUsageFlags::TRANSFER_SRC;
        let ray_bytes = (std::mem::size_of_val(rays) as u64).max(16);
        let hit_bytes = (rays.len() * std::mem::size_of::<crate::layouts::HitGpu>()) as u64;
        let count_bytes = (rays.len() * std::mem::size_of::<RayCounts>()) as u64;
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
        if counted && self.counts.as_ref().is_none_or(|b| b.size < count_bytes) {
            self.counts = Some(Buffer::new(
                &self.ctx,
                "ray_counts",
                count_bytes.max(16),
                usage,
                MemoryLocation::GpuOnly,
            )?);
        }
        let (ray_buf, hit_buf) = (self.rays.as_ref().unwrap(), self.hits.as_ref().unwrap());
        // The instance level's slots are the scene's, and so is the alpha-test flag; everything
        // else in the frame stays default.
        let flags = if scene.alpha_masked {
            crate::layouts::FRAME_FLAG_ALPHA_MASK
        } else {
            0
        };
        self.frame.write(&[crate::layouts::FrameData {
            instancing: scene.instancing_slots,
            frame: UVec4::new(0, 0, 0, flags),
            ..Default::default()
        }])?;
        self.recorder.begin()?;
        let batch = RayBatch {
            rays: ray_buf,
            hits: hit_buf,
            counts: if counted { self.counts.as_ref() } else { None },
            count: rays.len() as u32,
        };
        self.pass
            .record(&mut self.recorder, scene, &self.frame, &batch, any_hit)?;
        let ms = self.recorder.submit_and_wait()?.iter().map(|t| t.ms).sum();
        let mut hits = vec![crate::layouts::HitGpu::default(); rays.len()];
        hit_buf.download(&mut hits)?;
        let mut counts = Vec::new();
        if counted {
            counts = vec![RayCounts::default(); rays.len()];
            self.counts.as_ref().unwrap().download(&mut counts)?;
        }
        Ok((hits, counts, ms))
    }
}
