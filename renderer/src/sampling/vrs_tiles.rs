//! `vrs-tiles`: the foveation eye-tracked headsets ship through variable-rate shading, for a
//! path tracer: the screen in 16×16-pixel tiles, each traced at one sample per pixel, per 2×2 or
//! per 4×4 block — the coarsest rate whose density still meets Visual-Polar's at the tile's point
//! nearest the gaze, so no tile is sampled more sparsely than VP would sample it. One sample per
//! block, at the pixel nearest its centre (clamped to the screen). Like the hardware, it runs no
//! lane for the pixels a coarse block skips: the samples are packed into the grid tile row by tile
//! row (rate-1 tiles, then rate 2, then rate 4, by 4×4 patches of blocks), each row's unused texels
//! whole workgroups at its end. The way back splats each sample to its pixel, fills the rest
//! (push-pull) and applies the same foveated blur. Against `vp` it measures what quantising the
//! density to the hardware's rates and tiles costs in samples, with screen-order coherence. Paper
//! layout and normalised axis only (the density is VP's radial one).
//! GLSL: sampling/vrs_tiles.glsl.

use super::{
    RadialLaw, SamplingSpace, SpaceCapabilities, VisualPolar, VisualPolarParams, VpLayout, WayBack,
};
use crate::error::{Error, Result};
use crate::layouts::{SamplingParams, WORKGROUP_2D};
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
    /// Distances from the gaze beyond which rate 2 and rate 4 keep VP's density (finite: at
    /// most twice the screen's width + height).
    coarse_from: [f32; 2],
}

/// One tile row's run of tiles at one rate: first tile column, tiles, rate.
type Run = (i32, i32, i32);

impl VrsTiles {
    pub fn new(screen: UVec2, gaze: Vec2, params: VisualPolarParams) -> Result<VrsTiles> {
        let paper = params.layout == VpLayout::Paper
            && params.radial == RadialLaw::Acuity
            && params.eccentricity == super::Eccentricity::Normalized;
        if !paper {
            return Err(Error::Invalid("vrs tiles: follow the paper's Visual-Polar density only (layout = \"paper\", eccentricity = \"normalized\")".into()));
        }
        let axis = VisualPolar::new(screen, gaze, params)?;
        Ok(VrsTiles {
            axis,
            coarse_from: coarse_thresholds(&axis),
        })
    }

    fn tiles(&self) -> IVec2 {
        let s = self.axis.screen();
        IVec2::new(s.x.div_ceil(VRS_TILE) as i32, s.y.div_ceil(VRS_TILE) as i32)
    }

    /// Tile columns [x, y) of tile row `row` whose nearest point lies closer than `r` to the
    /// gaze (GLSL `vrs_columns_within`).
    fn columns_within(&self, row: i32, r: f32) -> IVec2 {
        let (g, t, tiles_x) = (self.axis.gaze(), VRS_TILE as f32, self.tiles().x);
        let dy = (row as f32 * t - g.y)
            .max(g.y - (row + 1) as f32 * t)
            .max(0.0);
        if dy >= r {
            return IVec2::ZERO;
        }
        let w = (r * r - dy * dy).sqrt();
        let lo = (((g.x - w) / t).floor() as i32).clamp(0, tiles_x);
        let hi = (((g.x + w) / t).ceil() as i32).min(tiles_x);
        IVec2::new(lo, hi.max(lo))
    }

    /// The five runs of tile row `row` in packing order: rate 1, rate 2 left and right of it,
    /// rate 4 left and right.
    fn runs(&self, row: i32) -> [Run; 5] {
        let mid = self.columns_within(row, self.coarse_from[1]);
        let mut fine = self.columns_within(row, self.coarse_from[0]);
        if fine.x == fine.y {
            fine = IVec2::splat(mid.x);
        }
        let tiles_x = self.tiles().x;
        [
            (fine.x, fine.y - fine.x, 1),
            (mid.x, fine.x - mid.x, 2),
            (fine.y, mid.y - fine.y, 2),
            (0, mid.x, 4),
            (mid.y, tiles_x - mid.y, 4),
        ]
    }

