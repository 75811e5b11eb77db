//! `fovea render`'s overview picture (`overview.png`): the last frame as the method rendered it,
//! the same frame at full cost (every pixel traced: Cartesian, with the same denoiser, TAA,
//! exposure and tone curve) and the method's samples per pixel as a heat map with the gaze.

use super::setup::Setup;
use crate::eval::density::{box_filter, heatmap_rgba, samples_per_pixel};
use crate::output::write_png;
use anyhow::Result;
use fovea_renderer::frame::{FrameInput, RenderSettings};
use fovea_renderer::gpu_scene::GpuScene;
use fovea_renderer::passes::exposure::Exposure;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::vk::Context;
use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Frames of history the full-cost frame is rendered with (the denoiser's and TAA's
/// accumulation settles within them), ending at the run's last frame.
pub const FULL_COST_HISTORY: usize = 8;

/// Gap between the panels, pixels.
const GAP: u32 = 4;

/// The inputs of the run's last frames, kept for the full-cost frame.
#[derive(Default)]
pub struct RecentFrames {
    inputs: VecDeque<FrameInput>,
}

impl RecentFrames {
    pub fn push(&mut self, input: FrameInput) {
        if self.inputs.len() == FULL_COST_HISTORY {
            self.inputs.pop_front();
        }
        self.inputs.push_back(input);
    }
}

/// What the overview is made of.
pub struct Overview<'a> {
    pub ctx: &'a Arc<Context>,
    pub setup: &'a Setup,
    /// The run's renderer after its last frame completed, and that frame's id.
    pub renderer: &'a Renderer,
    pub last_frame: u64,
    pub recent: &'a RecentFrames,
}

impl Overview<'_> {
    /// Renders the full-cost frame and writes `overview.png` into `out`; returns its path.
    pub fn write(&self, out: &Path) -> Result<PathBuf> {
        let screen = self.setup.screen();
        let (w, h) = (screen.x, screen.y);
        let mut foveated = Vec::new();
        self.renderer
            .read_view_ldr(self.last_frame, 0, &mut foveated)?;
        let full = self.full_cost()?;
        let space = self.renderer.space();
        // Far from the gaze single pixels get 0 or 1 samples: a box average shows the density.
        let density = box_filter(&samples_per_pixel(space), w, h, (w / 160).max(2));
        let heat = heatmap_rgba(&density, w, h, space.gaze());
        let panels = [&foveated, &full, &heat];
        let width = 3 * w + 2 * GAP;
        let mut picture = vec![255u8; (width * h * 4) as usize];
        for (i, panel) in panels.iter().enumerate() {
            let x0 = i as u32 * (w + GAP);
            for y in 0..h {
                let src = (y * w * 4) as usize..((y + 1) * w * 4) as usize;
                let dst = ((y * width + x0) * 4) as usize;
                picture[dst..dst + src.len()].copy_from_slice(&panel[src]);
            }
        }
        let path = out.join("overview.png");
        write_png(&path, width, h, &picture)?;
        Ok(path)
    }

    /// The run's last frame with every pixel traced: a Cartesian renderer with the run's
    /// filters over its last frames' inputs, displayed at the last frame's exposure.
    fn full_cost(&self) -> Result<Vec<u8>> {
        let exposure = self.renderer.frame_exposure(self.last_frame)?;
        let settings = RenderSettings {
            exposure: Exposure::Manual(exposure),
            ..self.setup.settings
        };
        let spaces = vec![Box::new(fovea_renderer::sampling::Cartesian::new(
            self.setup.screen(),
        ))
            as Box<dyn fovea_renderer::sampling::SamplingSpace>];
        let scene = GpuScene::upload(self.ctx, &self.setup.scene)?;
        let mut renderer = Renderer::with_views(self.ctx, scene, spaces, settings, 1)?;
        let mut last = None;
        for input in &self.recent.inputs {
            let mut first_view = FrameInput::views(&input.view_inputs()[..1], input.frame_index)?;
            first_view.frame_seconds = input.frame_seconds;
            let frame = renderer.submit(&first_view, None)?;
            renderer.wait_frame(frame)?;
            last = Some(frame);
        }
        let mut pixels = Vec::new();
        if let Some(frame) = last {
            renderer.read_view_ldr(frame, 0, &mut pixels)?;
        }
        Ok(pixels)
    }
}
