//! Thin owned wrappers over ash: context (instance, device, allocator, validation counter),
//! buffers and images that free themselves, reflected compute pipelines.

mod context;
mod pipeline;
mod resources;
mod validation;

pub use context::{
    Context, ContextOptions, DeviceCreator, DeviceInfo, DeviceSelector, EngineCounters,
};
pub use pipeline::{BindingInfo, ComputePipeline};
pub use resources::{color_range, format_bytes, next_resource_id, Buffer, Image, ResourceId};
pub use validation::ValidationCounter;