    /// Pixels per block side of the tile at `tile` (column, row).
    pub fn rate(&self, tile: IVec2) -> u32 {
        self.runs(tile.y)
            .iter()
            .find(|&&(first, n, _)| (first..first + n).contains(&tile.x))
            .map_or(RATES[2], |r| r.2 as u32)
    }

    /// The screen pixel of grid texel `texel`'s sample (GLSL `vrs_pixel`); `None` where the
    /// texel holds none.
    pub fn pixel(&self, texel: IVec2) -> Option<IVec2> {
        let grid = self.padded_grid().as_ivec2();
        let screen = self.axis.screen().as_ivec2();
        if texel.cmplt(IVec2::ZERO).any() || texel.cmpge(grid).any() {
            return None;
        }
        let wg = WORKGROUP_2D as i32;
        let mut k = ((texel.y / wg) * (grid.x / wg) + texel.x / wg) * wg * wg
            + (texel.y % wg) * wg
            + texel.x % wg;
        let tile = VRS_TILE as i32;
        let capacity = self.tiles().x * tile * tile;
        let row = k / capacity;
        k -= row * capacity;
        for (first, tiles, rate) in self.runs(row) {
            let per_side = tile / rate;
            let per_tile = per_side * per_side;
            if k < tiles * per_tile {
                let (column, s) = (first + k / per_tile, k % per_tile);
                let (patches, patch, q) = (per_side / 4, s / 16, s % 16);
                let block =
                    IVec2::new((patch % patches) * 4 + q % 4, (patch / patches) * 4 + q / 4);
                let origin = IVec2::new(column, row) * tile + block * rate;
                if origin.cmpge(screen).any() {
                    return None;
                }
                return Some((origin + rate / 2).min(screen - 1));
            }
            k -= tiles * per_tile;
        }
        None
    }

