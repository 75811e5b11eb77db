//! `pixel-blocks` (Mohanto, Klunge and Staadt 2023, comparators.md §F): a fovea of single pixels
//! within 5.2°, 2×2 blocks to 17°, 4×4 blocks beyond, each unit tracing τ samples — their 32 / 16
//! / 8 spp are offline, so the ratios are kept at a real-time 4 / 2 / 1 — and every missing pixel
//! filled by bilinear interpolation between the block centres of its level (passes/block_fill).
//! Degrees are Visual-Polar's eccentricity axis for the same profile, as for linear falloff.
//! The grid is an atlas of the three levels (see `sampling/pixel_blocks.glsl`); units outside
//! their region hold no sample (the rays are discarded before tracing, as in the paper).

use super::{SamplingSpace, SpaceCapabilities, VisualPolar, VisualPolarParams, WayBack};
use crate::error::{Error, Result};
use crate::layouts::SamplingParams;
use glam::{IVec2, UVec2, UVec4, Vec2, Vec4};

/// The regions and sample counts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlockShape {
    pub fovea_deg: f32,
    pub intermediate_deg: f32,
    /// Samples per unit of levels 0, 1, 2 (pixel, 2×2 block, 4×4 block).
    pub samples: [u32; 3],
}

impl Default for BlockShape {
    fn default() -> Self {
        BlockShape { fovea_deg: 5.2, intermediate_deg: 17.0, samples: [4, 2, 1] }
    }
}

pub const BLOCK_LEVELS: usize = 3;

#[derive(Clone, Copy, Debug)]
pub struct PixelBlocks {
    axis: VisualPolar,
    shape: BlockShape,
    fovea_px: f32,
    intermediate_px: f32,
}

impl PixelBlocks {
    pub fn new(screen: UVec2, vp: VisualPolarParams, shape: BlockShape) -> Result<PixelBlocks> {
        if !(shape.fovea_deg > 0.0 && shape.intermediate_deg > shape.fovea_deg) || shape.samples.iter().any(|&s| s == 0 || s > 64) {
            return Err(Error::Invalid(format!("pixel blocks: needs 0 < fovea < intermediate degrees and 1..=64 samples per unit, got {shape:?}")));
        }
        let axis = VisualPolar::new(screen, screen.as_vec2() * 0.5, vp)?;
        let mut space = PixelBlocks { axis, shape, fovea_px: 0.0, intermediate_px: 0.0 };
        space.set_radii();
        Ok(space)
    }

    fn set_radii(&mut self) {
        self.fovea_px = self.axis.radius_of_eccentricity(self.shape.fovea_deg);
        self.intermediate_px = self.axis.radius_of_eccentricity(self.shape.intermediate_deg);
    }

    /// The region radii in pixels (fovea, intermediate).
    pub fn radii(&self) -> (f32, f32) {
        (self.fovea_px, self.intermediate_px)
    }

    fn screen(&self) -> IVec2 {
        self.axis.screen().as_ivec2()
    }

    /// Blocks of `level` covering the screen (GLSL `pb_level_size`).
    pub fn level_size(&self, level: usize) -> IVec2 {
        let b = 1 << level;
        (self.screen() + b - 1) / b
    }

    /// Where `level` starts in the atlas (GLSL `pb_level_origin`).
    pub fn level_origin(&self, level: usize) -> IVec2 {
        let s = self.screen();
        match level {
            0 => IVec2::ZERO,
            1 => IVec2::new(s.x, 0),
            _ => IVec2::new(s.x, (s.y + 1) / 2),
        }
    }

    /// The level and block of an atlas texel (GLSL `pb_unit`).
    pub fn unit(&self, texel: IVec2) -> Option<(usize, IVec2)> {
        let level = if texel.x < self.screen().x { 0 } else if texel.y < self.level_origin(2).y { 1 } else { 2 };
        let block = texel - self.level_origin(level);
        (block.cmpge(IVec2::ZERO).all() && block.cmplt(self.level_size(level)).all()).then_some((level, block))
    }

    /// The level whose region holds a screen position (GLSL `pb_level_of`).
    pub fn level_of(&self, p: Vec2) -> usize {
        let d = (p - self.axis.gaze()).length();
        if d <= self.fovea_px {
            0
        } else if d <= self.intermediate_px {
            1
        } else {
            2
        }
    }

    /// Whether a unit traces (GLSL `pb_traced`).
    pub fn traced(&self, level: usize, block: IVec2) -> bool {
        let b = (1 << level) as f32;
        let d = ((block.as_vec2() + 0.5) * b - self.axis.gaze()).length();
        let reach = b * std::f32::consts::SQRT_2;
        match level {
            0 => d <= self.fovea_px,
            1 => d >= self.fovea_px - reach && d <= self.intermediate_px + reach,
            _ => d >= self.intermediate_px - reach,
        }
    }

    /// Samples the texel's unit traces per frame (GLSL `sample_count_in_texel`).
    pub fn samples_in_texel(&self, texel: IVec2) -> u32 {
        match self.unit(texel) {
            Some((level, block)) if self.traced(level, block) => self.shape.samples[level],
            _ => 0,
        }
    }
}

