//! `linear-falloff` (Weier et al. 2016 as configured by Koskela et al. 2019, comparators.md §B):
//! every screen pixel, traced with probability 1 inside 10°, falling linearly to 20 % at 20° and
//! 20 % beyond; the rest killed at random each frame. Koskela gave it 1.5× Visual-Polar's sample
//! count: the probabilities are scaled (capped at 1) until the expected count with the gaze at the
//! centre is that budget. Degrees are Visual-Polar's eccentricity axis for the same profile, so
//! both methods foveate around the same circles; the way back is push-pull hole filling and the
//! same foveated blur. GLSL: sampling/linear_falloff.glsl.

use super::random::unit_hash;
use super::{within, SamplingSpace, SpaceCapabilities, VisualPolar, VisualPolarParams, WayBack};
use crate::error::{Error, Result};
use crate::layouts::{SamplingParams, SPARSE_SALT_KEEP};
use glam::{UVec2, UVec4, Vec2, Vec4};

/// The falloff's shape in degrees (Koskela 2019's configuration of Weier et al.).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FalloffShape {
    pub inner_deg: f32,
    pub outer_deg: f32,
    /// Probability at and beyond `outer_deg` before the budget scale.
    pub floor: f32,
}

impl Default for FalloffShape {
    fn default() -> Self {
        FalloffShape {
            inner_deg: 10.0,
            outer_deg: 20.0,
            floor: 0.2,
        }
    }
}

/// Koskela et al. 2019: linear falloff got 1.5× Visual-Polar's samples.
pub const FALLOFF_BUDGET_OF_VP: f64 = 1.5;

#[derive(Clone, Copy, Debug)]
pub struct LinearFalloff {
    /// The eccentricity axis (and the blur's shape), re-centred with the gaze.
    axis: VisualPolar,
    shape: FalloffShape,
    inner_px: f32,
    outer_px: f32,
    /// Probability multiplier that meets the budget (≥ 1 raises the floor and widens the core).
    scale: f32,
}

impl LinearFalloff {
    /// The falloff on `screen` with `vp`'s eccentricity axis, scaled so that with the gaze at the
    /// centre it traces `budget_of_vp` × Visual-Polar's sample count (on average).
    pub fn new(
        screen: UVec2,
        vp: VisualPolarParams,
        shape: FalloffShape,
        budget_of_vp: f64,
    ) -> Result<LinearFalloff> {
        if !(shape.inner_deg > 0.0
            && shape.outer_deg > shape.inner_deg
            && (0.0..=1.0).contains(&shape.floor))
        {
            return Err(Error::Invalid(format!("linear falloff: needs 0 < inner < outer degrees and a floor in [0, 1], got {shape:?}")));
        }
        if !(budget_of_vp.is_finite() && budget_of_vp > 0.0) {
            return Err(Error::Invalid(format!(
                "linear falloff: budget {budget_of_vp} × Visual-Polar's samples must be positive"
            )));
        }
        let centre = screen.as_vec2() * 0.5;
        let axis = VisualPolar::new(screen, centre, vp)?;
        let mut space = LinearFalloff {
            axis,
            shape,
            inner_px: 0.0,
            outer_px: 0.0,
            scale: 1.0,
        };
        space.set_radii();
        let target =
            (budget_of_vp * axis.sample_count() as f64).min(screen.x as f64 * screen.y as f64);
        space.scale = space.scale_for(target);
        Ok(space)
    }

    fn set_radii(&mut self) {
        self.inner_px = self.axis.radius_of_eccentricity(self.shape.inner_deg);
        self.outer_px = self.axis.radius_of_eccentricity(self.shape.outer_deg);
    }

    /// As `falloff_keep_probability` in the GLSL.
    pub fn keep_probability(&self, r: f32) -> f32 {
        let ramp =
            ((r - self.inner_px) / (self.outer_px - self.inner_px).max(1e-6)).clamp(0.0, 1.0);
        (self.scale * (1.0 + (self.shape.floor - 1.0) * ramp)).min(1.0)
    }

    fn expected_count(&self) -> f64 {
        let size = self.axis.screen();
        let gaze = self.axis.gaze();
        let mut sum = 0.0;
        for y in 0..size.y {
            for x in 0..size.x {
                sum += self.keep_probability((Vec2::new(x as f32, y as f32) + 0.5 - gaze).length())
                    as f64;
            }
        }
        sum
    }

