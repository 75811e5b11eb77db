//! Records one frame: a sequence of compute passes whose resource accesses are declared at bind
//! time, so barriers are derived here instead of being written at each call site. Every pass is
//! wrapped in a debug label and a pair of GPU timestamps.
//!
//! All passes are compute (plus copies), all images stay in GENERAL layout, so a hazard needs only
//! a global memory barrier: read-after-write, write-after-write and write-after-read are detected
//! per resource since the last barrier. Images the engine does not own (a swapchain's) are
//! `External`: their layout transitions in and out are declared with `acquire_external` and
//! `release_external`.
//!
//! A recorder is one frame slot: `submit` returns at once, `wait` blocks on the slot's fence and
//! reads its timestamps. A frame's command buffer starts with a barrier against everything
//! submitted before it, so frames in flight that share history images are ordered on the GPU.

use crate::error::{Error, Result};
use crate::vk::{Buffer, ComputePipeline, Context, Image, ResourceId};
use ash::vk;
use std::sync::Arc;

const MAX_BINDINGS: usize = 32;

#[derive(Clone, Copy)]
pub enum Resource<'a> {
    Buffer(&'a Buffer),
    Texels(&'a Buffer),
    Image(&'a Image),
    External(&'a ExternalImage),
}

impl Resource<'_> {
    fn id(&self) -> ResourceId {
        match self {
            Resource::Buffer(b) | Resource::Texels(b) => b.id,
            Resource::Image(i) => i.id,
            Resource::External(e) => e.id,
        }
    }
}

/// An image the engine writes but does not own (a swapchain image): its handle, a view with
/// STORAGE usage, and the layouts it arrives in and must leave in.
#[derive(Clone, Copy, Debug)]
pub struct ExternalImage {
    pub raw: vk::Image,
    pub view: vk::ImageView,
    pub width: u32,
    pub height: u32,
    pub format: vk::Format,
    /// UNDEFINED for a freshly acquired swapchain image (its contents are overwritten).
    pub layout_before: vk::ImageLayout,
    /// PRESENT_SRC_KHR for a swapchain image.
    pub layout_after: vk::ImageLayout,
    pub id: ResourceId,
}

impl ExternalImage {
    /// Bytes of a tightly packed copy of the image (screenshots). `id` must be one per image,
    /// from `crate::vk::next_resource_id`.
    pub fn bytes(&self) -> u64 {
        self.width as u64 * self.height as u64 * crate::vk::format_bytes(self.format)
    }
}

/// One shader binding: its GLSL name, the resource, and whether the pass writes it.
#[derive(Clone, Copy)]
pub struct Bind<'a> {
    pub name: &'static str,
    pub resource: Resource<'a>,
    pub write: bool,
}

pub fn read_buffer<'a>(name: &'static str, b: &'a Buffer) -> Bind<'a> {
    Bind {
        name,
        resource: Resource::Buffer(b),
        write: false,
    }
}
pub fn write_buffer<'a>(name: &'static str, b: &'a Buffer) -> Bind<'a> {
    Bind {
        name,
        resource: Resource::Buffer(b),
        write: true,
    }
}
pub fn read_texels<'a>(name: &'static str, b: &'a Buffer) -> Bind<'a> {
    Bind {
        name,
        resource: Resource::Texels(b),
        write: false,
    }
}
pub fn read_image<'a>(name: &'static str, i: &'a Image) -> Bind<'a> {
    Bind {
        name,
        resource: Resource::Image(i),
        write: false,
    }
}
pub fn write_image<'a>(name: &'static str, i: &'a Image) -> Bind<'a> {
    Bind {
        name,
        resource: Resource::Image(i),
        write: true,
    }
}
pub fn write_external<'a>(name: &'static str, e: &'a ExternalImage) -> Bind<'a> {
    Bind {
        name,
        resource: Resource::External(e),
        write: true,
    }
}

/// GPU time of one pass of a completed frame.
#[derive(Clone, Copy, Debug)]
pub struct PassTiming {
    pub name: &'static str,
    /// The view (eye) the pass rendered; passes shared by all views count as view 0.
    pub view: u32,
    pub ms: f64,
}

/// Semaphores one submission waits on and signals (a swapchain's acquire and present).
#[derive(Clone, Copy, Default)]
pub struct SubmitSync<'a> {
    pub wait: &'a [(vk::Semaphore, vk::PipelineStageFlags)],
    pub signal: &'a [vk::Semaphore],
}

