//! One module per compute pass (or pass group: the denoisers, TAA): each owns its pipeline and
//! params struct, takes typed inputs and records into a `FrameRecorder`. The passes of the way
//! back to the screen are `crate::way_back`'s.

pub mod accumulate;
pub mod cross_eye;
pub mod denoise;
pub mod exposure;
pub mod grid;
pub mod raycast;
pub mod resampling;
pub mod taa;
pub mod tonemap;
pub mod trace;
pub mod trace_clear;

use crate::error::Result;
use crate::graph::{Bind, FrameRecorder};
use crate::vk::{ComputePipeline, Context};
use std::marker::PhantomData;
use std::sync::Arc;

/// A compute kernel: the shader a pass dispatches and its push-constant block (`()` for none).
pub trait Kernel {
    /// The shader under `shaders/`, without the extension and, for a kernel compiled per
    /// sampling space, without the variant (e.g. `passes/denoise/svgf_atrous`).
    const SHADER: &'static str;
    type Push: bytemuck::Pod;
}

/// A pass that dispatches one kernel: its pipeline, built once per context and shared
/// (`ComputePipeline::shared`). Each pass module names its kernel (`Kernel`) and adds its
/// `record`, which binds by name and calls `dispatch`.
pub struct Pass<K: Kernel> {
    pipeline: Arc<ComputePipeline>,
    kernel: PhantomData<K>,
}

impl<K: Kernel> Pass<K> {
    /// The kernel compiled for `variant` (`SamplingSpace::shader_variant` or `trace_variant`):
    /// shader `{SHADER}.{variant}`.
    pub fn new(ctx: &Arc<Context>, variant: &str) -> Result<Self> {
        Self::from_shader(ctx, &format!("{}.{variant}", K::SHADER))
    }

    /// A kernel compiled once (no variants).
    pub fn single(ctx: &Arc<Context>) -> Result<Self> {
        Self::from_shader(ctx, K::SHADER)
    }

    /// [`Pass::new`] compiled for `traversal` rather than the context's (a kernel that traces).
    pub fn for_traversal(
        ctx: &Arc<Context>,
        variant: &str,
        traversal: crate::traversal::Traversal,
    ) -> Result<Self> {
        let shader = format!("{}.{variant}", K::SHADER);
        let push = std::mem::size_of::<K::Push>() as u32;
        Ok(Pass {
            pipeline: ComputePipeline::shared_for(ctx, &shader, push, traversal)?,
            kernel: PhantomData,
        })
    }

    fn from_shader(ctx: &Arc<Context>, shader: &str) -> Result<Self> {
        let push = std::mem::size_of::<K::Push>() as u32;
        Ok(Pass {
            pipeline: ComputePipeline::shared(ctx, shader, push)?,
            kernel: PhantomData,
        })
    }

    /// Dispatches `threads` invocations; `name` labels the pass in the timings.
    pub(crate) fn dispatch(
        &self,
        rec: &mut FrameRecorder,
        name: &'static str,
        binds: &[Bind],
        push: &K::Push,
        threads: [u32; 3],
    ) -> Result<()> {
        rec.dispatch(name, &self.pipeline, binds, push_bytes(push), threads)
    }
}

/// One Visual-Polar kernel compiled for each layout (`//! variant paper` / `clipped`): lavapipe
/// pays for both sides of a branch, so the paper's layout gets a kernel without the
/// screen-clipped path.
pub(crate) struct VpLayoutPipelines {
    paper: std::sync::Arc<crate::vk::ComputePipeline>,
    clipped: std::sync::Arc<crate::vk::ComputePipeline>,
}

impl VpLayoutPipelines {
    /// `shader` without the variant suffix (e.g. `passes/remap`).
    pub fn new(
        ctx: &std::sync::Arc<crate::vk::Context>,
        shader: &str,
        push_size: u32,
    ) -> crate::error::Result<Self> {
        Self::with_prefix(ctx, &format!("{shader}."), push_size)
    }

    /// Variants `{prefix}paper` and `{prefix}clipped` (e.g. `passes/blur_grid.phi_`).
    pub fn with_prefix(
        ctx: &std::sync::Arc<crate::vk::Context>,
        prefix: &str,
        push_size: u32,
    ) -> crate::error::Result<Self> {
        Ok(VpLayoutPipelines {
            paper: crate::vk::ComputePipeline::shared(ctx, &format!("{prefix}paper"), push_size)?,
            clipped: crate::vk::ComputePipeline::shared(
                ctx,
                &format!("{prefix}clipped"),
                push_size,
            )?,
        })
    }

    /// The kernel for the space of `vp` (its flag slot, see VisualPolar::sampling_params): the
    /// `clipped` kernel is the general one (either layout, either ρ axis).
    pub fn for_space(&self, vp: &crate::layouts::SamplingParams) -> &crate::vk::ComputePipeline {
        if crate::sampling::params_need_general_kernel(vp) {
            &self.clipped
        } else {
            &self.paper
        }
    }
}

/// Bytes of a push-constant struct, as the recorder takes them.
pub(crate) fn push_bytes<T: bytemuck::Pod>(p: &T) -> &[u8] {
    bytemuck::bytes_of(p)
}
