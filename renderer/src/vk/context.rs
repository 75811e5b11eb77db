//! Instance, device selection, validation messenger, the compute queue and the allocator.
//! Everything else holds an `Arc<Context>`, so the device outlives every resource made from it.

use super::validation::{debug_callback, ValidationCounter};
use crate::error::{Error, Result};
use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use std::ffi::{c_char, CStr, CString};
use std::sync::atomic::{AtomicI64, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, Weak};

/// One entry of `Context::pipelines`.
pub(crate) type PipelineEntry = Weak<dyn std::any::Any + Send + Sync>;

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// How to pick the Vulkan device: by index in `fovea info`'s list or by a name substring.
#[derive(Clone, Debug, Default)]
pub enum DeviceSelector {
    /// Discrete GPU, else integrated, else virtual, else the CPU (lavapipe).
    #[default]
    Best,
    Index(usize),
    NameContains(String),
}

impl std::str::FromStr for DeviceSelector {
    type Err = std::convert::Infallible;
    fn from_str(s: &str) -> std::result::Result<Self, Self::Err> {
        Ok(match s.parse::<usize>() {
            Ok(i) => DeviceSelector::Index(i),
            Err(_) => DeviceSelector::NameContains(s.to_string()),
        })
    }
}

/// Creates the Vulkan instance and device on the engine's behalf from the engine's own
/// create-infos: an OpenXR runtime (`XR_KHR_vulkan_enable2`) adds the extensions its compositor
/// needs and chooses the physical device wired to the headset.
pub trait DeviceCreator: Send + Sync {
    /// # Safety
    /// `info` and everything it points to are valid for the call.
    unsafe fn create_instance(
        &self,
        entry: &ash::Entry,
        info: &vk::InstanceCreateInfo,
    ) -> std::result::Result<vk::Instance, String>;
    /// # Safety
    /// `instance` came from [`Self::create_instance`] and is alive.
    unsafe fn physical_device(
        &self,
        instance: vk::Instance,
    ) -> std::result::Result<vk::PhysicalDevice, String>;
    /// # Safety
    /// `physical` came from [`Self::physical_device`]; `info` is valid for the call.
    unsafe fn create_device(
        &self,
        entry: &ash::Entry,
        physical: vk::PhysicalDevice,
        info: &vk::DeviceCreateInfo,
    ) -> std::result::Result<vk::Device, String>;
}

#[derive(Clone, Default)]
pub struct ContextOptions {
    /// Turn on VK_LAYER_KHRONOS_validation and count its messages.
    pub validation: bool,
    /// Also turn on the layer's synchronisation validation (hazards between commands and
    /// between frames in flight); only with `validation`.
    pub sync_validation: bool,
    pub device: DeviceSelector,
    /// Extra instance extensions the caller needs (a window surface's, say).
    pub instance_extensions: Vec<CString>,
    /// Extra device extensions the caller needs (`VK_KHR_swapchain`).
    pub device_extensions: Vec<CString>,
    /// Refuse devices that cannot write storage images without a format qualifier (what the
    /// external-target tonemap needs to write a swapchain image of any UNORM format).
    pub require_storage_write_without_format: bool,
    /// Who creates the instance and device (and picks the physical device); `None`: the engine,
    /// by `device`.
    pub creator: Option<Arc<dyn DeviceCreator>>,
    /// The BVH traversal of the kernels that trace (`auto`: by the device's type).
    pub traversal: crate::traversal::TraversalChoice,
}

impl std::fmt::Debug for ContextOptions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ContextOptions")
            .field("validation", &self.validation)
            .field("sync_validation", &self.sync_validation)
            .field("device", &self.device)
            .field("instance_extensions", &self.instance_extensions)
            .field("device_extensions", &self.device_extensions)
            .field(
                "require_storage_write_without_format",
                &self.require_storage_write_without_format,
            )
            .field("creator", &self.creator.as_ref().map(|_| "external"))
            .field("traversal", &self.traversal)
            .finish()
    }
}

/// Waits and submissions since the context was made: the real-time loop's tests prove with these
/// that the steady state never drains the queue or the device.
#[derive(Default, Debug)]
pub struct EngineCounters {
    pub submits: AtomicU64,
    pub queue_idle_waits: AtomicU64,
    pub device_idle_waits: AtomicU64,
    pub fence_waits: AtomicU64,
}

impl EngineCounters {
    pub fn get(counter: &AtomicU64) -> u64 {
        counter.load(Ordering::SeqCst)
    }
}

