//! The engine's error type. Binaries wrap it with `anyhow` context.

use ash::vk;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error("Vulkan call failed: {0}")]
    Vulkan(#[from] vk::Result),
    #[error("the GPU was lost (VK_ERROR_DEVICE_LOST) while running pass '{last_pass}'")]
    DeviceLost { last_pass: String },
    #[error("cannot load the Vulkan library: {0}")]
    Loader(#[from] ash::LoadingError),
    #[error("no Vulkan device matches '{0}' (run `fovea info` to list devices)")]
    NoSuchDevice(String),
    #[error("no Vulkan device with a compute queue and the required features: {0}")]
    NoSuitableDevice(String),
    #[error("GPU memory allocation failed: {0}")]
    Allocation(#[from] gpu_allocator::AllocationError),
    #[error("shader '{0}' is not built into this binary")]
    UnknownShader(String),
    #[error("shader '{shader}': {reason}")]
    Shader { shader: String, reason: String },
    #[error("pass '{pass}': {reason}")]
    Binding { pass: String, reason: String },
    #[error("scene: {0}")]
    Scene(#[from] fovea_scene::SceneError),
    #[error("{0}")]
    Invalid(String),
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
