//! `VisualPolar` as a sampling space (`SamplingSpace`): its grid, its GPU parameters and table,
//! its trace tiles and its way back (the remap). The mapping itself is `visual_polar.rs`.

use super::trace_tiles::{visual_polar_tiles, TraceTiles};
use super::visual_polar::{RadialLaw, VisualPolar, VpLayout};
use super::{SamplingSpace, SpaceCapabilities, WayBack};
use crate::error::Result;
use crate::layouts::SamplingParams;
use glam::{UVec2, Vec2};

/// The tracer's view of the space: one sample per kept texel; the GPU twin is
/// `shaders/sampling/visual_polar.glsl` (kernel variant `visual_polar`). With the paper's layout
/// samples may land off the screen (the r_max circle covers the corners); they are traced, as in
/// the paper. The screen-clipped layout keeps them on it.
impl SamplingSpace for VisualPolar {
    fn name(&self) -> &'static str {
        match (self.params().radial, self.log_polar()) {
            (RadialLaw::Composite(_), _) => "composite",
            (_, Some(_)) => "log-polar",
            _ if self.headset().is_some() => "vp-headset",
            _ if self.params().layout == VpLayout::ScreenClipped => "vp-screen-clipped",
            _ if self.params().layout == VpLayout::ScreenAware => "vp-screen-aware",
            _ => "vp",
        }
    }
    /// The denoisers' and TAA's grid addressing: the paper's, or the screen-clipped layout's
    /// (its per-column arcs, `shaders/sampling/visual_polar_clipped_grid.glsl`).
    fn shader_variant(&self) -> &'static str {
        match self.params().layout {
            VpLayout::Paper => "visual_polar",
            VpLayout::ScreenClipped | VpLayout::ScreenAware => "visual_polar_clipped",
        }
    }
    /// `visual_polar_polynomial`: specialised for the paper's layout, normalised axis and quartic
    /// inverse CDF (the default), `visual_polar` the same with the exact inverse; `log_polar`: the
    /// paper's layout with the radial law read at run time; otherwise the general kernel
    /// (`visual_polar_clipped`: either layout, either axis).
    fn trace_variant(&self) -> &'static str {
        match (self.params().layout, self.headset().is_some()) {
            _ if self.log_polar().is_some() => "log_polar",
            (VpLayout::Paper, false) if !self.exact_inverse_cdf() => "visual_polar_polynomial",
            (VpLayout::Paper, false) => "visual_polar",
            _ => "visual_polar_clipped",
        }
    }
    fn grid_size(&self) -> UVec2 {
        VisualPolar::grid_size(self)
    }
    fn screen_size(&self) -> UVec2 {
        self.screen()
    }
    fn sample_count(&self) -> u64 {
        VisualPolar::sample_count(self)
    }
    fn params(&self) -> SamplingParams {
        self.sampling_params()
    }
    /// The per-column arcs (`column_table`): full circles in the paper's layout.
    fn write_sampling_table(&self, out: &mut Vec<[f32; 4]>) {
        self.write_column_table(out);
    }
    /// `None` outside the grid and in clipped texels (the texel is `floor(grid)`).
    fn grid_to_screen(&self, grid: Vec2) -> Option<Vec2> {
        if !grid.is_finite() {
            return None;
        }
        let t = grid.floor();
        // Range-check in f32 before converting, so huge values cannot wrap into the grid.
        if t.x < 0.0
            || t.y < 0.0
            || t.x >= VisualPolar::grid_size(self).x as f32
            || t.y >= VisualPolar::grid_size(self).y as f32
        {
            return None;
        }
        self.is_valid_texel(t.as_ivec2())
            .then(|| self.vp_to_screen(grid))
    }
    /// `None` where no texel samples the position: beyond r_max (only possible on screen with
    /// `RadiusMode::Fixed`). Off-screen positions inside r_max do have samples. r = r_max itself
    /// (the farthest corner) maps to u = 1 up to rounding and is kept inside the last column.
    fn screen_to_grid(&self, screen: Vec2) -> Option<Vec2> {
        if !screen.is_finite() {
            return None;
        }
        let g = self.screen_to_vp(screen);
        let w = VisualPolar::grid_size(self).x as f32;
        if !(g.x >= 0.0
            && g.x <= w * (1.0 + 1e-5)
            && g.y >= 0.0
            && g.y < VisualPolar::grid_size(self).y as f32)
        {
            return None;
        }
        let last = f32::from_bits(w.to_bits() - 1); // largest f32 below w (w ≥ 1)
        Some(Vec2::new(g.x.min(last), g.y))
    }
    fn gaze(&self) -> Vec2 {
        VisualPolar::gaze(self)
    }
    fn set_gaze(&mut self, gaze: Vec2) -> Result<()> {
        *self = VisualPolar::new(self.screen(), gaze, *self.params())?;
        Ok(())
    }
    fn visual_polar(&self) -> Option<&VisualPolar> {
        Some(self)
    }
    fn blur_axis(&self) -> Option<&VisualPolar> {
        Some(self)
    }
    /// The fovea's clipped tiles and, in the paper's layout, tiles far off the screen are idle.
    fn trace_tiles(&self, cull: bool, tiles: &mut TraceTiles) {
        visual_polar_tiles(self, cull, tiles);
    }
    /// Every layout runs the filters: the screen-clipped one addresses its grid through the
    /// per-column arcs of this frame and the previous one (`DenoiseFrame::sampling_table`).
    fn capabilities(&self) -> SpaceCapabilities {
        SpaceCapabilities {
            way_back: WayBack::Remap,
            temporal_filters: true,
            filters_note: "",
        }
    }
}
