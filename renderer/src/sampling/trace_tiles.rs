//! Which of the trace kernel's workgroup tiles run the tracer (`SamplingSpace::trace_tiles`).
//!
//! lavapipe runs a kernel's masked-off lanes at nearly the full cost of live ones, even where a
//! whole workgroup returns on its first line (doubling Cartesian's dispatch with idle rows
//! doubled its trace time). Visual-Polar's grid holds ≈ 19 % such texels with the gaze centred
//! (the fovea's clipped triangle, samples culled far off the screen). The trace runs over a list
//! of live tiles instead of the whole grid; the idle ones only get the "not traced" G-buffer
//! values from a cheap clearing kernel (`passes/trace_clear`). The tracer still decides per
//! sample: a tile is idle only where no texel holds a sample or every sample is certain to be
//! culled, so the picture and the counts are those of the full dispatch.

use super::{SamplingSpace, VisualPolar, VpLayout};
use crate::layouts::WORKGROUP_2D;
use glam::{UVec2, Vec2};

/// Texels per side of a trace tile (the trace kernel's workgroup).
pub const TRACE_TILE: u32 = WORKGROUP_2D;

/// Mirrors trace.comp's culling margin: three footprints and three pixels.
const CULL_FOOTPRINTS: f32 = 3.0;
const CULL_PIXELS: f32 = 3.0;
/// Extra pixels a tile must lie beyond the margin: the f32 mapping on the GPU and here differ by
/// far less than this.
const CULL_SLACK_PIXELS: f32 = 1.0;

/// This frame's tiles, each packed `x | y << 16` (tile coordinates).
#[derive(Default, Debug, Clone)]
pub struct TraceTiles {
    /// Tiles the trace kernel runs.
    pub live: Vec<u32>,
    /// Tiles only cleared to "not traced".
    pub idle: Vec<u32>,
    /// Samples in the idle tiles (all of them certainly culled off the screen).
    pub culled_samples: u32,
    /// `live` then `idle`, as the tile buffer holds them.
    packed: Vec<u32>,
    /// Scratch reused every frame: the radius at each column boundary, the directions at each
    /// tile row's first, middle and last angle.
    radii: Vec<f32>,
    directions: Vec<[Vec2; 3]>,
}

fn pack(x: u32, y: u32) -> u32 {
    x | (y << 16)
}

/// Tiles covering `grid`.
pub fn tile_count(grid: UVec2) -> UVec2 {
    UVec2::new(grid.x.div_ceil(TRACE_TILE), grid.y.div_ceil(TRACE_TILE))
}

impl TraceTiles {
    pub fn clear(&mut self) {
        self.live.clear();
        self.idle.clear();
        self.culled_samples = 0;
    }

    /// Every tile of `grid` live (spaces whose every texel may hold a traced sample).
    pub fn fill_live(&mut self, grid: UVec2) {
        self.clear();
        let n = tile_count(grid);
        self.live
            .extend((0..n.y).flat_map(|y| (0..n.x).map(move |x| pack(x, y))));
    }

    /// The tile buffer's contents: the live tiles, then the idle ones.
    pub fn packed(&mut self) -> &[u32] {
        self.packed.clear();
        self.packed.extend_from_slice(&self.live);
        self.packed.extend_from_slice(&self.idle);
        &self.packed
    }
}