    /// The screen padded to whole tiles.
    fn padded_grid(&self) -> UVec2 {
        self.tiles().as_uvec2() * VRS_TILE
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
        // Beyond every pixel (but finite, for the GPU's square) when no radius on the screen is
        // that sparse.
        let beyond = 2.0 * (vp.screen().x + vp.screen().y) as f32;
        if r >= far {
            beyond
        } else {
            (r + SCAN_STEP).max(0.0)
        }
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
        self.padded_grid()
    }
    fn screen_size(&self) -> UVec2 {
        self.axis.screen()
    }
    /// Every block of every tile whose corner lies on the screen.
    fn sample_count(&self) -> u64 {
        let (screen, tiles, tile) = (self.axis.screen().as_ivec2(), self.tiles(), VRS_TILE as i32);
        let mut count = 0u64;
        for row in 0..tiles.y {
            for (first, n, rate) in self.runs(row) {
                for column in first..first + n {
                    let origin = IVec2::new(column, row) * tile;
                    let blocks = (IVec2::splat(tile).min(screen - origin) + rate - 1) / rate;
                    count += (blocks.x * blocks.y) as u64;
                }
            }
        }
        count
    }
    /// grid = (padded grid, screen), gaze = (x, y, rate-2 radius, rate-4 radius),
    /// shape0 = (tile side, tiles across, tiles down, 0).
    fn params(&self) -> SamplingParams {
        let (s, g, grid, tiles) = (
            self.axis.screen(),
            self.axis.gaze(),
            self.padded_grid(),
            self.tiles(),
        );
        SamplingParams {
            grid: UVec4::new(grid.x, grid.y, s.x, s.y),
            gaze: Vec4::new(g.x, g.y, self.coarse_from[0], self.coarse_from[1]),
            shape0: Vec4::new(VRS_TILE as f32, tiles.x as f32, tiles.y as f32, 0.0),
            shape1: Vec4::ZERO,
        }
    }
    /// The texel's sample (its pixel's centre).
    fn grid_to_screen(&self, grid: Vec2) -> Option<Vec2> {
        grid.is_finite()
            .then(|| self.pixel(grid.floor().as_ivec2()))
            .flatten()
            .map(|p| p.as_vec2() + 0.5)
    }
    /// Samples have no inverse on the packed grid (a pixel maps to a texel only through the
    /// rows' runs): the way back splats them.
    fn screen_to_grid(&self, _screen: Vec2) -> Option<Vec2> {
        None
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
        SpaceCapabilities {
            way_back: WayBack::Splat,
            temporal_filters: false,
            filters_note: "(its samples are packed by tile, not laid out as on the screen)",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_block_traces_once_and_no_tile_is_sparser_than_visual_polar() {
        let screen = UVec2::new(320, 360);
        for gaze in [
            Vec2::new(120.0, 150.0),
            Vec2::new(3.0, 350.5),
            Vec2::new(-40.0, 20.0),
        ] {
            let s = VrsTiles::new(screen, gaze, VisualPolarParams::default()).unwrap();
            // The packed grid covers every block's pixel exactly once.
            let grid = s.grid_size().as_ivec2();
            let mut hits = vec![0u32; (screen.x * screen.y) as usize];
            for y in 0..grid.y {
                for x in 0..grid.x {
                    if let Some(p) = s.pixel(IVec2::new(x, y)) {
                        hits[(p.y * screen.x as i32 + p.x) as usize] += 1;
                    }
                }
            }
            assert_eq!(
                hits.iter().map(|&h| h as u64).sum::<u64>(),
                s.sample_count(),
                "gaze {gaze}"
            );
            let mut rates = [0u32; 5];
            for y in 0..screen.y as i32 {
                for x in 0..screen.x as i32 {
                    let p = IVec2::new(x, y);
                    let rate = s.rate(p / VRS_TILE as i32);
                    rates[rate as usize] += 1;
                    // A coarse tile is at least as dense as VP anywhere in it (the fovea's VP
                    // density may exceed one sample per pixel a little: rate 1 is the finest).
                    let r = (p.as_vec2() + 0.5 - gaze).length();
                    assert!(
                        rate == 1 || 1.0 / (rate * rate) as f32 >= s.vp_density(r) * 0.999,
                        "{p}: rate {rate}, VP {}",
                        s.vp_density(r)
                    );
                    // One traced pixel per block, the one nearest its centre.
                    let r = rate as i32;
                    let chosen = (p / r * r + r / 2).min(screen.as_ivec2() - 1);
                    assert_eq!(
                        hits[(p.y * screen.x as i32 + p.x) as usize],
                        (p == chosen) as u32,
                        "{p}, gaze {gaze}"
                    );
                }
            }
            assert!(rates[2] > 0 && rates[4] > 0, "{rates:?}");
            if gaze.x > 0.0 {
                assert!(rates[1] > 0, "{rates:?}");
            }
        }
        assert!(VrsTiles::new(
            screen,
            Vec2::ZERO,
            VisualPolarParams {
                layout: VpLayout::ScreenClipped,
                ..Default::default()
            }
        )
        .is_err());
    }

    #[test]
    fn quantised_up_it_traces_more_than_visual_polar_and_idles_only_at_row_ends() {
        let screen = UVec2::new(320, 360);
        let gaze = screen.as_vec2() * 0.5;
        let s = VrsTiles::new(screen, gaze, VisualPolarParams::default()).unwrap();
        let vp = VisualPolar::new(screen, gaze, VisualPolarParams::default()).unwrap();
        let (n, vp_n, pixels) = (
            s.sample_count(),
            vp.sample_count(),
            (screen.x * screen.y) as u64,
        );
        assert!(
            n > vp_n && n < pixels * 3 / 5,
            "{n} vs VP {vp_n}, {pixels} pixels"
        );
        // Workgroups hold samples in one run: at most one partly idle workgroup per tile row.
        let wg = WORKGROUP_2D as i32;
        let groups = s.grid_size().as_ivec2() / wg;
        let partial = (0..groups.y)
            .flat_map(|gy| (0..groups.x).map(move |gx| IVec2::new(gx, gy)))
            .filter(|g| {
                let live = (0..wg * wg)
                    .filter(|i| s.pixel(*g * wg + IVec2::new(i % wg, i / wg)).is_some())
                    .count();
                live > 0 && live < (wg * wg) as usize
            })
            .count();
        assert!(
            partial <= s.tiles().y as usize,
            "{partial} partly idle workgroups"
        );
        eprintln!("vrs tiles at 320×360, gaze centred: {n} samples, VP {vp_n}, {partial} partly idle workgroups");
    }
}