pub struct FrameRecorder {
    ctx: Arc<Context>,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    queries: vk::QueryPool,
    max_passes: u32,
    passes: Vec<(&'static str, u32)>,
    view: u32,
    read_since_barrier: Vec<ResourceId>,
    written_since_barrier: Vec<ResourceId>,
    timings: Vec<PassTiming>,
    recording: bool,
    /// Submitted and not yet waited for.
    in_flight: bool,
}

impl FrameRecorder {
    pub fn new(ctx: &Arc<Context>, max_passes: u32) -> Result<FrameRecorder> {
        let pool = *ctx.pool.lock().expect("command pool lock");
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        let cmd = unsafe { ctx.device.allocate_command_buffers(&alloc)? }[0];
        let fence = unsafe {
            ctx.device
                .create_fence(&vk::FenceCreateInfo::default(), None)?
        };
        let query_info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(max_passes * 2);
        let queries = unsafe { ctx.device.create_query_pool(&query_info, None)? };
        Ok(FrameRecorder {
            ctx: ctx.clone(),
            cmd,
            fence,
            queries,
            max_passes,
            passes: Vec::with_capacity(max_passes as usize),
            view: 0,
            read_since_barrier: Vec::with_capacity(64),
            written_since_barrier: Vec::with_capacity(64),
            timings: Vec::with_capacity(max_passes as usize),
            recording: false,
            in_flight: false,
        })
    }

    /// Starts recording; waits first if this slot's previous frame is still in flight.
    pub fn begin(&mut self) -> Result<()> {
        self.wait()?;
        let device = &self.ctx.device;
        unsafe {
            device.reset_command_buffer(self.cmd, vk::CommandBufferResetFlags::empty())?;
            let info = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            device.begin_command_buffer(self.cmd, &info)?;
            device.cmd_reset_query_pool(self.cmd, self.queries, 0, self.max_passes * 2);
            // Orders this frame after every earlier submission (frames in flight share history
            // images; a barrier's first scope covers all commands before it in submission order).
            let all = vk::AccessFlags::SHADER_READ
                | vk::AccessFlags::SHADER_WRITE
                | vk::AccessFlags::TRANSFER_READ
                | vk::AccessFlags::TRANSFER_WRITE;
            let stages = vk::PipelineStageFlags::COMPUTE_SHADER | vk::PipelineStageFlags::TRANSFER;
            let barrier = vk::MemoryBarrier::default()
                .src_access_mask(all)
                .dst_access_mask(all);
            device.cmd_pipeline_barrier(
                self.cmd,
                stages,
                stages,
                vk::DependencyFlags::empty(),
                &[barrier],
                &[],
                &[],
            );
        }
        self.passes.clear();
        self.view = 0;
        self.read_since_barrier.clear();
        self.written_since_barrier.clear();
        self.recording = true;
        Ok(())
    }

    /// The view the following passes render (their timings carry it).
    pub fn set_view(&mut self, view: u32) {
        self.view = view;
    }

    /// Whether a submitted frame has not been waited for yet.
    pub fn in_flight(&self) -> bool {
        self.in_flight
    }

