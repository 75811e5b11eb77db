//! The engine's Vulkan context made through the OpenXR runtime (`XR_KHR_vulkan_enable2`: the
//! runtime adds its compositor's extensions and picks the GPU wired to the headset), and the
//! runtime's swapchain images as the engine's external targets.

use anyhow::{bail, Context as _, Result};
use ash::vk::{self, Handle};
use fovea_hal::openxr::{xr, OpenXrRuntime, SessionOwner, VulkanBinding, STORAGE_FORMATS};
use fovea_renderer::graph::ExternalImage;
use fovea_renderer::vk::{color_range, next_resource_id, Context, ContextOptions, DeviceCreator};
use std::ffi::c_void;
use std::sync::Arc;

/// Lets the runtime create the engine's instance and device from the engine's create-infos.
pub struct RuntimeDevice(pub Arc<OpenXrRuntime>);

fn loader_gipa(entry: &ash::Entry) -> xr::sys::platform::VkGetInstanceProcAddr {
    // SAFETY: the same C function pointer; OpenXR's binding types Vulkan's handles as void.
    unsafe {
        std::mem::transmute::<vk::PFN_vkGetInstanceProcAddr, xr::sys::platform::VkGetInstanceProcAddr>(
            entry.static_fn().get_instance_proc_addr,
        )
    }
}

impl DeviceCreator for RuntimeDevice {
    unsafe fn create_instance(
        &self,
        entry: &ash::Entry,
        info: &vk::InstanceCreateInfo,
    ) -> Result<vk::Instance, String> {
        // SAFETY: `info` is valid for the call (the caller's contract).
        let raw = unsafe {
            self.0
                .create_vulkan_instance(loader_gipa(entry), info as *const _ as *const c_void)
        }
        .map_err(|e| e.to_string())?;
        Ok(vk::Instance::from_raw(raw as u64))
    }

    unsafe fn physical_device(&self, instance: vk::Instance) -> Result<vk::PhysicalDevice, String> {
        // SAFETY: `instance` came from `create_instance` (the caller's contract).
        let raw = unsafe {
            self.0
                .vulkan_physical_device(instance.as_raw() as usize as *const c_void)
        }
        .map_err(|e| e.to_string())?;
        Ok(vk::PhysicalDevice::from_raw(raw as u64))
    }

    unsafe fn create_device(
        &self,
        entry: &ash::Entry,
        physical: vk::PhysicalDevice,
        info: &vk::DeviceCreateInfo,
    ) -> Result<vk::Device, String> {
        let physical = physical.as_raw() as usize as *const c_void;
        // SAFETY: `physical` came from `physical_device`, `info` is valid (the caller's contract).
        let raw = unsafe {
            self.0.create_vulkan_device(
                loader_gipa(entry),
                physical,
                info as *const _ as *const c_void,
            )
        }
        .map_err(|e| e.to_string())?;
        Ok(vk::Device::from_raw(raw as u64))
    }
}

/// The engine's context on the runtime's device (`options` gives validation; the runtime gives
/// the device).
pub fn open_context(rt: &Arc<OpenXrRuntime>, mut options: ContextOptions) -> Result<Arc<Context>> {
    let req = rt.vulkan_requirements()?;
    let (min, max) = (req.min_api_version_supported, req.max_api_version_supported);
    // The engine asks for Vulkan 1.2 (`Context::new`).
    if (min.major(), min.minor()) > (1, 2) || (max.major(), max.minor()) < (1, 2) {
        bail!(
            "the OpenXR runtime accepts Vulkan {}.{} to {}.{}; fovea needs 1.2",
            min.major(),
            min.minor(),
            max.major(),
            max.minor()
        );
    }
    options.creator = Some(Arc::new(RuntimeDevice(rt.clone())));
    // External targets: the swapchain's format is the runtime's choice, not the engine's RGBA8.
    options.require_storage_write_without_format = true;
    Context::new(&options).context("creating the Vulkan device through the OpenXR runtime")
}

/// What the session needs to know of the engine's Vulkan objects.
pub fn binding(ctx: &Context) -> VulkanBinding {
    VulkanBinding {
        instance: ctx.instance.handle().as_raw() as usize as *const c_void,
        physical_device: ctx.physical.as_raw() as usize as *const c_void,
        device: ctx.device.handle().as_raw() as usize as *const c_void,
        queue_family_index: ctx.queue_family,
        queue_index: 0,
    }
}

/// One swapchain holding both eyes side by side (left at x = 0, right at x = `eye_width`), its
/// images wrapped as external targets of the engine.
pub struct XrSwapchain {
    ctx: Arc<Context>,
    pub handle: xr::Swapchain<xr::Vulkan>,
    pub images: Vec<ExternalImage>,
    pub format: vk::Format,
    pub eye_width: u32,
    pub height: u32,
}

impl XrSwapchain {
    pub fn new(
        ctx: &Arc<Context>,
        owner: &SessionOwner<xr::Vulkan>,
        eye_width: u32,
        height: u32,
    ) -> Result<XrSwapchain> {
        let offered = owner.swapchain_formats()?;
        let format = offered
            .iter()
            .copied()
            .find(|f| STORAGE_FORMATS.contains(f) && storage_capable(ctx, vk::Format::from_raw(*f as i32)))
            .ok_or_else(|| anyhow::anyhow!("the runtime offers no swapchain format the engine can write (offered VkFormats: {offered:?}; need R8G8B8A8_UNORM or B8G8R8A8_UNORM with storage)"))?;
        let width = 2 * eye_width;
        let handle = owner.create_storage_swapchain(format, width, height)?;
        let format = vk::Format::from_raw(format as i32);
        let mut swapchain = XrSwapchain {
            ctx: ctx.clone(),
            handle,
            images: Vec::new(),
            format,
            eye_width,
            height,
        };
        for raw in swapchain
            .handle
            .enumerate_images()
            .context("xrEnumerateSwapchainImages")?
        {
            let image = vk::Image::from_raw(raw);
            let info = vk::ImageViewCreateInfo::default()
                .image(image)
                .view_type(vk::ImageViewType::TYPE_2D)
                .format(format)
                .subresource_range(color_range());
            // SAFETY: a live image of the runtime's swapchain on this device.
            let view = unsafe { ctx.device.create_image_view(&info, None)? };
            swapchain.images.push(ExternalImage {
                raw: image,
                view,
                width,
                height,
                format,
                // OpenXR hands Vulkan colour swapchain images over in this layout and wants them
                // back in it (XR_KHR_vulkan_enable2).
                layout_before: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                layout_after: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                id: next_resource_id(),
            });
        }
        Ok(swapchain)
    }
}

impl Drop for XrSwapchain {
    fn drop(&mut self) {
        // Shutdown only: the views may still be read by the last frames.
        let _ = self.ctx.wait_idle();
        for image in &self.images {
            // SAFETY: made by `new` on this device; the device is idle.
            unsafe { self.ctx.device.destroy_image_view(image.view, None) };
        }
    }
}

fn storage_capable(ctx: &Context, format: vk::Format) -> bool {
    // SAFETY: a query on the context's own physical device.
    let props = unsafe {
        ctx.instance
            .get_physical_device_format_properties(ctx.physical, format)
    };
    props
        .optimal_tiling_features
        .contains(vk::FormatFeatureFlags::STORAGE_IMAGE)
}
