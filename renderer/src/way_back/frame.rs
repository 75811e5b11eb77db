//! What every way back reads of a frame and what it leaves, and the interface its passes share.

use super::blur::BlurSettings;
use crate::error::Result;
use crate::graph::FrameRecorder;
use crate::passes::grid::GridFrame;
use crate::passes::tonemap::ToneTarget;
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
    /// The display image, when nothing reads the screen's radiance: a way back whose last pass
    /// can tone-map (the foveated blur) writes it there itself.
    pub display: Option<ToneTarget<'a>>,
}

/// What a way back leaves: radiance on the screen to tone-map, or the display image already
/// written (the blur's last axis wrote it).
pub enum ScreenOut<'a> {
    Radiance(&'a Image),
    Shown,
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