    /// Moves an external image from its arrival layout to GENERAL before the passes write it.
    pub fn acquire_external(&mut self, image: &ExternalImage) {
        self.barrier_for([(image.id, true)].into_iter());
        let barrier = image_transition(
            image.raw,
            image.layout_before,
            vk::ImageLayout::GENERAL,
            vk::AccessFlags::empty(),
            vk::AccessFlags::SHADER_WRITE,
        );
        let stages = vk::PipelineStageFlags::COMPUTE_SHADER | vk::PipelineStageFlags::TRANSFER;
        unsafe {
            self.ctx.device.cmd_pipeline_barrier(
                self.cmd,
                stages,
                vk::PipelineStageFlags::COMPUTE_SHADER,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &[barrier],
            );
        }
        self.written_since_barrier.push(image.id);
    }

    /// Moves an external image to the layout it must leave in (PRESENT_SRC_KHR), after copying
    /// it into `copy_to` when given (a screenshot of exactly what is presented).
    pub fn release_external(
        &mut self,
        image: &ExternalImage,
        copy_to: Option<&Buffer>,
    ) -> Result<()> {
        let ctx = self.ctx.clone();
        let device = &ctx.device;
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let transfer = vk::PipelineStageFlags::TRANSFER;
        let mut from = vk::ImageLayout::GENERAL;
        let mut src_access = vk::AccessFlags::SHADER_WRITE;
        let mut src_stage = compute;
        if let Some(buffer) = copy_to {
            if buffer.size < image.bytes() {
                return Err(Error::Binding {
                    pass: "screenshot".into(),
                    reason: format!("buffer '{}' too small for the external image", buffer.name),
                });
            }
            self.barrier_for([(buffer.id, true)].into_iter());
            let index = self.open_pass("screenshot")?;
            let to_src = image_transition(
                image.raw,
                from,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                src_access,
                vk::AccessFlags::TRANSFER_READ,
            );
            let region = vk::BufferImageCopy::default()
                .image_subresource(vk::ImageSubresourceLayers {
                    aspect_mask: vk::ImageAspectFlags::COLOR,
                    mip_level: 0,
                    base_array_layer: 0,
                    layer_count: 1,
                })
                .image_extent(vk::Extent3D {
                    width: image.width,
                    height: image.height,
                    depth: 1,
                });
            unsafe {
                device.cmd_pipeline_barrier(
                    self.cmd,
                    compute,
                    transfer,
                    vk::DependencyFlags::empty(),
                    &[],
                    &[],
                    &[to_src],
                );
                device.cmd_copy_image_to_buffer(
                    self.cmd,
                    image.raw,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    buffer.raw,
                    &[region],
                );
            }
            self.close_pass(index);
            from = vk::ImageLayout::TRANSFER_SRC_OPTIMAL;
            src_access = vk::AccessFlags::TRANSFER_READ;
            src_stage = transfer;
        }
        // Presentation waits on a semaphore, which makes these writes visible: no dst access.
        let to_final = image_transition(
            image.raw,
            from,
            image.layout_after,
            src_access,
            vk::AccessFlags::empty(),
        );
        unsafe {
            device.cmd_pipeline_barrier(
                self.cmd,
                src_stage,
                vk::PipelineStageFlags::BOTTOM_OF_PIPE,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &[to_final],
            );
        }
        Ok(())
    }

