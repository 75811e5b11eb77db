//! The fovea engine: records Vulkan compute command buffers that trace, filter and remap
//! foveated samples. Read the modules in pipeline order:
//! `scene` (what is traced, CPU side, crate `fovea_scene`) → `gpu_scene` (its upload; the
//! environment map's in `environment`) →
//! `sampling` (where samples go) → `passes` (trace; the denoisers; TAA; tonemap; accumulate) →
//! `way_back` (the sampling grid → the screen, as the space chooses) → `frame` (what a frame is
//! made of) → `view` (one eye's state) → `pipeline` (the engine: views, one submit per frame) →
//! `frames` (frames in flight).
//! `vk`, `graph`, `layouts` and `shaders` are the plumbing underneath; `traversal` picks the BVH
//! traversal the kernels that trace are compiled for.

pub mod environment;
pub mod error;
pub mod frame;
pub mod frames;
pub mod gpu_scene;
pub mod graph;
pub mod layouts;
pub mod passes;
pub mod pipeline;
pub mod sampling;
pub mod shaders;
pub mod texture_pack;
pub mod traversal;
pub mod view;
pub mod vk;
pub mod way_back;

pub use error::{Error, Result};
pub use fovea_scene as scene;
