//! `pixel-blocks` (Mohanto, Klunge and Staadt 2023, comparators.md §F): a fovea of single pixels
//! within 5.2°, 2×2 blocks to 17°, 4×4 blocks beyond, each unit tracing τ samples — their 32 / 16
//! / 8 spp are offline, so the ratios are kept at a real-time 4 / 2 / 1 — and every missing pixel
//! filled by bilinear interpolation between the block centres of its level (passes/block_fill).
//! Degrees are Visual-Polar's eccentricity axis for the same profile, as for linear falloff.
//! The grid is an atlas of windows (see `sampling/pixel_blocks.glsl`): level 2 over the whole
//! screen, levels 0 and 1 in square windows that follow the gaze, sized once for the largest
//! regions any gaze gives (the grid never changes size); units outside their region hold no
//! sample (the rays are discarded before tracing, as in the paper).

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
        BlockShape {
            fovea_deg: 5.2,
            intermediate_deg: 17.0,
            samples: [4, 2, 1],
        }
    }
}

pub const BLOCK_LEVELS: usize = 3;

#[derive(Clone, Copy, Debug)]
pub struct PixelBlocks {
    axis: VisualPolar,
    shape: BlockShape,
    fovea_px: f32,
    intermediate_px: f32,
    /// Edge of the level-0 and level-1 windows, in units.
    windows: [i32; 2],
}

/// Units a window keeps beyond its region's radius on each side (the gaze's block is rounded).
const WINDOW_MARGIN: i32 = 2;

/// A window's edge for a region of `radius` px at block size `b`.
fn window_for(radius: f32, b: f32) -> i32 {
    2 * ((radius / b).ceil() as i32 + WINDOW_MARGIN)
}

impl PixelBlocks {
    pub fn new(screen: UVec2, vp: VisualPolarParams, shape: BlockShape) -> Result<PixelBlocks> {
        if !(shape.fovea_deg > 0.0 && shape.intermediate_deg > shape.fovea_deg)
            || shape.samples.iter().any(|&s| s == 0 || s > 64)
        {
            return Err(Error::Invalid(format!("pixel blocks: needs 0 < fovea < intermediate degrees and 1..=64 samples per unit, got {shape:?}")));
        }
        // The windows hold the largest regions of any gaze: the corners' and the centre's.
        let s = screen.as_vec2();
        let mut windows = [0; 2];
        for gaze in [
            Vec2::ZERO,
            Vec2::new(s.x, 0.0),
            Vec2::new(0.0, s.y),
            s,
            s * 0.5,
        ] {
            let axis = VisualPolar::new(screen, gaze, vp)?;
            windows[0] = windows[0].max(window_for(
                axis.radius_of_eccentricity(shape.fovea_deg),
                1.0,
            ));
            let reach = 2.0 * std::f32::consts::SQRT_2;
            windows[1] = windows[1].max(window_for(
                axis.radius_of_eccentricity(shape.intermediate_deg) + reach,
                2.0,
            ));
        }
        let axis = VisualPolar::new(screen, s * 0.5, vp)?;
        let mut space = PixelBlocks {
            axis,
            shape,
            fovea_px: 0.0,
            intermediate_px: 0.0,
            windows,
        };
        space.set_radii();
        Ok(space)
    }

