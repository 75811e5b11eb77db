//! What every way back reads of a frame and what it leaves, and the interface its passes share.

use super::blur::{BlurSettings, PendingBlur};
use crate::error::Result;
use crate::graph::FrameRecorder;
use crate::passes::grid::GridFrame;
use crate::sampling::SamplingSpace;
use crate::vk::Image;
use glam::Vec2;

/// One frame of one view, as its way back reads it.
pub struct WayBackFrame<'a> {
    /// The view's space this frame (its gaze, its blur axis).
    pub space: &'a dyn SamplingSpace,
    /// The sampling grid's frame: its buffers, its G-buffer and this frame's space parameters
    /// (`current`, as the `sampling` buffer holds them).
    pub grid: GridFrame<'a>,
    /// The grid's radiance: the trace's, denoised and resolved where those ran.
    pub radiance: &'a Image,
    pub blur: &'a BlurSettings,
    /// Where the tracer put this frame's samples inside their texel (`TaaSettings::jitter`), on
    /// frames jittered for TAA.
    pub jitter: Option<Vec2>,
}

/// What a way back leaves: radiance on the screen, or radiance whose foveated blur is still to
/// record (its last axis can write the display image itself, one full-screen pass fewer than a
/// separate tone mapping).
pub enum ScreenOut<'a> {
    Radiance(&'a Image),
    Unblurred(PendingBlur<'a>),
}

impl<'a> ScreenOut<'a> {
    /// The screen radiance the exposure meter reads.
    pub fn metered(&self) -> &'a Image {
        match self {
            ScreenOut::Radiance(image) => image,
            ScreenOut::Unblurred(pending) => pending.src,
        }
    }

    /// The final screen radiance, recording a pending blur.
    pub fn into_radiance(self, rec: &mut FrameRecorder) -> Result<&'a Image> {
        match self {
            ScreenOut::Radiance(image) => Ok(image),
            ScreenOut::Unblurred(pending) => pending.radiance(rec),
        }
    }
}

/// The passes of one way back with their screen-sized images, made once for a view.
pub trait WayBackPasses {
    /// Records the way back of `frame`.
    fn record<'a>(
        &'a mut self,
        rec: &mut FrameRecorder,
        frame: &WayBackFrame<'a>,
    ) -> Result<ScreenOut<'a>>;

    /// Dispatches it records beyond the allowance every view has (`View::max_passes`).
    fn extra_passes(&self) -> u32 {
        0
    }

    /// GPU bytes of the screen-space TAA history it carries between frames.
    fn taa_history_bytes(&self) -> u64 {
        0
    }
}