/// What `fovea info` prints about each device.
#[derive(Clone, Debug)]
pub struct DeviceInfo {
    pub index: usize,
    pub name: String,
    pub kind: String,
    pub device_type: vk::PhysicalDeviceType,
    pub api_version: String,
    pub max_compute_workgroup_invocations: u32,
    pub max_storage_buffer_range: u32,
    pub max_texel_buffer_elements: u32,
    pub max_image_dimension_2d: u32,
    pub max_push_constants_size: u32,
    pub timestamp_period_ns: f32,
    pub suitable: std::result::Result<(), String>,
}

pub struct Context {
    pub entry: ash::Entry,
    pub instance: ash::Instance,
    pub physical: vk::PhysicalDevice,
    pub device: ash::Device,
    pub queue: vk::Queue,
    pub queue_family: u32,
    pub info: DeviceInfo,
    /// The BVH traversal pipelines and scene uploads use unless told otherwise
    /// ([`ContextOptions::traversal`] resolved for this device).
    pub traversal: crate::traversal::Traversal,
    pub push_descriptor: ash::khr::push_descriptor::Device,
    /// Present when VK_EXT_debug_utils is: names objects and labels passes.
    pub debug_utils: Option<ash::ext::debug_utils::Device>,
    debug_instance: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    pub validation: Arc<ValidationCounter>,
    allocator: Mutex<Option<Allocator>>,
    live_allocations: AtomicI64,
    allocated_bytes: AtomicI64,
    pub counters: EngineCounters,
    /// Storage images may be written without a format qualifier (the external-target tonemap:
    /// swapchain formats differ from the engine's own RGBA8).
    pub storage_write_without_format: bool,
    /// Compute pipelines by shader name (`ComputePipeline::shared`), shared by every view and
    /// pass that uses the kernel. Weak: a pipeline lives as long as a pass holds it (no cycle
    /// through the context). Held as `Any`: the context is made before any pipeline module.
    pub(crate) pipelines: Mutex<std::collections::HashMap<String, PipelineEntry>>,
    /// Serialises queue submissions (vkQueueSubmit needs external synchronisation).
    pub(crate) queue_lock: Mutex<()>,
    pub(crate) pool: Mutex<vk::CommandPool>,
}

impl Context {
    pub fn new(options: &ContextOptions) -> Result<Arc<Context>> {
        let entry = unsafe { ash::Entry::load()? };
        let validation = Arc::new(ValidationCounter::default());
        let (instance, debug_enabled) = create_instance(&entry, options)?;
        let debug_instance = if debug_enabled {
            let loader = ash::ext::debug_utils::Instance::new(&entry, &instance);
            let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(
                    vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                        | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING
                        | vk::DebugUtilsMessageSeverityFlagsEXT::INFO,
                )
                .message_type(
                    vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                        | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                        | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
                )
                .pfn_user_callback(Some(debug_callback))
                .user_data(Arc::as_ptr(&validation) as *mut _);
            let messenger = unsafe { loader.create_debug_utils_messenger(&info, None)? };
            Some((loader, messenger))
        } else {
            None
        };

        let devices = list_devices(&instance)?;
        let physicals = unsafe { instance.enumerate_physical_devices()? };
        let chosen = match &options.creator {
            Some(creator) => {
                let physical = unsafe { creator.physical_device(instance.handle()) }
                    .map_err(Error::Invalid)?;
                let index = physicals
                    .iter()
                    .position(|&p| p == physical)
                    .ok_or_else(|| {
                        Error::Invalid(
                            "the device creator chose a physical device the instance does not list"
                                .into(),
                        )
                    })?;
                let chosen = &devices[index];
                if let Err(why) = &chosen.suitable {
                    return Err(Error::NoSuitableDevice(format!(
                        "{} (chosen by the OpenXR runtime): {why}",
                        chosen.name
                    )));
                }
                chosen
            }
            None => choose_device(&devices, &options.device)?,
        };
        let physical = physicals[chosen.index];
        let queue_family = compute_queue_family(&instance, physical).ok_or_else(|| {
            Error::NoSuitableDevice(format!("{} has no compute queue", chosen.name))
        })?;

        let priorities = [1.0];
        let queue_infos = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        let mut extensions = vec![ash::khr::push_descriptor::NAME.as_ptr()];
        extensions.extend(options.device_extensions.iter().map(|e| e.as_ptr()));
        let supported = unsafe { instance.get_physical_device_features(physical) };
        let without_format = supported.shader_storage_image_write_without_format == vk::TRUE;
        if options.require_storage_write_without_format && !without_format {
            return Err(Error::NoSuitableDevice(format!(
                "{}: no shaderStorageImageWriteWithoutFormat (needed for external targets)",
                chosen.name
            )));
        }
        let features = vk::PhysicalDeviceFeatures::default()
            .shader_storage_image_write_without_format(without_format);
        let device_info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_infos)
            .enabled_extension_names(&extensions)
            .enabled_features(&features);
        let device = match &options.creator {
            Some(creator) => {
                let raw = unsafe { creator.create_device(&entry, physical, &device_info) }
                    .map_err(Error::Invalid)?;
                unsafe { ash::Device::load(instance.fp_v1_0(), raw) }
            }
            None => unsafe { instance.create_device(physical, &device_info, None)? },
        };
        let queue = unsafe { device.get_device_queue(queue_family, 0) };