    /// Records one compute dispatch covering `threads` invocations.
    pub fn dispatch(
        &mut self,
        pass: &'static str,
        pipeline: &ComputePipeline,
        binds: &[Bind],
        push: &[u8],
        threads: [u32; 3],
    ) -> Result<()> {
        self.check_bindings(pass, pipeline, binds, push)?;
        let used = |b: &&Bind| pipeline.bindings.iter().any(|x| x.name == b.name);
        self.barrier_for(
            binds
                .iter()
                .filter(used)
                .map(|b| (b.resource.id(), b.write)),
        );
        let index = self.open_pass(pass)?;
        let device = &self.ctx.device;

        let mut buffer_infos = [vk::DescriptorBufferInfo::default(); MAX_BINDINGS];
        let mut image_infos = [vk::DescriptorImageInfo::default(); MAX_BINDINGS];
        let mut views = [vk::BufferView::null(); MAX_BINDINGS];
        for (i, b) in binds.iter().enumerate() {
            match b.resource {
                Resource::Buffer(buf) => {
                    buffer_infos[i] = vk::DescriptorBufferInfo {
                        buffer: buf.raw,
                        offset: 0,
                        range: vk::WHOLE_SIZE,
                    }
                }
                Resource::Texels(buf) => views[i] = buf.texel_view.unwrap_or_default(),
                Resource::Image(img) => {
                    image_infos[i] = vk::DescriptorImageInfo {
                        sampler: vk::Sampler::null(),
                        image_view: img.view,
                        image_layout: vk::ImageLayout::GENERAL,
                    }
                }
                Resource::External(ext) => {
                    image_infos[i] = vk::DescriptorImageInfo {
                        sampler: vk::Sampler::null(),
                        image_view: ext.view,
                        image_layout: vk::ImageLayout::GENERAL,
                    }
                }
            }
        }
        let mut writes = [vk::WriteDescriptorSet::default(); MAX_BINDINGS];
        let mut count = 0;
        for (i, b) in binds.iter().enumerate() {
            let Some(info) = pipeline.bindings.iter().find(|x| x.name == b.name) else {
                continue;
            };
            let w = vk::WriteDescriptorSet::default()
                .dst_binding(info.binding)
                .descriptor_type(info.ty);
            writes[count] = match b.resource {
                Resource::Buffer(_) => w.buffer_info(std::slice::from_ref(&buffer_infos[i])),
                Resource::Texels(_) => w.texel_buffer_view(std::slice::from_ref(&views[i])),
                Resource::Image(_) | Resource::External(_) => {
                    w.image_info(std::slice::from_ref(&image_infos[i]))
                }
            };
            count += 1;
        }
        let groups = pipeline.groups_for(threads);
        unsafe {
            device.cmd_bind_pipeline(self.cmd, vk::PipelineBindPoint::COMPUTE, pipeline.raw);
            self.ctx.push_descriptor.cmd_push_descriptor_set(
                self.cmd,
                vk::PipelineBindPoint::COMPUTE,
                pipeline.layout,
                0,
                &writes[..count],
            );
            if !push.is_empty() {
                device.cmd_push_constants(
                    self.cmd,
                    pipeline.layout,
                    vk::ShaderStageFlags::COMPUTE,
                    0,
                    push,
                );
            }
            device.cmd_dispatch(self.cmd, groups[0], groups[1], groups[2]);
        }
        self.close_pass(index);
        Ok(())
    }

    /// Fills a buffer with a 32-bit value (clearing counters).
    pub fn fill_buffer(&mut self, pass: &'static str, buffer: &Buffer, value: u32) -> Result<()> {
        self.barrier_for([(buffer.id, true)].into_iter());
        let index = self.open_pass(pass)?;
        unsafe {
            self.ctx
                .device
                .cmd_fill_buffer(self.cmd, buffer.raw, 0, vk::WHOLE_SIZE, value)
        };
        self.close_pass(index);
        Ok(())
    }

    /// Copies an image into a host-visible buffer (tightly packed rows) for read-back.
    pub fn copy_image_to_buffer(
        &mut self,
        pass: &'static str,
        image: &Image,
        buffer: &Buffer,
    ) -> Result<()> {
        self.copy_between(pass, image, buffer, false)
    }

    /// Fills an image from a buffer of tightly packed rows (test inputs, uploads).
    pub fn copy_buffer_to_image(
        &mut self,
        pass: &'static str,
        buffer: &Buffer,
        image: &Image,
    ) -> Result<()> {
        self.copy_between(pass, image, buffer, true)
    }

