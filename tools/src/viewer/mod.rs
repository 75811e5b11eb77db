//! `fovea view`'s window plumbing.
pub mod swapchain;
