//! The window's swapchain: images the engine's last pass writes as external targets.
//! sRGB swapchain formats rarely allow STORAGE, so a UNORM format with STORAGE is chosen and
//! the tonemap shader encodes sRGB itself.

use anyhow::{bail, Context as _, Result};
use ash::vk;
use fovea_renderer::graph::{image_transition, ExternalImage};
use fovea_renderer::vk::{next_resource_id, Buffer, Context};
use std::sync::Arc;

/// Present modes by `--present-mode` name.
pub const PRESENT_MODES: &[(&str, vk::PresentModeKHR)] = &[
    ("fifo", vk::PresentModeKHR::FIFO),
    ("mailbox", vk::PresentModeKHR::MAILBOX),
    ("immediate", vk::PresentModeKHR::IMMEDIATE),
];

pub struct Swapchain {
    ctx: Arc<Context>,
    pub loader: ash::khr::swapchain::Device,
    pub raw: vk::SwapchainKHR,
    pub images: Vec<ExternalImage>,
    /// Signalled by each image's frame, waited on by its presentation (one per image: an image
    /// is only re-acquired after its presentation).
    pub rendered: Vec<vk::Semaphore>,
    pub extent: vk::Extent2D,
    pub format: vk::Format,
    pub present_mode: vk::PresentModeKHR,
    /// What the images were made for (STORAGE, plus the transfers the surface allows).
    pub usage: vk::ImageUsageFlags,
}

impl Swapchain {
    pub fn new(
        ctx: &Arc<Context>,
        surface_loader: &ash::khr::surface::Instance,
        surface: vk::SurfaceKHR,
        size: (u32, u32),
        wanted_mode: vk::PresentModeKHR,
        old: vk::SwapchainKHR,
    ) -> Result<Swapchain> {
        let caps = unsafe {
            surface_loader.get_physical_device_surface_capabilities(ctx.physical, surface)?
        };
        if !caps
            .supported_usage_flags
            .contains(vk::ImageUsageFlags::STORAGE)
        {
            bail!("the window surface does not allow STORAGE images (the engine writes the swapchain from a compute shader)");
        }
        let format = pick_format(ctx, surface_loader, surface)?;
        let modes = unsafe {
            surface_loader.get_physical_device_surface_present_modes(ctx.physical, surface)?
        };
        let present_mode = if modes.contains(&wanted_mode) {
            wanted_mode
        } else {
            vk::PresentModeKHR::FIFO
        };
        let extent = match caps.current_extent.width {
            u32::MAX => vk::Extent2D {
                width: size
                    .0
                    .clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: size
                    .1
                    .clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            },
            _ => caps.current_extent,
        };
        let mut count = caps.min_image_count + 1;
        if caps.max_image_count > 0 {
            count = count.min(caps.max_image_count);
        }
        // Screenshots copy the presented image (TRANSFER_SRC) and debug views copy a CPU-made
        // picture into it (TRANSFER_DST), where the surface allows them.
        let usage = vk::ImageUsageFlags::STORAGE
            | (caps.supported_usage_flags
                & (vk::ImageUsageFlags::TRANSFER_SRC | vk::ImageUsageFlags::TRANSFER_DST));
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(surface)
            .min_image_count(count)
            .image_format(format)
            .image_color_space(vk::ColorSpaceKHR::SRGB_NONLINEAR)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(usage)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(vk::CompositeAlphaFlagsKHR::OPAQUE)
            .present_mode(present_mode)
            .clipped(true)
            .old_swapchain(old);
        let loader = ash::khr::swapchain::Device::new(&ctx.instance, &ctx.device);
        let raw = unsafe {
            loader
                .create_swapchain(&info, None)
                .context("creating the swapchain")?
        };
        let raw_images = unsafe { loader.get_swapchain_images(raw)? };
        let mut images = Vec::with_capacity(raw_images.len());
        let mut rendered = Vec::with_capacity(raw_images.len());
        for image in raw_images {
            let view_info = vk::ImageViewCreateInfo::default()
                .image(image)
                .view_type(vk::ImageViewType::TYPE_2D)
                .format(format)
                .subresource_range(fovea_renderer::vk::color_range());
            let view = unsafe { ctx.device.create_image_view(&view_info, None)? };
            images.push(ExternalImage {
                raw: image,
                view,
                width: extent.width,
                height: extent.height,
                format,
                layout_before: vk::ImageLayout::UNDEFINED,
                layout_after: vk::ImageLayout::PRESENT_SRC_KHR,
                id: next_resource_id(),
            });
            rendered.push(unsafe {
                ctx.device
                    .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)?
            });
        }
        Ok(Swapchain {
            ctx: ctx.clone(),
            loader,
            raw,
            images,
            rendered,
            extent,
            format,
            present_mode,
            usage,
        })
    }

    /// Whether the images allow `usage` (screenshots copy from them: TRANSFER_SRC; debug views
    /// copy into them: TRANSFER_DST).
    pub fn allows(&self, usage: vk::ImageUsageFlags) -> bool {
        self.usage.contains(usage)
    }
}

