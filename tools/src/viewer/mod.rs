//! `fovea view`'s window plumbing.
pub mod debug;
pub mod swapchain;