    fn copy_between(
        &mut self,
        pass: &'static str,
        image: &Image,
        buffer: &Buffer,
        to_image: bool,
    ) -> Result<()> {
        if buffer.size < image.width as u64 * image.height as u64 * image.texel_bytes() {
            return Err(Error::Binding {
                pass: pass.into(),
                reason: format!(
                    "buffer '{}' too small for image '{}'",
                    buffer.name, image.name
                ),
            });
        }
        self.barrier_for([(image.id, to_image), (buffer.id, !to_image)].into_iter());
        let index = self.open_pass(pass)?;
        let region = vk::BufferImageCopy::default()
            .image_subresource(vk::ImageSubresourceLayers {
                aspect_mask: vk::ImageAspectFlags::COLOR,
                mip_level: 0,
                base_array_layer: 0,
                layer_count: 1,
            })
            .image_extent(vk::Extent3D {
                width: image.width,
                height: image.height,
                depth: 1,
            });
        // Copies prefer the TRANSFER_*_OPTIMAL layouts (the validation layer warns otherwise):
        // switch for the copy and back to GENERAL, the layout every pass expects.
        let (layout, access) = if to_image {
            (
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                vk::AccessFlags::TRANSFER_WRITE,
            )
        } else {
            (
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                vk::AccessFlags::TRANSFER_READ,
            )
        };
        let transition = |from, to, src, dst| image_transition(image.raw, from, to, src, dst);
        let stages = vk::PipelineStageFlags::COMPUTE_SHADER | vk::PipelineStageFlags::TRANSFER;
        let any = vk::AccessFlags::SHADER_READ
            | vk::AccessFlags::SHADER_WRITE
            | vk::AccessFlags::TRANSFER_WRITE;
        let device = &self.ctx.device;
        unsafe {
            let enter = transition(vk::ImageLayout::GENERAL, layout, any, access);
            device.cmd_pipeline_barrier(
                self.cmd,
                stages,
                stages,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &[enter],
            );
            if to_image {
                device.cmd_copy_buffer_to_image(self.cmd, buffer.raw, image.raw, layout, &[region]);
            } else {
                device.cmd_copy_image_to_buffer(self.cmd, image.raw, layout, buffer.raw, &[region]);
            }
            let back = transition(
                layout,
                vk::ImageLayout::GENERAL,
                access,
                any | vk::AccessFlags::TRANSFER_READ,
            );
            device.cmd_pipeline_barrier(
                self.cmd,
                stages,
                stages,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &[back],
            );
        }
        self.close_pass(index);
        Ok(())
    }

    /// Submits the frame, waits for it and reads the pass timings back.
    pub fn submit_and_wait(&mut self) -> Result<&[PassTiming]> {
        self.submit(SubmitSync::default())?;
        self.wait()?;
        Ok(&self.timings)
    }

    /// Ends and submits the frame without waiting (`wait` or the next `begin` collects it).
    pub fn submit(&mut self, sync: SubmitSync) -> Result<()> {
        let device = &self.ctx.device;
        let all = vk::AccessFlags::SHADER_WRITE | vk::AccessFlags::TRANSFER_WRITE;
        let to_host = vk::MemoryBarrier::default()
            .src_access_mask(all)
            .dst_access_mask(vk::AccessFlags::HOST_READ);
        unsafe {
            device.cmd_pipeline_barrier(
                self.cmd,
                vk::PipelineStageFlags::COMPUTE_SHADER | vk::PipelineStageFlags::TRANSFER,
                vk::PipelineStageFlags::HOST,
                vk::DependencyFlags::empty(),
                &[to_host],
                &[],
                &[],
            );
            device.end_command_buffer(self.cmd)?;
        }
        self.recording = false;
        let cmds = [self.cmd];
        let mut wait_semaphores = [vk::Semaphore::null(); 4];
        let mut wait_stages = [vk::PipelineStageFlags::empty(); 4];
        let waits = sync.wait.len().min(4);
        for (i, &(semaphore, stage)) in sync.wait.iter().take(waits).enumerate() {
            wait_semaphores[i] = semaphore;
            wait_stages[i] = stage;
        }
        let submit = vk::SubmitInfo::default()
            .command_buffers(&cmds)
            .wait_semaphores(&wait_semaphores[..waits])
            .wait_dst_stage_mask(&wait_stages[..waits])
            .signal_semaphores(sync.signal);
        self.ctx
            .submit(&[submit], self.fence)
            .map_err(|e| self.lost(e))?;
        self.in_flight = true;
        Ok(())
    }