/// Visual-Polar's tiles: idle where every texel is clipped (the fovea's triangle) or, with
/// `cull`, where every sample is certain to lie farther off the screen than trace.comp's
/// margin (the paper's layout on the normalised axis, the only one placing samples off it).
pub fn visual_polar_tiles(vp: &VisualPolar, cull: bool, tiles: &mut TraceTiles) {
    tiles.clear();
    let grid = vp.grid_size();
    let n = tile_count(grid);
    let cull = cull && vp.params().layout == VpLayout::Paper && vp.headset().is_none();
    let mut radii = std::mem::take(&mut tiles.radii);
    let mut directions = std::mem::take(&mut tiles.directions);
    if cull {
        // Radius at every column boundary (u = c / width); angles of full columns' rows.
        radii.clear();
        radii.extend((0..=grid.x).map(|c| vp.r_of_u(c as f32 / grid.x as f32)));
        let angle = |row: f32| std::f32::consts::TAU * row / grid.y as f32;
        let direction = |phi: f32| Vec2::new(phi.cos(), phi.sin());
        directions.clear();
        directions.extend((0..n.y).map(|ty| {
            let (y0, y1) = (
                (ty * TRACE_TILE) as f32,
                ((ty + 1) * TRACE_TILE).min(grid.y) as f32,
            );
            [
                direction(angle(y0)),
                direction(angle(0.5 * (y0 + y1))),
                direction(angle(y1)),
            ]
        }));
    }
    for ty in 0..n.y {
        for tx in 0..n.x {
            let (x0, y0) = (tx * TRACE_TILE, ty * TRACE_TILE);
            let (x1, y1) = ((x0 + TRACE_TILE).min(grid.x), (y0 + TRACE_TILE).min(grid.y));
            let samples: u32 = (x0..x1)
                .map(|c| vp.rows_in_column(c).min(y1).saturating_sub(y0))
                .sum();
            let full_columns = (x0..x1).all(|c| vp.rows_in_column(c) == grid.y);
            if samples == 0 {
                tiles.idle.push(pack(tx, ty));
            } else if cull
                && full_columns
                && surely_culled(vp, &radii, &directions[ty as usize], (x0, x1), (y0, y1))
            {
                tiles.idle.push(pack(tx, ty));
                tiles.culled_samples += samples;
            } else {
                tiles.live.push(pack(tx, ty));
            }
        }
    }
    tiles.radii = radii;
    tiles.directions = directions;
}

/// Whether every sample of the tile's full columns [x0, x1) × rows [y0, y1), at any jitter,
/// lies farther off the screen than its culling margin (`far_off_screen` in trace.comp).
/// `directions`: at the rows' first, middle and last angle.
fn surely_culled(
    vp: &VisualPolar,
    radii: &[f32],
    directions: &[Vec2; 3],
    (x0, x1): (u32, u32),
    (y0, y1): (u32, u32),
) -> bool {
    let grid = vp.grid_size();
    let w = grid.x as usize;
    let (r_a, r_b) = (radii[x0 as usize], radii[x1 as usize]);
    let tau = std::f32::consts::TAU;
    let (phi_a, phi_b) = (
        tau * y0 as f32 / grid.y as f32,
        tau * y1 as f32 / grid.y as f32,
    );
    // The largest footprint a sample here can have: its ρ neighbour (one column out, or in at
    // the last column) lies within two column spacings, its φ neighbour one arc step away.
    let lo = (x0 as usize).saturating_sub(1);
    let rho = (lo..x1 as usize)
        .map(|c| radii[(c + 2).min(w)] - radii[c])
        .fold(0.0f32, f32::max);
    let footprint = rho.max(r_b * tau / grid.y as f32).max(1.0);
    let margin = CULL_FOOTPRINTS * footprint + CULL_PIXELS + CULL_SLACK_PIXELS;
    // How far the tile's annular sector lies off the screen, from 3 × 3 points on it: the
    // distance off the screen (the larger axis') changes by at most the distance moved, and no
    // point of the sector is farther than `reach` from the nearest probe.
    let screen = vp.screen_size().as_vec2();
    let gaze = vp.gaze();
    let reach = 0.25 * (r_b - r_a) + 0.25 * r_b * (phi_b - phi_a);
    let mut nearest = f32::INFINITY;
    for i in 0..3 {
        let r = r_a + (r_b - r_a) * i as f32 * 0.5;
        for direction in directions {
            let p = gaze + r * *direction;
            let outside = (-p).max(p - screen).max(Vec2::ZERO);
            nearest = nearest.min(outside.x.max(outside.y));
        }
    }
    nearest - reach > margin
}

#[cfg(test)]
#[path = "trace_tiles_tests.rs"]
mod tests;