    /// The regions' radii for the current gaze, within what the windows hold.
    fn set_radii(&mut self) {
        let fits = |window: i32, b: f32| (window / 2 - WINDOW_MARGIN) as f32 * b;
        self.fovea_px = self
            .axis
            .radius_of_eccentricity(self.shape.fovea_deg)
            .min(fits(self.windows[0], 1.0));
        let reach = 2.0 * std::f32::consts::SQRT_2;
        self.intermediate_px = self
            .axis
            .radius_of_eccentricity(self.shape.intermediate_deg)
            .min(fits(self.windows[1], 2.0) - reach);
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

    /// A level's window in units (GLSL `pb_window_size`).
    pub fn window_size(&self, level: usize) -> IVec2 {
        match level {
            2 => self.level_size(2),
            l => IVec2::splat(self.windows[l]),
        }
    }

    /// Where a level's window starts in the atlas (GLSL `pb_atlas_origin`).
    pub fn atlas_origin(&self, level: usize) -> IVec2 {
        let x = self.level_size(2).x;
        match level {
            2 => IVec2::ZERO,
            0 => IVec2::new(x, 0),
            _ => IVec2::new(x, self.window_size(0).y),
        }
    }

    /// The first block of a level's window (GLSL `pb_window_first_block`).
    pub fn window_first_block(&self, level: usize) -> IVec2 {
        if level == 2 {
            return IVec2::ZERO;
        }
        let gaze_block = (self.axis.gaze() / (1 << level) as f32).floor().as_ivec2();
        gaze_block - self.window_size(level) / 2
    }

    /// The level and block of an atlas texel (GLSL `pb_unit`).
    pub fn unit(&self, texel: IVec2) -> Option<(usize, IVec2)> {
        let level = if texel.x < self.atlas_origin(0).x {
            2
        } else if texel.y < self.atlas_origin(1).y {
            0
        } else {
            1
        };
        let local = texel - self.atlas_origin(level);
        let block = local + self.window_first_block(level);
        let inside = local.cmplt(self.window_size(level)).all()
            && block.cmpge(IVec2::ZERO).all()
            && block.cmplt(self.level_size(level)).all();
        inside.then_some((level, block))
    }

    /// The atlas texel of a level's block (GLSL `pb_atlas_texel`).
    pub fn atlas_texel(&self, level: usize, block: IVec2) -> IVec2 {
        self.atlas_origin(level) + block - self.window_first_block(level)
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
        let level2 = self.level_size(2);
        let (w0, w1) = (self.windows[0], self.windows[1]);
        UVec2::new((level2.x + w0.max(w1)) as u32, level2.y.max(w0 + w1) as u32)
    }
    fn screen_size(&self) -> UVec2 {
        self.axis.screen()
    }
    /// Samples per frame: every traced unit × its level's count (exact, no randomness).
    fn sample_count(&self) -> u64 {
        let g = self.grid_size().as_ivec2();
        (0..g.y)
            .flat_map(|y| (0..g.x).map(move |x| IVec2::new(x, y)))
            .map(|t| self.samples_in_texel(t) as u64)
            .sum()
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
            shape1: Vec4::new(self.windows[0] as f32, self.windows[1] as f32, 0.0, 0.0),
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
        if !(screen.is_finite()
            && screen.cmpge(Vec2::ZERO).all()
            && screen.cmplt(self.axis.screen().as_vec2()).all())
        {
            return None;
        }
        let level = self.level_of(screen);
        let in_level = screen / (1 << level) as f32;
        Some(
            in_level - in_level.floor()
                + self
                    .atlas_texel(level, in_level.floor().as_ivec2())
                    .as_vec2(),
        )
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
        SpaceCapabilities {
            way_back: WayBack::BlockFill,
            temporal_filters: false,
            filters_note: "(its grid is an atlas of three block levels)",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_windows_hold_every_traced_unit_and_the_regions_nest() {
        let screen = UVec2::new(322, 361);
        let mut s =
            PixelBlocks::new(screen, VisualPolarParams::default(), BlockShape::default()).unwrap();
        let grid = s.grid_size();
        for gaze in [
            Vec2::new(161.0, 180.0),
            Vec2::new(3.0, 350.0),
            Vec2::new(321.5, 0.5),
        ] {
            s.set_gaze(gaze).unwrap();
            assert_eq!(s.grid_size(), grid, "the grid never changes size");
            let (f, m) = s.radii();
            assert!(f > 5.0 && m > 3.0 * f, "{f} {m}");
            // Every unit a level's region traces lies in its window, once.
            let mut seen = std::collections::HashSet::new();
            for y in 0..grid.y as i32 {
                for x in 0..grid.x as i32 {
                    if let Some((level, block)) = s.unit(IVec2::new(x, y)) {
                        assert!(seen.insert((level, block)));
                        assert_eq!(s.atlas_texel(level, block), IVec2::new(x, y));
                        let centre = s.grid_to_screen(IVec2::new(x, y).as_vec2() + 0.5).unwrap();
                        if centre.cmplt(screen.as_vec2()).all() && s.level_of(centre) == level {
                            assert_eq!(
                                s.screen_to_grid(centre),
                                Some(IVec2::new(x, y).as_vec2() + 0.5)
                            );
                        }
                    }
                }
            }
            for level in 0..BLOCK_LEVELS {
                let n = s.level_size(level);
                for by in 0..n.y {
                    for bx in 0..n.x {
                        let b = IVec2::new(bx, by);
                        if s.traced(level, b) {
                            assert!(
                                seen.contains(&(level, b)),
                                "gaze {gaze}: level {level} block {b} traced but not in its window"
                            );
                        }
                    }
                }
            }
            // Each level's pixels find all four interpolation neighbours traced.
            for y in 0..screen.y {
                for x in 0..screen.x {
                    let p = Vec2::new(x as f32, y as f32) + 0.5;
                    let level = s.level_of(p);
                    if level == 0 {
                        assert!(s.traced(0, IVec2::new(x as i32, y as i32)));
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
        }
        // A small atlas: far fewer lanes than the screen.
        assert!(grid.x * grid.y < screen.x * screen.y / 2, "{grid}");
        assert!(PixelBlocks::new(
            screen,
            VisualPolarParams::default(),
            BlockShape {
                samples: [4, 0, 1],
                ..Default::default()
            }
        )
        .is_err());
    }
}