    /// Waits for this slot's submitted frame (if any) and reads its pass timings.
    pub fn wait(&mut self) -> Result<()> {
        if !self.in_flight {
            return Ok(());
        }
        let device = &self.ctx.device;
        self.ctx
            .counters
            .fence_waits
            .fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        unsafe {
            device
                .wait_for_fences(&[self.fence], true, u64::MAX)
                .map_err(|e| self.lost(e))?;
            device.reset_fences(&[self.fence])?;
        }
        self.in_flight = false;
        self.timings.clear();
        if !self.passes.is_empty() {
            let mut stamps = [0u64; 512];
            let count = (self.passes.len() * 2).min(stamps.len());
            unsafe {
                device.get_query_pool_results(
                    self.queries,
                    0,
                    &mut stamps[..count],
                    vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
                )?
            };
            let period_ms = self.ctx.info.timestamp_period_ns as f64 * 1e-6;
            for (i, &(name, view)) in self.passes.iter().enumerate().take(count / 2) {
                let ticks = stamps[2 * i + 1].saturating_sub(stamps[2 * i]);
                self.timings.push(PassTiming {
                    name,
                    view,
                    ms: ticks as f64 * period_ms,
                });
            }
        }
        Ok(())
    }

    fn lost(&self, e: vk::Result) -> Error {
        match e {
            vk::Result::ERROR_DEVICE_LOST => Error::DeviceLost {
                last_pass: self.passes.last().map_or("<none>", |p| p.0).to_string(),
            },
            other => Error::Vulkan(other),
        }
    }

    pub fn timings(&self) -> &[PassTiming] {
        &self.timings
    }

    fn check_bindings(
        &self,
        pass: &str,
        pipeline: &ComputePipeline,
        binds: &[Bind],
        push: &[u8],
    ) -> Result<()> {
        let fail = |reason: String| {
            Err(Error::Binding {
                pass: pass.to_string(),
                reason,
            })
        };
        if !self.recording {
            return fail("recorded outside begin()/submit_and_wait()".into());
        }
        if push.len() as u32 != pipeline.push_size {
            return fail(format!(
                "{} push-constant bytes given, shader takes {}",
                push.len(),
                pipeline.push_size
            ));
        }
        if binds.len() > MAX_BINDINGS {
            return fail(format!("more than {MAX_BINDINGS} bindings"));
        }
        for b in binds {
            // Names the shader does not declare are skipped: the optimiser drops unused
            // bindings, so a shared binding list (the scene's) may name more than a kernel uses.
            let Some(info) = pipeline.bindings.iter().find(|x| x.name == b.name) else {
                continue;
            };
            let ok = matches!(
                (b.resource, info.ty),
                (
                    Resource::Buffer(_),
                    vk::DescriptorType::STORAGE_BUFFER | vk::DescriptorType::UNIFORM_BUFFER
                ) | (
                    Resource::Texels(_),
                    vk::DescriptorType::UNIFORM_TEXEL_BUFFER
                ) | (
                    Resource::Image(_) | Resource::External(_),
                    vk::DescriptorType::STORAGE_IMAGE
                )
            );
            if !ok {
                return fail(format!(
                    "binding '{}' is a {:?} in the shader",
                    b.name, info.ty
                ));
            }
        }
        for info in &pipeline.bindings {
            if binds.iter().filter(|b| b.name == info.name).count() != 1 {
                return fail(format!(
                    "shader binding '{}' must be bound exactly once",
                    info.name
                ));
            }
        }
        Ok(())
    }