impl SamplingSpace for PixelBlocks {
    fn name(&self) -> &'static str {
        "pixel-blocks"
    }
    fn shader_variant(&self) -> &'static str {
        "pixel_blocks"
    }
    fn grid_size(&self) -> UVec2 {
        let s = self.screen();
        let level1 = self.level_size(1);
        let height = s.y.max(self.level_origin(2).y + self.level_size(2).y);
        UVec2::new((s.x + level1.x) as u32, height as u32)
    }
    fn screen_size(&self) -> UVec2 {
        self.axis.screen()
    }
    /// Samples per frame: every traced unit × its level's count (exact, no randomness).
    fn sample_count(&self) -> u64 {
        let g = self.grid_size().as_ivec2();
        (0..g.y).flat_map(|y| (0..g.x).map(move |x| IVec2::new(x, y))).map(|t| self.samples_in_texel(t) as u64).sum()
    }
    fn samples_per_texel(&self) -> u32 {
        self.shape.samples.into_iter().max().unwrap_or(1)
    }
    fn params(&self) -> SamplingParams {
        let (s, g) = (self.axis.screen(), self.axis.gaze());
        let grid = self.grid_size();
        let [t0, t1, t2] = self.shape.samples.map(|n| n as f32);
        SamplingParams {
            grid: UVec4::new(grid.x, grid.y, s.x, s.y),
            gaze: Vec4::new(g.x, g.y, self.fovea_px, self.intermediate_px),
            shape0: Vec4::new(t0, t1, t2, 0.0),
            shape1: Vec4::ZERO,
        }
    }
    /// The unit's block centre (texel + 0.5 → the centre); `None` in the atlas's unused parts.
    fn grid_to_screen(&self, grid: Vec2) -> Option<Vec2> {
        if !grid.is_finite() {
            return None;
        }
        let (level, block) = self.unit(grid.floor().as_ivec2())?;
        let b = (1 << level) as f32;
        Some((block.as_vec2() + grid.fract()) * b)
    }
    /// The unit of the level whose region holds the position.
    fn screen_to_grid(&self, screen: Vec2) -> Option<Vec2> {
        if !(screen.is_finite() && screen.cmpge(Vec2::ZERO).all() && screen.cmplt(self.axis.screen().as_vec2()).all()) {
            return None;
        }
        let level = self.level_of(screen);
        Some(screen / (1 << level) as f32 + self.level_origin(level).as_vec2())
    }
    fn gaze(&self) -> Vec2 {
        self.axis.gaze()
    }
    fn set_gaze(&mut self, gaze: Vec2) -> Result<()> {
        self.axis = VisualPolar::new(self.axis.screen(), gaze, *self.axis.params())?;
        self.set_radii();
        Ok(())
    }
    fn capabilities(&self) -> SpaceCapabilities {
        SpaceCapabilities { way_back: WayBack::BlockFill, temporal_filters: false, filters_note: "(its grid is an atlas of three block levels)" }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_atlas_holds_each_level_once_and_the_regions_nest() {
        let screen = UVec2::new(322, 361);
        let s = PixelBlocks::new(screen, VisualPolarParams::default(), BlockShape::default()).unwrap();
        let g = s.grid_size();
        assert_eq!(g, UVec2::new(322 + 161, 361));
        let mut units = [0u32; BLOCK_LEVELS];
        for y in 0..g.y as i32 {
            for x in 0..g.x as i32 {
                if let Some((level, block)) = s.unit(IVec2::new(x, y)) {
                    units[level] += 1;
                    // A unit's centre maps back to it where its own level holds the position.
                    let centre = s.grid_to_screen(IVec2::new(x, y).as_vec2() + 0.5).unwrap();
                    if centre.cmplt(screen.as_vec2()).all() && s.level_of(centre) == level {
                        assert_eq!(s.screen_to_grid(centre), Some(IVec2::new(x, y).as_vec2() + 0.5));
                    }
                    assert!(block.cmplt(s.level_size(level)).all());
                }
            }
        }
        assert_eq!(units, [322 * 361, 161 * 181, 81 * 91]);
        let (f, m) = s.radii();
        assert!(f > 10.0 && m > 3.0 * f, "{f} {m}");
        // Each level's pixels find all four interpolation neighbours traced.
        for y in 0..361 {
            for x in 0..322 {
                let p = Vec2::new(x as f32, y as f32) + 0.5;
                let level = s.level_of(p);
                if level == 0 {
                    assert!(s.traced(0, IVec2::new(x, y)));
                    continue;
                }
                let b = (1 << level) as f32;
                let i0 = (p / b - 0.5).floor().as_ivec2();
                for o in [IVec2::ZERO, IVec2::X, IVec2::Y, IVec2::ONE] {
                    let n = (i0 + o).clamp(IVec2::ZERO, s.level_size(level) - 1);
                    assert!(s.traced(level, n), "pixel {p} level {level} neighbour {n}");
                }
            }
        }
        assert!(PixelBlocks::new(screen, VisualPolarParams::default(), BlockShape { samples: [4, 0, 1], ..Default::default() }).is_err());
    }
}
