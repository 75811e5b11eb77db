//! What every way back reads of a frame and what it leaves, and the interface its passes share.

use super::blur::BlurSettings;
use crate::error::Result;
use crate::graph::FrameRecorder;
use crate::layouts::SamplingParams;
use crate::passes::taa::ScreenTaaFrame;
use crate::passes::tonemap::ToneTarget;
use crate::sampling::SamplingSpace;
use crate::vk::{Buffer, Image};

/// One frame of one view, as its way back reads it.
pub struct WayBackFrame<'a> {
    /// The view's space this frame (its gaze, its blur axis).
    pub space: &'a dyn SamplingSpace,
    /// `space.params()`, as the `sampling` buffer holds them.
    pub params: SamplingParams,
    /// The grid's radiance: the trace's, denoised and resolved where those ran.
    pub grid: &'a Image,
    /// The frame's uniform buffers and the space's table (the space's kernels read them).
    pub frame_data: &'a Buffer,
    pub sampling: &'a Buffer,
    pub sampling_table: &'a Buffer,
    pub blur: &'a BlurSettings,
    /// The screen-space TAA's inputs, on frames jittered for TAA.
    pub taa: Option<ScreenTaaFrame<'a>>,
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