        let mut debug_settings = gpu_allocator::AllocatorDebugSettings::default();
        debug_settings.log_leaks_on_shutdown = true;
        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device: physical,
            debug_settings,
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })?;
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        let pool = unsafe { device.create_command_pool(&pool_info, None)? };

        Ok(Arc::new(Context {
            push_descriptor: ash::khr::push_descriptor::Device::new(&instance, &device),
            debug_utils: debug_enabled
                .then(|| ash::ext::debug_utils::Device::new(&instance, &device)),
            entry,
            physical,
            queue,
            queue_family,
            info: chosen.clone(),
            traversal: options.traversal.resolve(chosen.device_type),
            debug_instance,
            validation,
            allocator: Mutex::new(Some(allocator)),
            live_allocations: AtomicI64::new(0),
            allocated_bytes: AtomicI64::new(0),
            counters: EngineCounters::default(),
            storage_write_without_format: without_format,
            pipelines: Mutex::new(Default::default()),
            queue_lock: Mutex::new(()),
            pool: Mutex::new(pool),
            device,
            instance,
        }))
    }

    /// All devices the loader reports, for `fovea info`.
    pub fn enumerate() -> Result<Vec<DeviceInfo>> {
        let entry = unsafe { ash::Entry::load()? };
        let (instance, _) = create_instance(&entry, &ContextOptions::default())?;
        let devices = list_devices(&instance);
        unsafe { instance.destroy_instance(None) };
        devices
    }

    pub(crate) fn allocate(
        &self,
        desc: &gpu_allocator::vulkan::AllocationCreateDesc,
    ) -> Result<gpu_allocator::vulkan::Allocation> {
        let mut guard = self.allocator.lock().expect("allocator lock poisoned");
        let allocation = guard
            .as_mut()
            .expect("allocator alive while the context is")
            .allocate(desc)?;
        self.live_allocations.fetch_add(1, Ordering::SeqCst);
        self.allocated_bytes
            .fetch_add(allocation.size() as i64, Ordering::SeqCst);
        Ok(allocation)
    }

    pub(crate) fn free(&self, allocation: gpu_allocator::vulkan::Allocation) {
        let mut guard = self.allocator.lock().expect("allocator lock poisoned");
        if let Some(a) = guard.as_mut() {
            self.allocated_bytes
                .fetch_sub(allocation.size() as i64, Ordering::SeqCst);
            // Freeing can only fail for a foreign allocation, which would be a bug here.
            a.free(allocation)
                .expect("free of an allocation from this allocator");
            self.live_allocations.fetch_sub(1, Ordering::SeqCst);
        }
    }

    /// Allocations not yet freed (tests check this is zero once resources are dropped).
    pub fn live_allocations(&self) -> i64 {
        self.live_allocations.load(Ordering::SeqCst)
    }

    /// GPU memory bytes held by live allocations (stereo's one shared scene upload is measured
    /// with this).
    pub fn allocated_bytes(&self) -> i64 {
        self.allocated_bytes.load(Ordering::SeqCst)
    }

    /// Waits until the device is idle (shutdown and resource rebuilds, never the frame loop);
    /// counted in `counters.device_idle_waits`.
    pub fn wait_idle(&self) -> Result<()> {
        self.counters
            .device_idle_waits
            .fetch_add(1, Ordering::SeqCst);
        let _guard = self.queue_lock.lock().expect("queue lock");
        unsafe { self.device.device_wait_idle()? };
        Ok(())
    }

    /// Submits under the queue lock, counted in `counters.submits`.
    pub(crate) fn submit(
        &self,
        submits: &[vk::SubmitInfo],
        fence: vk::Fence,
    ) -> std::result::Result<(), vk::Result> {
        self.counters.submits.fetch_add(1, Ordering::SeqCst);
        let _guard = self.queue_lock.lock().expect("queue lock");
        unsafe { self.device.queue_submit(self.queue, submits, fence) }
    }

    /// Holds the queue for a call outside the engine that needs it (vkQueuePresentKHR).
    pub fn queue_guard(&self) -> std::sync::MutexGuard<'_, ()> {
        self.queue_lock.lock().expect("queue lock")
    }

    /// Whether the compute queue family can present to `surface` (a window's).
    pub fn queue_supports_surface(
        &self,
        surface_loader: &ash::khr::surface::Instance,
        surface: vk::SurfaceKHR,
    ) -> Result<bool> {
        Ok(unsafe {
            surface_loader.get_physical_device_surface_support(
                self.physical,
                self.queue_family,
                surface,
            )?
        })
    }

    /// Records and runs a short command buffer now and waits for it (set-up work, not frames).
    pub fn one_shot(&self, record: impl FnOnce(&ash::Device, vk::CommandBuffer)) -> Result<()> {
        let pool = self.pool.lock().expect("command pool lock");
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(*pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        let cmd = unsafe { self.device.allocate_command_buffers(&alloc)? }[0];
        let result = (|| unsafe {
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            self.device.begin_command_buffer(cmd, &begin)?;
            record(&self.device, cmd);
            self.device.end_command_buffer(cmd)?;
            let cmds = [cmd];
            let submit = vk::SubmitInfo::default().command_buffers(&cmds);
            self.submit(&[submit], vk::Fence::null())?;
            self.counters
                .queue_idle_waits
                .fetch_add(1, Ordering::SeqCst);
            let _guard = self.queue_lock.lock().expect("queue lock");
            self.device.queue_wait_idle(self.queue)
        })();
        unsafe { self.device.free_command_buffers(*pool, &[cmd]) };
        result.map_err(|e| match e {
            vk::Result::ERROR_DEVICE_LOST => Error::DeviceLost {
                last_pass: "set-up".into(),
            },
            other => Error::Vulkan(other),
        })
    }

    pub fn set_name<H: vk::Handle>(&self, handle: H, name: &str) {
        if let Some(du) = &self.debug_utils {
            let name = std::ffi::CString::new(name).unwrap_or_default();
            let info = vk::DebugUtilsObjectNameInfoEXT::default()
                .object_handle(handle)
                .object_name(&name);
            unsafe {
                let _ = du.set_debug_utils_object_name(&info);
            }
        }
    }
}

