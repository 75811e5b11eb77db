//! What `fovea xr` (tools/src/commands/xr.rs) builds on: the engine's Vulkan through the OpenXR
//! runtime and its swapchain, the gaze of each frame, and the per-frame log.

pub mod frame_log;
pub mod gaze;
pub mod vulkan;
