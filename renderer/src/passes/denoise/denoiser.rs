//! What a denoiser provides to the registry (`passes::denoise`): its parameters
//! (`DenoiserParams`: name, profile section, validation, construction) and its per-eye passes
//! and state (`Denoiser`), recorded once per frame over the view's `GridFrame`.

use crate::error::Result;
use crate::graph::FrameRecorder;
use crate::passes::grid::{GradientTargets, GridFrame};
use crate::vk::{Context, Image};
use glam::UVec2;
use serde::de::DeserializeOwned;
use std::any::Any;
use std::fmt::Debug;
use std::sync::Arc;

/// A denoiser with its per-eye state (what its `DenoiserParams::build` makes), between the
/// tracer and the way back to the screen.
pub trait Denoiser: Any {
    /// GPU bytes of the history carried between frames.
    fn history_bytes(&self) -> u64;

    /// Dispatches one frame records at most.
    fn max_passes(&self) -> u32;

    /// Records what must run before the tracer, while the G-buffer still holds last frame.
    fn record_before_trace(&mut self, rec: &mut FrameRecorder, frame: &GridFrame) -> Result<()> {
        let _ = (rec, frame);
        Ok(())
    }

    /// What the tracer's gradient kernel variant re-shades and writes, for a denoiser whose
    /// parameters say `NEEDS_GRADIENTS`.
    fn gradient_targets(&self) -> Option<GradientTargets<'_>> {
        None
    }

    /// Records the denoiser over this frame's G-buffer; returns the denoised radiance
    /// (grid-sized).
    fn record(&mut self, rec: &mut FrameRecorder, frame: &GridFrame) -> Result<&Image>;

    /// The denoiser as `Any`, for callers that inspect one kind's state (`downcast_ref`).
    fn as_any(&self) -> &dyn Any;
}

impl dyn Denoiser {
    /// This denoiser as a `T`, when it is one.
    pub fn downcast_ref<T: Denoiser>(&self) -> Option<&T> {
        self.as_any().downcast_ref()
    }
}

/// A denoiser's parameters: `Default` is its paper's, serde reads its render-profile section
/// (`[NAME]`, every key optional) onto those defaults.
pub trait DenoiserParams: Copy + Default + PartialEq + Debug + DeserializeOwned + 'static {
    /// Its `--denoiser` name, its render-profile section and its place in the viewer's cycle.
    const NAME: &'static str;
    /// Whether the tracer must re-shade gradient samples (its `*_gradients` variant) and keep the
    /// visibility they are projected from.
    const NEEDS_GRADIENTS: bool = false;

    fn validate(&self) -> Result<()>;

    /// The denoiser for a grid of `grid` texels; `variant` is the sampling space's kernel
    /// variant (`SamplingSpace::shader_variant`).
    fn build(&self, ctx: &Arc<Context>, grid: UVec2, variant: &str) -> Result<Box<dyn Denoiser>>;

    /// Completes these parameters from the other denoisers' (`others`, by name), once every
    /// profile section is read (A-SVGF's SVGF stages take `[svgf]`).
    fn complete(&mut self, others: &dyn OtherParams) {
        let _ = others;
    }
}

/// The registered denoisers' parameters by name, for `DenoiserParams::complete`.
pub trait OtherParams {
    fn params(&self, name: &str) -> Option<&dyn Any>;
}

/// `DenoiserParams` as a trait object: what `DenoiserSettings` asks of whichever denoiser it
/// holds.
pub(crate) trait ErasedParams {
    fn name(&self) -> &'static str;
    fn needs_gradients(&self) -> bool;
    fn validate(&self) -> Result<()>;
    fn build(&self, ctx: &Arc<Context>, grid: UVec2, variant: &str) -> Result<Box<dyn Denoiser>>;
    fn complete(&mut self, others: &dyn OtherParams);
    fn as_any(&self) -> &dyn Any;
}

impl<P: DenoiserParams> ErasedParams for P {
    fn name(&self) -> &'static str {
        P::NAME
    }
    fn needs_gradients(&self) -> bool {
        P::NEEDS_GRADIENTS
    }
    fn validate(&self) -> Result<()> {
        DenoiserParams::validate(self)
    }
    fn build(&self, ctx: &Arc<Context>, grid: UVec2, variant: &str) -> Result<Box<dyn Denoiser>> {
        DenoiserParams::build(self, ctx, grid, variant)
    }
    fn complete(&mut self, others: &dyn OtherParams) {
        DenoiserParams::complete(self, others)
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
}
