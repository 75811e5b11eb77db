//! `uniform-budget`: a regular grid coarser than the screen holding as many samples as another
//! space (Visual-Polar's), brought to the screen by bilinear upscaling — the comparator that
//! spends the foveated budget uniformly. Same kernels as Cartesian (`cartesian.glsl` scales the
//! texel to the screen when the grid is smaller).

use super::{within, SamplingSpace, SpaceCapabilities, WayBack};
use crate::error::{Error, Result};
use crate::layouts::SamplingParams;
use glam::{UVec2, UVec4, Vec2, Vec4};

#[derive(Clone, Copy, Debug)]
pub struct UniformBudget {
    pub screen: UVec2,
    pub grid: UVec2,
    /// Recorded for reports; uniform sampling does not depend on it.
    pub gaze: Vec2,
}

impl UniformBudget {
    /// The regular grid with the screen's aspect and about `samples` texels (at most one per pixel).
    pub fn with_samples(screen: UVec2, samples: u64) -> Result<UniformBudget> {
        let pixels = screen.x as f64 * screen.y as f64;
        if screen.x == 0 || screen.y == 0 || samples == 0 {
            return Err(Error::Invalid(format!(
                "uniform budget: {samples} samples over a {}×{} screen",
                screen.x, screen.y
            )));
        }
        let scale = (samples as f64 / pixels).sqrt().min(1.0);
        let axis = |n: u32| ((n as f64 * scale).round() as u32).clamp(1, n);
        Ok(UniformBudget {
            screen,
            grid: UVec2::new(axis(screen.x), axis(screen.y)),
            gaze: screen.as_vec2() * 0.5,
        })
    }

    fn scale(&self) -> Vec2 {
        self.screen.as_vec2() / self.grid.as_vec2()
    }
}

impl SamplingSpace for UniformBudget {
    fn name(&self) -> &'static str {
        "uniform-budget"
    }
    fn shader_variant(&self) -> &'static str {
        "cartesian"
    }
    fn grid_size(&self) -> UVec2 {
        self.grid
    }
    fn screen_size(&self) -> UVec2 {
        self.screen
    }
    fn sample_count(&self) -> u64 {
        self.grid.x as u64 * self.grid.y as u64
    }
    fn params(&self) -> SamplingParams {
        SamplingParams {
            grid: UVec4::new(self.grid.x, self.grid.y, self.screen.x, self.screen.y),
            gaze: Vec4::new(self.gaze.x, self.gaze.y, 0.0, 0.0),
            shape0: Vec4::ZERO,
            shape1: Vec4::ZERO,
        }
    }
    fn grid_to_screen(&self, grid: Vec2) -> Option<Vec2> {
        within(grid, self.grid).then_some(grid * self.scale())
    }
    fn screen_to_grid(&self, screen: Vec2) -> Option<Vec2> {
        within(screen, self.screen).then_some(screen / self.scale())
    }
    fn gaze(&self) -> Vec2 {
        self.gaze
    }
    fn set_gaze(&mut self, gaze: Vec2) -> Result<()> {
        self.gaze = gaze;
        Ok(())
    }
    fn capabilities(&self) -> SpaceCapabilities {
        // The denoisers' Cartesian addressing takes the grid for the screen (no scaled
        // reprojection yet), so they and TAA are refused rather than run wrong.
        SpaceCapabilities {
            way_back: WayBack::Upscale,
            temporal_filters: false,
            filters_note: "(its grid is coarser than the screen)",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grid_keeps_the_budget_and_the_aspect() {
        let s = UniformBudget::with_samples(UVec2::new(1280, 1440), 360_000).unwrap();
        assert!(
            (s.sample_count() as f64 / 360_000.0 - 1.0).abs() < 0.01,
            "{:?}",
            s.grid
        );
        assert!((s.grid.x as f32 / s.grid.y as f32 - 1280.0 / 1440.0).abs() < 0.01);
        let p = Vec2::new(100.5, 700.25);
        let back = s.grid_to_screen(s.screen_to_grid(p).unwrap()).unwrap();
        assert!((back - p).length() < 1e-3);
        // Never more than one sample per pixel.
        assert_eq!(
            UniformBudget::with_samples(UVec2::new(64, 72), 1 << 20)
                .unwrap()
                .grid,
            UVec2::new(64, 72)
        );
        assert!(UniformBudget::with_samples(UVec2::new(64, 72), 0).is_err());
    }
}
