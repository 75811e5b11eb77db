//! Buffers and images that own their memory and free it on drop.

use super::context::Context;
use crate::error::{Error, Result};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// Identity of a resource for barrier tracking in the frame graph.
pub type ResourceId = u64;

/// A fresh resource identity (also for images the engine does not own, `graph::ExternalImage`).
pub fn next_resource_id() -> ResourceId {
    next_id()
}

fn next_id() -> ResourceId {
    static NEXT: AtomicU64 = AtomicU64::new(1);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

pub struct Buffer {
    ctx: Arc<Context>,
    pub raw: vk::Buffer,
    /// A texel view (RGBA32F) when the buffer was made for texel-buffer reads.
    pub texel_view: Option<vk::BufferView>,
    pub size: u64,
    pub id: ResourceId,
    pub name: String,
    allocation: Option<Allocation>,
}

impl Buffer {
    pub fn new(
        ctx: &Arc<Context>,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Buffer> {
        let info = vk::BufferCreateInfo::default()
            .size(size)
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        let raw = unsafe { ctx.device.create_buffer(&info, None)? };
        let requirements = unsafe { ctx.device.get_buffer_memory_requirements(raw) };
        let allocation = match ctx.allocate(&AllocationCreateDesc {
            name,
            requirements,
            location,
            linear: true,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        }) {
            Ok(a) => a,
            Err(e) => {
                unsafe { ctx.device.destroy_buffer(raw, None) };
                return Err(e);
            }
        };
        let mut buffer = Buffer {
            ctx: ctx.clone(),
            raw,
            texel_view: None,
            size,
            id: next_id(),
            name: name.to_string(),
            allocation: None,
        };
        unsafe {
            ctx.device
                .bind_buffer_memory(raw, allocation.memory(), allocation.offset())?
        };
        buffer.allocation = Some(allocation);
        ctx.set_name(raw, name);
        Ok(buffer)
    }

    /// A host-visible storage buffer filled with `data` (small per-scene or per-frame data).
    pub fn with_data<T: bytemuck::Pod>(
        ctx: &Arc<Context>,
        name: &str,
        data: &[T],
        usage: vk::BufferUsageFlags,
    ) -> Result<Buffer> {
        // Zero-sized buffers are invalid in Vulkan; keep one element of room.
        let size = (std::mem::size_of_val(data) as u64).max(16);
        let buffer = Buffer::new(ctx, name, size, usage, MemoryLocation::CpuToGpu)?;
        buffer.write(data)?;
        Ok(buffer)
    }

    /// A read-only RGBA32F texel buffer (BVH nodes and triangles: 5–6× faster than std430
    /// storage reads on lavapipe, see build-notes.md).
    pub fn texels(ctx: &Arc<Context>, name: &str, texels: &[[f32; 4]]) -> Result<Buffer> {
        let buffer = Buffer::host_texels(ctx, name, std::mem::size_of_val(texels) as u64)?;
        buffer.write(texels)?;
        Ok(buffer)
    }

    /// An empty host-visible (CpuToGpu) RGBA32F texel buffer of `size` bytes, refilled with
    /// `write` between submissions (per-frame tables read with `texelFetch`).
    pub fn host_texels(ctx: &Arc<Context>, name: &str, size: u64) -> Result<Buffer> {
        Self::texel_buffer(
            ctx,
            name,
            size,
            vk::BufferUsageFlags::empty(),
            MemoryLocation::CpuToGpu,
        )
    }

    /// A device-local RGBA32F texel buffer holding `texels`, uploaded once (BVH nodes and
    /// triangles: see `device_local`).
    pub fn device_texels(ctx: &Arc<Context>, name: &str, texels: &[[f32; 4]]) -> Result<Buffer> {
        let size = std::mem::size_of_val(texels) as u64;
        let usage = vk::BufferUsageFlags::TRANSFER_DST | vk::BufferUsageFlags::TRANSFER_SRC;
        let buffer = Self::texel_buffer(ctx, name, size, usage, MemoryLocation::GpuOnly)?;
        buffer.upload(texels)?;
        Ok(buffer)
    }

    fn texel_buffer(
        ctx: &Arc<Context>,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Buffer> {
        let size = size.max(16).next_multiple_of(16);
        let limit = ctx.info.max_texel_buffer_elements as u64;
        if size / 16 > limit {
            return Err(Error::Invalid(format!(
                "{name}: {} texels exceed the device limit {limit}",
                size / 16
            )));
        }
        let mut buffer = Buffer::new(
            ctx,
            name,
            size,
            usage | vk::BufferUsageFlags::UNIFORM_TEXEL_BUFFER,
            location,
        )?;
        let info = vk::BufferViewCreateInfo::default()
            .buffer(buffer.raw)
            .format(vk::Format::R32G32B32A32_SFLOAT)
            .offset(0)
            .range(vk::WHOLE_SIZE);
        buffer.texel_view = Some(unsafe { ctx.device.create_buffer_view(&info, None)? });
        Ok(buffer)
    }

    /// A device-local buffer holding `data`, uploaded once through a staging buffer: scene data
    /// that every ray reads and the host never rewrites. On a discrete GPU host-visible memory
    /// may sit across the bus (every BVH node fetch a PCIe read); on lavapipe both are system
    /// memory and this costs one copy at load.
    pub fn device_local<T: bytemuck::Pod>(
        ctx: &Arc<Context>,
        name: &str,
        data: &[T],
        usage: vk::BufferUsageFlags,
    ) -> Result<Buffer> {
        let size = (std::mem::size_of_val(data) as u64).max(16);
        let transfer = vk::BufferUsageFlags::TRANSFER_DST | vk::BufferUsageFlags::TRANSFER_SRC;
        let buffer = Buffer::new(ctx, name, size, usage | transfer, MemoryLocation::GpuOnly)?;
        buffer.upload(data)?;
        Ok(buffer)
    }

    /// Fills this device-local buffer from the host now and waits (set-up and benchmark inputs,
    /// never inside a frame).
    pub fn upload<T: bytemuck::Pod>(&self, data: &[T]) -> Result<()> {
        let bytes = std::mem::size_of_val(data) as u64;
        if bytes == 0 {
            return Ok(());
        }
        let staging = Buffer::new(
            &self.ctx,
            &format!("{}.staging", self.name),
            bytes,
            vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::CpuToGpu,
        )?;
        staging.write(data)?;
        copy_now(&self.ctx, &staging, self, bytes)
    }

    /// Reads the first `out.len()` elements of this device-local buffer back through a staging
    /// buffer now (benchmark results, never inside a frame).
    pub fn download<T: bytemuck::Pod>(&self, out: &mut [T]) -> Result<()> {
        let bytes = std::mem::size_of_val(out) as u64;
        if bytes == 0 {
            return Ok(());
        }
        let staging = Buffer::new(
            &self.ctx,
            &format!("{}.readback", self.name),
            bytes,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        copy_now(&self.ctx, self, &staging, bytes)?;
        staging.read_into(out)
    }

    /// The mapped pointer of a host-visible buffer.
    fn mapped(&self) -> Result<std::ptr::NonNull<std::ffi::c_void>> {
        self.allocation
            .as_ref()
            .and_then(|a| a.mapped_ptr())
            .ok_or_else(|| Error::Invalid(format!("buffer '{}' is not host-visible", self.name)))
    }

    pub fn write<T: bytemuck::Pod>(&self, data: &[T]) -> Result<()> {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        let slice = self.mapped()?;
        if bytes.len() as u64 > self.size {
            return Err(Error::Invalid(format!(
                "buffer '{}': {} bytes do not fit in {}",
                self.name,
                bytes.len(),
                self.size
            )));
        }
        // SAFETY: mapped host-visible memory of at least `size` bytes, not in use by the GPU
        // (callers write between submissions).
        unsafe {
            std::ptr::copy_nonoverlapping(bytes.as_ptr(), slice.as_ptr() as *mut u8, bytes.len())
        };
        Ok(())
    }

    /// Copies the first `out.len()` elements back without allocating (render-loop read-backs).
    pub fn read_into<T: bytemuck::Pod>(&self, out: &mut [T]) -> Result<()> {
        let ptr = self.mapped()?;
        let bytes = std::mem::size_of_val(out);
        if bytes as u64 > self.size {
            return Err(Error::Invalid(format!(
                "buffer '{}': {bytes} bytes requested from {}",
                self.name, self.size
            )));
        }
        // SAFETY: mapped host-visible memory of at least `bytes`; the GPU is done with it.
        unsafe {
            std::ptr::copy_nonoverlapping(
                ptr.as_ptr() as *const u8,
                out.as_mut_ptr() as *mut u8,
                bytes,
            )
        };
        Ok(())
    }

    /// Reads the whole buffer back as `T`s (host-visible buffers only, after the GPU is done).
    pub fn read<T: bytemuck::Pod>(&self) -> Result<Vec<T>> {
        let mut out = vec![T::zeroed(); self.size as usize / std::mem::size_of::<T>()];
        self.read_into(&mut out)?;
        Ok(out)
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        unsafe {
            if let Some(view) = self.texel_view.take() {
                self.ctx.device.destroy_buffer_view(view, None);
            }
            self.ctx.device.destroy_buffer(self.raw, None);
        }
        if let Some(a) = self.allocation.take() {
            self.ctx.free(a);
        }
    }
}

/// A 2-D storage image kept in GENERAL layout for its whole life (compute-only engine).
pub struct Image {
    ctx: Arc<Context>,
    pub raw: vk::Image,
    pub view: vk::ImageView,
    pub format: vk::Format,
    pub width: u32,
    pub height: u32,
    pub id: ResourceId,
    pub name: String,
    allocation: Option<Allocation>,
}

impl Image {
    pub fn new(
        ctx: &Arc<Context>,
        name: &str,
        width: u32,
        height: u32,
        format: vk::Format,
    ) -> Result<Image> {
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(format)
            .extent(vk::Extent3D {
                width,
                height,
                depth: 1,
            })
            .mip_levels(1)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(
                vk::ImageUsageFlags::STORAGE
                    | vk::ImageUsageFlags::SAMPLED
                    | vk::ImageUsageFlags::TRANSFER_SRC
                    | vk::ImageUsageFlags::TRANSFER_DST,
            )
            .initial_layout(vk::ImageLayout::UNDEFINED);
        let raw = unsafe { ctx.device.create_image(&info, None)? };
        let requirements = unsafe { ctx.device.get_image_memory_requirements(raw) };
        let allocation = match ctx.allocate(&AllocationCreateDesc {
            name,
            requirements,
            location: MemoryLocation::GpuOnly,
            linear: false,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        }) {
            Ok(a) => a,
            Err(e) => {
                unsafe { ctx.device.destroy_image(raw, None) };
                return Err(e);
            }
        };
        unsafe {
            ctx.device
                .bind_image_memory(raw, allocation.memory(), allocation.offset())?
        };
        let view_info = vk::ImageViewCreateInfo::default()
            .image(raw)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(format)
            .subresource_range(color_range());
        let view = unsafe { ctx.device.create_image_view(&view_info, None)? };
        ctx.set_name(raw, name);
        // Storage images live in GENERAL layout; make the transition once, here.
        ctx.one_shot(|device, cmd| unsafe {
            let barrier = vk::ImageMemoryBarrier::default()
                .image(raw)
                .old_layout(vk::ImageLayout::UNDEFINED)
                .new_layout(vk::ImageLayout::GENERAL)
                .dst_access_mask(
                    vk::AccessFlags::SHADER_READ
                        | vk::AccessFlags::SHADER_WRITE
                        | vk::AccessFlags::TRANSFER_READ
                        | vk::AccessFlags::TRANSFER_WRITE,
                )
                .subresource_range(color_range());
            device.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::TOP_OF_PIPE,
                vk::PipelineStageFlags::COMPUTE_SHADER | vk::PipelineStageFlags::TRANSFER,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &[barrier],
            );
            device.cmd_clear_color_image(
                cmd,
                raw,
                vk::ImageLayout::GENERAL,
                &vk::ClearColorValue::default(),
                &[color_range()],
            );
        })?;
        Ok(Image {
            ctx: ctx.clone(),
            raw,
            view,
            format,
            width,
            height,
            id: next_id(),
            name: name.to_string(),
            allocation: Some(allocation),
        })
    }

    pub fn texel_bytes(&self) -> u64 {
        format_bytes(self.format)
    }
}

impl Drop for Image {
    fn drop(&mut self) {
        unsafe {
            self.ctx.device.destroy_image_view(self.view, None);
            self.ctx.device.destroy_image(self.raw, None);
        }
        if let Some(a) = self.allocation.take() {
            self.ctx.free(a);
        }
    }
}

pub fn color_range() -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: 0,
        layer_count: 1,
    }
}

pub fn format_bytes(format: vk::Format) -> u64 {
    match format {
        vk::Format::R32G32B32A32_SFLOAT | vk::Format::R32G32B32A32_UINT => 16,
        vk::Format::R16G16B16A16_SFLOAT | vk::Format::R32G32_SFLOAT | vk::Format::R32G32_UINT => 8,
        vk::Format::R8G8B8A8_UNORM | vk::Format::R32_SFLOAT | vk::Format::R32_UINT => 4,
        // Swapchain formats the viewer accepts (external targets).
        vk::Format::B8G8R8A8_UNORM => 4,
        other => panic!("format {other:?} not used by this engine"),
    }
}

/// Copies `bytes` from the start of `src` to the start of `dst` now and waits: a full
/// barrier on each side (set-up work; what ran before and what runs after see the data).
fn copy_now(ctx: &Context, src: &Buffer, dst: &Buffer, bytes: u64) -> Result<()> {
    if bytes > src.size || bytes > dst.size {
        return Err(Error::Invalid(format!(
            "copy of {bytes} bytes from '{}' ({} bytes) to '{}' ({} bytes)",
            src.name, src.size, dst.name, dst.size
        )));
    }
    ctx.one_shot(|device, cmd| unsafe {
        let all = vk::PipelineStageFlags::ALL_COMMANDS;
        let barrier = vk::MemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::MEMORY_WRITE)
            .dst_access_mask(vk::AccessFlags::MEMORY_READ | vk::AccessFlags::MEMORY_WRITE);
        device.cmd_pipeline_barrier(
            cmd,
            all,
            all,
            vk::DependencyFlags::empty(),
            &[barrier],
            &[],
            &[],
        );
        device.cmd_copy_buffer(
            cmd,
            src.raw,
            dst.raw,
            &[vk::BufferCopy {
                src_offset: 0,
                dst_offset: 0,
                size: bytes,
            }],
        );
        let after = barrier.dst_access_mask(
            vk::AccessFlags::MEMORY_READ
                | vk::AccessFlags::MEMORY_WRITE
                | vk::AccessFlags::HOST_READ,
        );
        device.cmd_pipeline_barrier(
            cmd,
            all,
            all | vk::PipelineStageFlags::HOST,
            vk::DependencyFlags::empty(),
            &[after],
            &[],
            &[],
        );
    })
}
