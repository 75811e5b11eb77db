//! Uniform Cartesian sampling: one sample per screen pixel (the quality and cost reference).

use super::SamplingSpace;
use crate::error::Result;
use crate::layouts::SamplingParams;
use glam::{UVec2, UVec4, Vec2, Vec4};

#[derive(Clone, Copy, Debug)]
pub struct Cartesian {
    pub screen: UVec2,
    /// Recorded for reports; uniform sampling does not depend on it.
    pub gaze: Vec2,
}

impl Cartesian {
    /// Uniform sampling of `screen`, gaze at its centre.
    pub fn new(screen: UVec2) -> Cartesian {
        Cartesian {
            screen,
            gaze: screen.as_vec2() * 0.5,
        }
    }
}

impl SamplingSpace for Cartesian {
    fn name(&self) -> &'static str {
        "cartesian"
    }
    fn shader_variant(&self) -> &'static str {
        "cartesian"
    }
    fn grid_size(&self) -> UVec2 {
        self.screen
    }
    fn screen_size(&self) -> UVec2 {
        self.screen
    }
    fn sample_count(&self) -> u64 {
        self.screen.x as u64 * self.screen.y as u64
    }
    fn params(&self) -> SamplingParams {
        SamplingParams {
            grid: UVec4::new(self.screen.x, self.screen.y, self.screen.x, self.screen.y),
            gaze: Vec4::new(self.gaze.x, self.gaze.y, 0.0, 0.0),
            shape0: Vec4::ZERO,
            shape1: Vec4::ZERO,
        }
    }
    fn grid_to_screen(&self, grid: Vec2) -> Option<Vec2> {
        super::within(grid, self.screen).then_some(grid)
    }
    fn screen_to_grid(&self, screen: Vec2) -> Option<Vec2> {
        self.grid_to_screen(screen)
    }
    fn gaze(&self) -> Vec2 {
        self.gaze
    }
    fn set_gaze(&mut self, gaze: Vec2) -> Result<()> {
        self.gaze = gaze;
        Ok(())
    }
}
