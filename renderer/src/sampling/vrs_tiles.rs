//! `vrs-tiles`: the foveation eye-tracked headsets ship through variable-rate shading, for a
//! path tracer: the screen in 16×16-pixel tiles, each traced at one sample per pixel, per 2×2 or
//! per 4×4 block — the coarsest rate whose density still meets Visual-Polar's at the tile's point
//! nearest the gaze, so no tile is sampled more sparsely than VP would sample it. One sample per
//! block, at the pixel nearest its centre (clamped to the screen); the other pixels are holes that
//! the way back fills (push-pull) before the same foveated blur. Against `vp` it measures what
//! quantising the density to the hardware's rates and tiles costs in samples, with screen-order
//! coherence. Paper layout and normalised axis only (the density is VP's radial one).
//! GLSL: sampling/vrs_tiles.glsl.

use super::{within, RadialLaw, SamplingSpace, SpaceCapabilities, VisualPolar, VisualPolarParams, VpLayout, WayBack};
use crate::error::{Error, Result};
use crate::layouts::SamplingParams;
use glam::{IVec2, UVec2, UVec4, Vec2, Vec4};
use std::f32::consts::TAU;

/// Pixels per tile side (the variable-rate image's texel on most GPUs).
pub const VRS_TILE: u32 = 16;

/// Blocks of rate×rate pixels share one sample; a tile gets the coarsest whose density
/// (1 / rate²) is at least VP's.
const RATES: [u32; 3] = [1, 2, 4];

/// Radius steps (pixels) of the scan for the rate thresholds.
const SCAN_STEP: f32 = 0.5;

#[derive(Clone, Copy, Debug)]
pub struct VrsTiles {
    /// The density the rates follow, re-centred with the gaze.
    axis: VisualPolar,
    /// Distances from the gaze beyond which rate 2 and rate 4 keep VP's density.
    coarse_from: [f32; 2],
}

impl VrsTiles {
    pub fn new(screen: UVec2, gaze: Vec2, params: VisualPolarParams) -> Result<VrsTiles> {
        let paper = params.layout == VpLayout::Paper && params.radial == RadialLaw::Acuity && params.eccentricity == super::Eccentricity::Normalized;
        if !paper {
            return Err(Error::Invalid("vrs tiles: follow the paper's Visual-Polar density only (layout = \"paper\", eccentricity = \"normalized\")".into()));
        }
        let axis = VisualPolar::new(screen, gaze, params)?;
        Ok(VrsTiles { axis, coarse_from: coarse_thresholds(&axis) })
    }

    /// Pixels per block side of the tile holding `pixel`.
    pub fn rate(&self, pixel: IVec2) -> u32 {
        let tile = VRS_TILE as f32;
        let lo = (pixel.as_vec2() / tile).floor() * tile;
        let g = self.axis.gaze();
        let d = (g.clamp(lo, lo + tile) - g).length();
        if d < self.coarse_from[0] {
            RATES[0]
        } else if d < self.coarse_from[1] {
            RATES[1]
        } else {
            RATES[2]
        }
    }

    /// Whether `pixel` traces its block's sample (the GPU's `sample_exists`).
    pub fn traces(&self, pixel: IVec2) -> bool {
        let screen = self.axis.screen().as_ivec2();
        if pixel.cmplt(IVec2::ZERO).any() || pixel.cmpge(screen).any() {
            return false;
        }
        let rate = self.rate(pixel) as i32;
        pixel == (pixel / rate * rate + rate / 2).min(screen - 1)
    }

    /// Samples per screen pixel Visual-Polar places `r` pixels from the gaze: columns per pixel
    /// along the radius times the column's rows per pixel of arc.
    pub fn vp_density(&self, r: f32) -> f32 {
        vp_density(&self.axis, r)
    }
}

fn vp_density(vp: &VisualPolar, r: f32) -> f32 {
    let r = r.max(SCAN_STEP);
    let h = 0.25;
    let du_dr = (vp.u_of_r(r + h) - vp.u_of_r((r - h).max(0.0))) / (r + h - (r - h).max(0.0));
    let columns = vp.grid_size().x as f32;
    let rows = vp.rows_in_column(vp.column_of(vp.u_of_r(r) * columns)) as f32;
    columns * du_dr * rows / (TAU * r)
}

/// For rates 2 and 4: the radius beyond which VP's density stays at or below 1 / rate² (scanned
/// from the farthest corner inwards, so a bump in the density cannot make a tile too coarse).
fn coarse_thresholds(vp: &VisualPolar) -> [f32; 2] {
    let far = vp.r_max();
    [RATES[1], RATES[2]].map(|rate| {
        let limit = 1.0 / (rate * rate) as f32;
        let mut r = far;
        while r > 0.0 && vp_density(vp, r) <= limit {
            r -= SCAN_STEP;
        }
        // Past the screen's farthest corner when no radius on it is that sparse.
        if r >= far { f32::MAX } else { (r + SCAN_STEP).max(0.0) }
    })
}

