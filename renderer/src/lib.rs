//! The fovea engine: records Vulkan compute command buffers that trace, filter and remap
//! foveated samples. Read the modules in pipeline order:
//! `scene` (what is traced, CPU side, crate `fovea_scene`) → `gpu_scene` (its upload; the
//! environment map's in `environment`) →
//! `sampling` (where samples go) → `passes` (trace; mip_phi, remap, blur; tonemap; accumulate) →
//! `to_screen` (VP grid → screen) → `view` (one eye's state) → `pipeline` (the engine: views,
//! one submit per frame) → `frames` (frames in flight).
//! `vk`, `graph`, `layouts` and `shaders` are the plumbing underneath; `traversal` picks the BVH
//! traversal the kernels that trace are compiled for.

pub mod environment;
pub mod error;
pub mod fill_to_screen;
pub mod frames;
pub mod gpu_scene;
pub mod graph;
pub mod layouts;
pub mod passes;
pub mod pipeline;
pub mod sampling;
pub mod shaders;
pub mod texture_pack;
pub mod to_screen;
pub mod traversal;
pub mod view;
pub mod vk;

pub use error::{Error, Result};
pub use fovea_scene as scene;
