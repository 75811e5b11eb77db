//! `fovea render --debug-views`: per frame the sampling-grid image (what was traced, before the
//! remap), a screen-space sample-density heat map with the gaze marked and the frame with that
//! heat map laid over it; once per run a plot of samples per pixel against eccentricity (VP vs
//! the acuity target vs uniform).

use crate::eval::density::{box_filter, density_plot, heatmap_rgba, overlay, samples_per_pixel};
use crate::output::write_png;
use anyhow::Result;
use fovea_renderer::pipeline::Renderer;
use glam::UVec2;
use std::path::{Path, PathBuf};

/// Share of the heat map in `debug_overlay`: enough to read the density, little enough to see
/// the scene under it.
const OVERLAY_WEIGHT: f32 = 0.45;

/// Eccentricity rings of the density plot.
const PLOT_RINGS: usize = 40;

pub struct DebugViews {
    out: PathBuf,
    screen: UVec2,
    grid: UVec2,
    pixels: Vec<u8>,
    frame: Vec<u8>,
}

impl DebugViews {
    pub fn new(out: &Path, screen: UVec2, grid: UVec2) -> DebugViews {
        DebugViews {
            out: out.to_path_buf(),
            screen,
            grid,
            pixels: Vec::new(),
            frame: Vec::new(),
        }
    }

    /// Writes `debug_grid_NNNN.png`, `debug_density_NNNN.png` and `debug_overlay_NNNN.png` for
    /// the frame just rendered (rendered with `FrameInput::read_grid`; the first view's).
    pub fn frame(&mut self, index: u32, renderer: &Renderer) -> Result<()> {
        renderer.read_grid_ldr(&mut self.pixels)?;
        write_png(
            &self.out.join(format!("debug_grid_{index:04}.png")),
            self.grid.x,
            self.grid.y,
            &self.pixels,
        )?;
        let space = renderer.space();
        // Far from the gaze single pixels get 0 or 1 samples: a box average over a few pixels
        // shows the density rather than the sample pattern.
        let radius = (self.screen.x / 160).max(2);
        let density = box_filter(
            &samples_per_pixel(space),
            self.screen.x,
            self.screen.y,
            radius,
        );
        let heat = heatmap_rgba(&density, self.screen.x, self.screen.y, space.gaze());
        write_png(
            &self.out.join(format!("debug_density_{index:04}.png")),
            self.screen.x,
            self.screen.y,
            &heat,
        )?;
        renderer.read_view_ldr(index as u64, 0, &mut self.frame)?;
        let laid_over = overlay(&self.frame, &heat, OVERLAY_WEIGHT);
        write_png(
            &self.out.join(format!("debug_overlay_{index:04}.png")),
            self.screen.x,
            self.screen.y,
            &laid_over,
        )
    }

    /// Writes `debug_density_plot.png` for the last frame's gaze (Visual-Polar runs only: the
    /// Cartesian density is 1 everywhere).
    pub fn finish(&self, renderer: &Renderer) -> Result<()> {
        match renderer.space().visual_polar() {
            Some(vp) => density_plot(&self.out.join("debug_density_plot.png"), vp, PLOT_RINGS),
            None => Ok(()),
        }
    }
}