    /// The scale whose expected count is `target` (bisection: the count grows with the scale).
    fn scale_for(&mut self, target: f64) -> f32 {
        let (mut lo, mut hi) = (0.0f32, 1.0f32);
        loop {
            self.scale = hi;
            if self.expected_count() >= target || hi > 1e4 {
                break;
            }
            lo = hi;
            hi *= 2.0;
        }
        for _ in 0..24 {
            self.scale = 0.5 * (lo + hi);
            if self.expected_count() < target {
                lo = self.scale;
            } else {
                hi = self.scale;
            }
        }
        hi
    }

    pub fn scale(&self) -> f32 {
        self.scale
    }

    /// Whether the frame (`frame`, `seed` as in FrameData.frame) traces `texel`: the GPU's rule.
    pub fn keeps(&self, texel: UVec2, frame: u32, seed: u32) -> bool {
        let r = (texel.as_vec2() + 0.5 - self.axis.gaze()).length();
        unit_hash(texel.to_array(), frame, seed, SPARSE_SALT_KEEP) < self.keep_probability(r)
    }

    /// The pixels one frame traces.
    pub fn traced_count(&self, frame: u32, seed: u32) -> u64 {
        let size = self.axis.screen();
        (0..size.y)
            .flat_map(|y| (0..size.x).map(move |x| UVec2::new(x, y)))
            .filter(|&t| self.keeps(t, frame, seed))
            .count() as u64
    }
}

impl SamplingSpace for LinearFalloff {
    fn name(&self) -> &'static str {
        "linear-falloff"
    }
    fn shader_variant(&self) -> &'static str {
        "linear_falloff"
    }
    fn grid_size(&self) -> UVec2 {
        self.axis.screen()
    }
    fn screen_size(&self) -> UVec2 {
        self.axis.screen()
    }
    /// The expected count for the current gaze (the traced count varies from frame to frame);
    /// a sum over the screen, so computed when a report asks, not on every gaze change.
    fn sample_count(&self) -> u64 {
        self.expected_count().round() as u64
    }
    fn params(&self) -> SamplingParams {
        let (s, g) = (self.axis.screen(), self.axis.gaze());
        SamplingParams {
            grid: UVec4::new(s.x, s.y, s.x, s.y),
            gaze: Vec4::new(g.x, g.y, self.inner_px, self.outer_px),
            shape0: Vec4::new(self.shape.floor, self.scale, 0.0, 0.0),
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
        self.set_radii();
        Ok(())
    }
    fn blur_axis(&self) -> Option<&VisualPolar> {
        Some(&self.axis)
    }
    fn capabilities(&self) -> SpaceCapabilities {
        SpaceCapabilities {
            way_back: WayBack::Fill,
            temporal_filters: false,
            filters_note: "(its pixels are killed at random each frame)",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_budget_is_met_and_the_shape_kept() {
        let screen = UVec2::new(320, 360);
        let vp = VisualPolarParams::default();
        let s =
            LinearFalloff::new(screen, vp, FalloffShape::default(), FALLOFF_BUDGET_OF_VP).unwrap();
        let vp_count = VisualPolar::new(screen, screen.as_vec2() * 0.5, vp)
            .unwrap()
            .sample_count() as f64;
        assert!(
            (s.sample_count() as f64 / (1.5 * vp_count) - 1.0).abs() < 0.002,
            "{} vs {}",
            s.sample_count(),
            vp_count
        );
        // Full rate in the core, never rising outwards.
        assert_eq!(s.keep_probability(0.0), 1.0);
        let p: Vec<f32> = (0..400).map(|r| s.keep_probability(r as f32)).collect();
        assert!(p.windows(2).all(|w| w[1] <= w[0]));
        // One frame's traced pixels scatter around the expectation (binomial, σ ≪ 1 %).
        let traced = s.traced_count(0, 1) as f64;
        assert!(
            (traced / s.sample_count() as f64 - 1.0).abs() < 0.02,
            "{traced}"
        );
        // A budget below the unscaled shape's count lowers the probabilities everywhere.
        let low = LinearFalloff::new(screen, vp, FalloffShape::default(), 0.2).unwrap();
        assert!(low.scale() < 1.0 && low.keep_probability(0.0) < 1.0);
        assert!(LinearFalloff::new(
            screen,
            vp,
            FalloffShape {
                floor: 1.5,
                ..Default::default()
            },
            1.5
        )
        .is_err());
    }
}
