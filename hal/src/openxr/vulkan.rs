//! Vulkan through the runtime (`XR_KHR_vulkan_enable2`): the runtime adds the instance and device
//! extensions it needs to the renderer's create-infos and picks the physical device (the one
//! wired to the headset). hal has no Vulkan dependency: handles and create-infos are raw
//! pointers (cast from ash's `vk::InstanceCreateInfo` etc.).

use super::{call, fail, OpenXrRuntime};
use crate::error::HalError;
use openxr as xr;
use xr::sys::platform::{
    VkDevice, VkDeviceCreateInfo, VkGetInstanceProcAddr, VkInstance, VkInstanceCreateInfo,
    VkPhysicalDevice,
};

impl OpenXrRuntime {
    fn require_vulkan2(&self) -> Result<(), HalError> {
        if self.has_vulkan2 {
            Ok(())
        } else {
            Err(fail("the OpenXR runtime does not offer XR_KHR_vulkan_enable2: no Vulkan session possible"))
        }
    }

    /// `xrGetVulkanGraphicsRequirements2KHR`: the Vulkan API versions the runtime accepts. OpenXR
    /// requires this call before a Vulkan session is created ([`super::SessionOwner::vulkan`]
    /// makes it too).
    pub fn vulkan_requirements(&self) -> Result<xr::vulkan::Requirements, HalError> {
        self.require_vulkan2()?;
        call(
            "xrGetVulkanGraphicsRequirements2KHR",
            self.instance
                .graphics_requirements::<xr::Vulkan>(self.system),
        )
    }

    /// `xrCreateVulkanInstanceKHR`: the runtime creates the `VkInstance` from the renderer's
    /// `VkInstanceCreateInfo` (adding its own extensions).
    ///
    /// # Safety
    /// `create_info` must point to a valid `VkInstanceCreateInfo` (and everything it points to)
    /// for the duration of the call; `get_instance_proc_addr` must be the Vulkan loader's.
    pub unsafe fn create_vulkan_instance(
        &self,
        get_instance_proc_addr: VkGetInstanceProcAddr,
        create_info: *const VkInstanceCreateInfo,
    ) -> Result<VkInstance, HalError> {
        self.require_vulkan2()?;
        self.vulkan_requirements()?;
        // SAFETY: forwarded from the caller.
        let r = call("xrCreateVulkanInstanceKHR", unsafe {
            self.instance
                .create_vulkan_instance(self.system, get_instance_proc_addr, create_info)
        })?;
        r.map_err(|vk| {
            fail(format!(
                "xrCreateVulkanInstanceKHR: vkCreateInstance failed with {}",
                vk_result_name(vk)
            ))
        })
    }

    /// `xrGetVulkanGraphicsDevice2KHR`: the physical device the runtime drives the headset with.
    ///
    /// # Safety
    /// `instance` must come from [`Self::create_vulkan_instance`] and still be alive.
    pub unsafe fn vulkan_physical_device(
        &self,
        instance: VkInstance,
    ) -> Result<VkPhysicalDevice, HalError> {
        self.require_vulkan2()?;
        // SAFETY: forwarded from the caller.
        call("xrGetVulkanGraphicsDevice2KHR", unsafe {
            self.instance.vulkan_graphics_device(self.system, instance)
        })
    }

    /// `xrCreateVulkanDeviceKHR`: the runtime creates the `VkDevice` from the renderer's
    /// `VkDeviceCreateInfo` (adding its own extensions).
    ///
    /// # Safety
    /// `physical_device` must come from [`Self::vulkan_physical_device`]; `create_info` must
    /// point to a valid `VkDeviceCreateInfo` for the duration of the call.
    pub unsafe fn create_vulkan_device(
        &self,
        get_instance_proc_addr: VkGetInstanceProcAddr,
        physical_device: VkPhysicalDevice,
        create_info: *const VkDeviceCreateInfo,
    ) -> Result<VkDevice, HalError> {
        self.require_vulkan2()?;
        // SAFETY: forwarded from the caller.
        let r = call("xrCreateVulkanDeviceKHR", unsafe {
            self.instance.create_vulkan_device(
                self.system,
                get_instance_proc_addr,
                physical_device,
                create_info,
            )
        })?;
        r.map_err(|vk| {
            fail(format!(
                "xrCreateVulkanDeviceKHR: vkCreateDevice failed with {}",
                vk_result_name(vk)
            ))
        })
    }
}

/// The usual reasons vkCreateInstance / vkCreateDevice fail, by name.
fn vk_result_name(code: i32) -> String {
    let name = match code {
        -1 => "VK_ERROR_OUT_OF_HOST_MEMORY",
        -2 => "VK_ERROR_OUT_OF_DEVICE_MEMORY",
        -3 => "VK_ERROR_INITIALIZATION_FAILED",
        -6 => "VK_ERROR_LAYER_NOT_PRESENT",
        -7 => "VK_ERROR_EXTENSION_NOT_PRESENT",
        -8 => "VK_ERROR_FEATURE_NOT_PRESENT",
        -9 => "VK_ERROR_INCOMPATIBLE_DRIVER",
        _ => return format!("VkResult {code}"),
    };
    format!("{name} ({code})")
}