    fn barrier_for(&mut self, accesses: impl Iterator<Item = (ResourceId, bool)> + Clone) {
        let hazard = accesses.clone().any(|(id, write)| {
            self.written_since_barrier.contains(&id)
                || (write && self.read_since_barrier.contains(&id))
        });
        if hazard {
            let all = vk::AccessFlags::SHADER_READ
                | vk::AccessFlags::SHADER_WRITE
                | vk::AccessFlags::TRANSFER_READ
                | vk::AccessFlags::TRANSFER_WRITE;
            let barrier = vk::MemoryBarrier::default()
                .src_access_mask(all)
                .dst_access_mask(all);
            let stages = vk::PipelineStageFlags::COMPUTE_SHADER | vk::PipelineStageFlags::TRANSFER;
            unsafe {
                self.ctx.device.cmd_pipeline_barrier(
                    self.cmd,
                    stages,
                    stages,
                    vk::DependencyFlags::empty(),
                    &[barrier],
                    &[],
                    &[],
                )
            };
            self.read_since_barrier.clear();
            self.written_since_barrier.clear();
        }
        for (id, write) in accesses {
            if write {
                self.written_since_barrier.push(id);
            } else {
                self.read_since_barrier.push(id);
            }
        }
    }

    fn open_pass(&mut self, pass: &'static str) -> Result<u32> {
        let index = self.passes.len() as u32;
        if index >= self.max_passes {
            return Err(Error::Binding {
                pass: pass.into(),
                reason: format!("more than {} passes in one frame", self.max_passes),
            });
        }
        self.passes.push((pass, self.view));
        unsafe {
            if let Some(du) = &self.ctx.debug_utils {
                let mut name = [0u8; 64];
                let n = pass.len().min(63);
                name[..n].copy_from_slice(&pass.as_bytes()[..n]);
                let label = vk::DebugUtilsLabelEXT::default()
                    .label_name(std::ffi::CStr::from_bytes_until_nul(&name).unwrap_or(c"pass"));
                du.cmd_begin_debug_utils_label(self.cmd, &label);
            }
            self.ctx.device.cmd_write_timestamp(
                self.cmd,
                vk::PipelineStageFlags::COMPUTE_SHADER,
                self.queries,
                2 * index,
            );
        }
        Ok(index)
    }

    fn close_pass(&mut self, index: u32) {
        unsafe {
            self.ctx.device.cmd_write_timestamp(
                self.cmd,
                vk::PipelineStageFlags::COMPUTE_SHADER,
                self.queries,
                2 * index + 1,
            );
            if let Some(du) = &self.ctx.debug_utils {
                du.cmd_end_debug_utils_label(self.cmd);
            }
        }
    }
}

/// A colour image's layout transition with its access masks (mip 0, layer 0: all the engine's
/// images and swapchain images have). Public for the callers' own one-shot copies.
pub fn image_transition(
    image: vk::Image,
    from: vk::ImageLayout,
    to: vk::ImageLayout,
    src: vk::AccessFlags,
    dst: vk::AccessFlags,
) -> vk::ImageMemoryBarrier<'static> {
    vk::ImageMemoryBarrier::default()
        .image(image)
        .old_layout(from)
        .new_layout(to)
        .src_access_mask(src)
        .dst_access_mask(dst)
        .subresource_range(crate::vk::color_range())
}

impl Drop for FrameRecorder {
    fn drop(&mut self) {
        unsafe {
            // Only this slot's frame can still use the command buffer and queries.
            if self.in_flight {
                let _ = self
                    .ctx
                    .device
                    .wait_for_fences(&[self.fence], true, u64::MAX);
            }
            self.ctx.device.destroy_query_pool(self.queries, None);
            self.ctx.device.destroy_fence(self.fence, None);
            if let Ok(pool) = self.ctx.pool.lock() {
                self.ctx.device.free_command_buffers(*pool, &[self.cmd]);
            }
        }
    }
}