impl Drop for Swapchain {
    fn drop(&mut self) {
        // The caller has drained the frames that used these images.
        unsafe {
            for (image, semaphore) in self.images.iter().zip(&self.rendered) {
                self.ctx.device.destroy_image_view(image.view, None);
                self.ctx.device.destroy_semaphore(*semaphore, None);
            }
            self.loader.destroy_swapchain(self.raw, None);
        }
    }
}

/// The first UNORM 8-bit format the surface offers whose images the device can write from a
/// compute shader without a format qualifier.
fn pick_format(
    ctx: &Context,
    surface_loader: &ash::khr::surface::Instance,
    surface: vk::SurfaceKHR,
) -> Result<vk::Format> {
    let formats =
        unsafe { surface_loader.get_physical_device_surface_formats(ctx.physical, surface)? };
    let candidates = [vk::Format::B8G8R8A8_UNORM, vk::Format::R8G8B8A8_UNORM];
    for wanted in candidates {
        if !formats
            .iter()
            .any(|f| f.format == wanted && f.color_space == vk::ColorSpaceKHR::SRGB_NONLINEAR)
        {
            continue;
        }
        let props = unsafe {
            ctx.instance
                .get_physical_device_format_properties(ctx.physical, wanted)
        };
        if props
            .optimal_tiling_features
            .contains(vk::FormatFeatureFlags::STORAGE_IMAGE)
        {
            return Ok(wanted);
        }
    }
    bail!(
        "the window surface offers no UNORM format with STORAGE support (offered: {:?})",
        formats.iter().map(|f| f.format).collect::<Vec<_>>()
    )
}

impl Swapchain {
    /// Acquires an image, copies `rgba` (the whole extent, RGBA8 sRGB) into it and presents it:
    /// the debug views' way to the window. Waits for the acquire and for the copy (a debug frame
    /// is not the steady state). `Ok(false)`: the swapchain is out of date.
    pub fn present_pixels(&self, staging: &Buffer, rgba: &[u8]) -> Result<bool> {
        let device = &self.ctx.device;
        let fence = unsafe { device.create_fence(&vk::FenceCreateInfo::default(), None)? };
        let acquired = unsafe {
            self.loader
                .acquire_next_image(self.raw, u64::MAX, vk::Semaphore::null(), fence)
        };
        let index = match acquired {
            Ok((index, _)) => index,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => {
                unsafe { device.destroy_fence(fence, None) };
                return Ok(false);
            }
            Err(e) => {
                unsafe { device.destroy_fence(fence, None) };
                return Err(e.into());
            }
        };
        let waited = unsafe { device.wait_for_fences(&[fence], true, u64::MAX) };
        unsafe { device.destroy_fence(fence, None) };
        waited?;
        let mut bytes = rgba.to_vec();
        if self.format == vk::Format::B8G8R8A8_UNORM {
            bytes.chunks_exact_mut(4).for_each(|p| p.swap(0, 2));
        }
        staging.write(&bytes)?;
        let image = self.images[index as usize].raw;
        let extent = vk::Extent3D {
            width: self.extent.width,
            height: self.extent.height,
            depth: 1,
        };
        self.ctx.one_shot(|device, cmd| unsafe {
            let to_dst = image_transition(
                image,
                vk::ImageLayout::UNDEFINED,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                vk::AccessFlags::empty(),
                vk::AccessFlags::TRANSFER_WRITE,
            );
            device.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::TOP_OF_PIPE,
                vk::PipelineStageFlags::TRANSFER,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &[to_dst],
            );
            let region = vk::BufferImageCopy::default()
                .image_subresource(vk::ImageSubresourceLayers {
                    aspect_mask: vk::ImageAspectFlags::COLOR,
                    mip_level: 0,
                    base_array_layer: 0,
                    layer_count: 1,
                })
                .image_extent(extent);
            device.cmd_copy_buffer_to_image(
                cmd,
                staging.raw,
                image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[region],
            );
            let to_present = image_transition(
                image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                vk::ImageLayout::PRESENT_SRC_KHR,
                vk::AccessFlags::TRANSFER_WRITE,
                vk::AccessFlags::empty(),
            );
            device.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::TRANSFER,
                vk::PipelineStageFlags::BOTTOM_OF_PIPE,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &[to_present],
            );
        })?;
        let (swapchains, indices) = ([self.raw], [index]);
        let present = vk::PresentInfoKHR::default()
            .swapchains(&swapchains)
            .image_indices(&indices);
        let result = {
            let _queue = self.ctx.queue_guard();
            unsafe { self.loader.queue_present(self.ctx.queue, &present) }
        };
        match result {
            Ok(false) => Ok(true),
            Ok(true) | Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(false),
            Err(e) => Err(e.into()),
        }
    }
}