impl SamplingSpace for VrsTiles {
    fn name(&self) -> &'static str {
        "vrs-tiles"
    }
    fn shader_variant(&self) -> &'static str {
        "vrs_tiles"
    }
    fn grid_size(&self) -> UVec2 {
        self.axis.screen()
    }
    fn screen_size(&self) -> UVec2 {
        self.axis.screen()
    }
    /// The blocks of the current gaze's tiles (a sum over the screen: computed when a report
    /// asks, not on every gaze change).
    fn sample_count(&self) -> u64 {
        let s = self.axis.screen().as_ivec2();
        (0..s.y).flat_map(|y| (0..s.x).map(move |x| IVec2::new(x, y))).filter(|&p| self.traces(p)).count() as u64
    }
    /// gaze = (x, y, rate-2 radius, rate-4 radius), shape0.x = tile side (pixels).
    fn params(&self) -> SamplingParams {
        let (s, g) = (self.axis.screen(), self.axis.gaze());
        SamplingParams {
            grid: UVec4::new(s.x, s.y, s.x, s.y),
            gaze: Vec4::new(g.x, g.y, self.coarse_from[0], self.coarse_from[1]),
            shape0: Vec4::new(VRS_TILE as f32, 0.0, 0.0, 0.0),
            shape1: Vec4::ZERO,
        }
    }
    fn grid_to_screen(&self, grid: Vec2) -> Option<Vec2> {
        within(grid, self.axis.screen()).then_some(grid)
    }
    fn screen_to_grid(&self, screen: Vec2) -> Option<Vec2> {
        self.grid_to_screen(screen)
    }
    fn gaze(&self) -> Vec2 {
        self.axis.gaze()
    }
    fn set_gaze(&mut self, gaze: Vec2) -> Result<()> {
        self.axis = VisualPolar::new(self.axis.screen(), gaze, *self.axis.params())?;
        self.coarse_from = coarse_thresholds(&self.axis);
        Ok(())
    }
    fn blur_axis(&self) -> Option<&VisualPolar> {
        Some(&self.axis)
    }
    fn capabilities(&self) -> SpaceCapabilities {
        SpaceCapabilities { way_back: WayBack::Fill, temporal_filters: false, filters_note: "(its coarse tiles trace one pixel in 4 or 16)" }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_tile_is_sparser_than_visual_polar_and_each_block_traces_once() {
        let screen = UVec2::new(320, 360);
        let gaze = Vec2::new(120.0, 150.0);
        let s = VrsTiles::new(screen, gaze, VisualPolarParams::default()).unwrap();
        let vp = VisualPolar::new(screen, gaze, VisualPolarParams::default()).unwrap();
        let mut rates = [0u32; 5];
        for y in 0..screen.y as i32 {
            for x in 0..screen.x as i32 {
                let p = IVec2::new(x, y);
                let rate = s.rate(p);
                rates[rate as usize] += 1;
                // Every pixel of a coarse tile at least as dense as VP there (the fovea's VP
                // density may exceed one sample per pixel a little: rate 1 is the finest).
                let r = (p.as_vec2() + 0.5 - gaze).length();
                assert!(rate == 1 || 1.0 / (rate * rate) as f32 >= s.vp_density(r) * 0.999, "{p}: rate {rate}, VP {}", s.vp_density(r));
                // One traced pixel per block.
                let block = p / rate as i32 * rate as i32;
                let traced = (0..rate as i32).flat_map(|j| (0..rate as i32).map(move |i| block + IVec2::new(i, j))).filter(|&q| s.traces(q)).count();
                assert_eq!(traced, 1, "{p}");
            }
        }
        assert!(rates[1] > 0 && rates[2] > 0 && rates[4] > 0, "{rates:?}");
        // Quantised up, VRS traces more than VP but far fewer than the screen's pixels.
        let (n, vp_n, pixels) = (s.sample_count(), vp.sample_count(), (screen.x * screen.y) as u64);
        assert!(n > vp_n && n < pixels * 3 / 5, "{n} vs VP {vp_n}, {pixels} pixels");
        eprintln!("vrs tiles at 320×360: {n} samples, VP {vp_n}, rates (pixels) {rates:?}");
        assert!(VrsTiles::new(screen, gaze, VisualPolarParams { layout: VpLayout::ScreenClipped, ..Default::default() }).is_err());
    }
}