impl Drop for Context {
    fn drop(&mut self) {
        unsafe {
            let _ = self.device.device_wait_idle();
            if let Ok(pool) = self.pool.lock() {
                self.device.destroy_command_pool(*pool, None);
            }
            // The allocator frees its memory blocks and logs leaks; it must go before the device.
            if let Ok(mut a) = self.allocator.lock() {
                a.take();
            }
            self.device.destroy_device(None);
            if let Some((loader, messenger)) = self.debug_instance.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

fn create_instance(entry: &ash::Entry, options: &ContextOptions) -> Result<(ash::Instance, bool)> {
    let validation = options.validation;
    let available_layers = unsafe { entry.enumerate_instance_layer_properties()? };
    let has_layer = available_layers
        .iter()
        .any(|l| l.layer_name_as_c_str().is_ok_and(|n| n == VALIDATION_LAYER));
    if validation && !has_layer {
        return Err(Error::Invalid(
            "validation requested but VK_LAYER_KHRONOS_validation is not installed (apt-get install vulkan-validationlayers)".into(),
        ));
    }
    let available_ext = unsafe { entry.enumerate_instance_extension_properties(None)? };
    let has_debug_utils = available_ext.iter().any(|e| {
        e.extension_name_as_c_str()
            .is_ok_and(|n| n == ash::ext::debug_utils::NAME)
    });
    let debug_enabled = validation || has_debug_utils;

    let app = vk::ApplicationInfo::default()
        .application_name(c"fovea")
        .engine_name(c"fovea")
        .api_version(vk::API_VERSION_1_2);
    let layers: Vec<*const c_char> = if validation {
        vec![VALIDATION_LAYER.as_ptr()]
    } else {
        vec![]
    };
    let mut extensions: Vec<*const c_char> = if debug_enabled {
        vec![ash::ext::debug_utils::NAME.as_ptr()]
    } else {
        vec![]
    };
    extensions.extend(options.instance_extensions.iter().map(|e| e.as_ptr()));
    let sync_validation = validation && options.sync_validation;
    if sync_validation {
        extensions.push(ash::ext::validation_features::NAME.as_ptr());
    }
    let sync = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
    let mut features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&sync);
    let mut info = vk::InstanceCreateInfo::default()
        .application_info(&app)
        .enabled_layer_names(&layers)
        .enabled_extension_names(&extensions);
    if sync_validation {
        info = info.push_next(&mut features);
    }
    let instance = match &options.creator {
        Some(creator) => {
            let raw = unsafe { creator.create_instance(entry, &info) }.map_err(Error::Invalid)?;
            unsafe { ash::Instance::load(entry.static_fn(), raw) }
        }
        None => unsafe { entry.create_instance(&info, None)? },
    };
    Ok((instance, debug_enabled))
}

fn compute_queue_family(instance: &ash::Instance, physical: vk::PhysicalDevice) -> Option<u32> {
    let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
    families
        .iter()
        .position(|f| f.queue_flags.contains(vk::QueueFlags::COMPUTE) && f.timestamp_valid_bits > 0)
        .map(|i| i as u32)
}

fn list_devices(instance: &ash::Instance) -> Result<Vec<DeviceInfo>> {
    let physicals = unsafe { instance.enumerate_physical_devices()? };
    Ok(physicals
        .iter()
        .enumerate()
        .map(|(index, &p)| {
            let props = unsafe { instance.get_physical_device_properties(p) };
            let limits = props.limits;
            let v = props.api_version;
            let exts =
                unsafe { instance.enumerate_device_extension_properties(p) }.unwrap_or_default();
            let has_push = exts.iter().any(|e| {
                e.extension_name_as_c_str()
                    .is_ok_and(|n| n == ash::khr::push_descriptor::NAME)
            });
            let suitable = if vk::api_version_minor(v) < 2 && vk::api_version_major(v) == 1 {
                Err("needs Vulkan 1.2".to_string())
            } else if !has_push {
                Err("needs VK_KHR_push_descriptor".to_string())
            } else if compute_queue_family(instance, p).is_none() {
                Err("no compute queue with timestamps".to_string())
            } else {
                Ok(())
            };
            DeviceInfo {
                index,
                name: props
                    .device_name_as_c_str()
                    .map(|c| c.to_string_lossy().into_owned())
                    .unwrap_or_default(),
                kind: format!("{:?}", props.device_type),
                device_type: props.device_type,
                api_version: format!(
                    "{}.{}.{}",
                    vk::api_version_major(v),
                    vk::api_version_minor(v),
                    vk::api_version_patch(v)
                ),
                max_compute_workgroup_invocations: limits.max_compute_work_group_invocations,
                max_storage_buffer_range: limits.max_storage_buffer_range,
                max_texel_buffer_elements: limits.max_texel_buffer_elements,
                max_image_dimension_2d: limits.max_image_dimension2_d,
                max_push_constants_size: limits.max_push_constants_size,
                timestamp_period_ns: limits.timestamp_period,
                suitable,
            }
        })
        .collect())
}

fn choose_device<'a>(
    devices: &'a [DeviceInfo],
    selector: &DeviceSelector,
) -> Result<&'a DeviceInfo> {
    let found = match selector {
        DeviceSelector::Index(i) => devices
            .get(*i)
            .ok_or_else(|| Error::NoSuchDevice(i.to_string()))?,
        DeviceSelector::NameContains(s) => devices
            .iter()
            .find(|d| d.name.to_lowercase().contains(&s.to_lowercase()))
            .ok_or_else(|| Error::NoSuchDevice(s.clone()))?,
        DeviceSelector::Best => {
            let rank = |d: &DeviceInfo| match d.kind.as_str() {
                "DISCRETE_GPU" => 0,
                "INTEGRATED_GPU" => 1,
                "VIRTUAL_GPU" => 2,
                "CPU" => 3,
                _ => 4,
            };
            devices
                .iter()
                .filter(|d| d.suitable.is_ok())
                .min_by_key(|d| rank(d))
                .ok_or_else(|| {
                    let why: Vec<String> = devices
                        .iter()
                        .map(|d| {
                            format!(
                                "{}: {}",
                                d.name,
                                d.suitable.clone().err().unwrap_or_default()
                            )
                        })
                        .collect();
                    Error::NoSuitableDevice(if why.is_empty() {
                        "no Vulkan devices".into()
                    } else {
                        why.join("; ")
                    })
                })?
        }
    };
    if let Err(why) = &found.suitable {
        return Err(Error::NoSuitableDevice(format!("{}: {why}", found.name)));
    }
    Ok(found)
}
