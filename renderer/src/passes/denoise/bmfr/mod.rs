//! BMFR — blockwise multi-order feature regression (Koskela et al. 2019, TOG; denoisers.md) on
//! the sampling grid: accumulation of the noisy demodulated radiance and the features (normal,
//! camera-relative position) → per 32×32 block a least-squares fit of the radiance as a linear
//! combination of 10 features (1, normal, position, position²; Householder QR) → each texel
//! evaluates its block's fit → accumulation of the fitted colour, re-modulated by albedo.
//! Emitters seen directly (and misses) stay out of the fits and keep their accumulated input: a
//! light in a ceiling has the ceiling's features, and one fit for both smears it over the ceiling.
//! The block grid shifts every frame (16 fixed offsets) so that block seams move and the
//! accumulation after the fit hides them.
//!
//! Visual-Polar (visual-polar.md §5): reprojection as SVGF's (through the previous gaze); blocks
//! wrap on φ and clamp on ρ. Deviation from the design note: instead of a staircase φ clip synced
//! with the block offsets (it would change the traced layout, and with it the tracer, mips and
//! remap), each texel is placed in its block column at its angle on the column's tallest height,
//! so every valid texel belongs to exactly one block per frame, blocks cross the φ seam, and
//! clipped texels are zero rows (`shaders/denoise/bmfr.glsl`).

mod accumulate;
mod accumulate_filtered;
mod fit;
mod idle;
mod weighted_sum;

use super::{DenoiseFrame, DenoiseScene};
use crate::error::{Error, Result};
use crate::graph::FrameRecorder;
use crate::layouts::{SamplingParams, BMFR_BLOCK, BMFR_WEIGHT_TEXELS};
use crate::passes::trace::GBuffer;
use crate::vk::{Context, Image};
use accumulate::AccumulatePass;
use accumulate_filtered::AccumulateFilteredPass;
use ash::vk;
use fit::FitPass;
use glam::{IVec2, UVec2, Vec3};
use idle::{IdlePass, IdleTargets};
use std::sync::Arc;
use weighted_sum::WeightedSumPass;

/// Filter parameters; `Default` is the paper's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BmfrSettings {
    /// Smallest blend weight of the new noisy sample and features before the fit
    /// (α = max(this, 1/history)).
    pub alpha_noisy: f32,
    /// The same for the fitted colour after the fit.
    pub alpha_filtered: f32,
    /// Amplitude of the uniform noise added to the features (not the constant) in the fit.
    pub noise: f32,
}

impl Default for BmfrSettings {
    fn default() -> Self {
        BmfrSettings {
            alpha_noisy: 0.2,
            alpha_filtered: 0.1,
            noise: 1e-2,
        }
    }
}

impl BmfrSettings {
    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(Error::Invalid(format!("bmfr: {what}")));
        // α = 1 would mean no accumulation at all; the passes use it to drop the history.
        let open_unit = |a: f32| a > 0.0 && a < 1.0;
        if !open_unit(self.alpha_noisy) || !open_unit(self.alpha_filtered) {
            return bad(format!(
                "alpha_noisy and alpha_filtered must be in (0, 1), got {} and {}",
                self.alpha_noisy, self.alpha_filtered
            ));
        }
        if !(self.noise.is_finite() && (0.0..=0.1).contains(&self.noise)) {
            return bad(format!("noise must be in [0, 0.1], got {}", self.noise));
        }
        Ok(())
    }
}

/// Block-grid offsets in texels, one per frame (frame % 16): every even value of [−16, 14] once
/// per axis, in an order that spreads consecutive offsets (x bit-reversed, y stepping by 5).
pub const BLOCK_OFFSETS: [[i32; 2]; 16] = block_offsets();

const fn block_offsets() -> [[i32; 2]; 16] {
    let mut table = [[0; 2]; 16];
    let mut i = 0;
    while i < 16 {
        let reversed = ((i & 1) << 3 | (i & 2) << 1 | (i & 4) >> 1 | (i & 8) >> 3) as i32;
        table[i] = [2 * reversed - 16, 2 * ((5 * i as i32 + 3) % 16) - 16];
        i += 1;
    }
    table
}

/// Blocks per axis of a grid: one more than the grid needs, so that every offset covers it.
pub fn block_count(grid: UVec2) -> UVec2 {
    grid.map(|v| v.div_ceil(BMFR_BLOCK) + 1)
}

/// Per-eye temporal state: everything BMFR carries from one frame to the next, allocated once,
/// in halves that ping-pong by frame parity (a frame reads the other half at reprojected
/// positions while writing its own).
pub struct BmfrHistory {
    /// Accumulated noisy demodulated radiance (rgb) and history length (w).
    pub noisy: [Image; 2],
    /// Accumulated normal.
    pub normal: [Image; 2],
    /// Accumulated camera-relative position (xyz; w the texel's world footprint, negative for an
    /// emitter, 0 = a miss).
    pub position: [Image; 2],
    /// Accumulated fitted colour (demodulated).
    pub filtered: [Image; 2],
    /// Frames recorded so far; the parity picks this frame's half and `% 16` the block offset.
    frames: u64,
    /// The camera origin of the last recorded frame (positions are relative to it).
    origin: Vec3,
}

impl BmfrHistory {
    fn new(ctx: &Arc<Context>, grid: UVec2) -> Result<BmfrHistory> {
        let pair = |name: &str, format| -> Result<[Image; 2]> {
            Ok([
                Image::new(ctx, &format!("{name}0"), grid.x, grid.y, format)?,
                Image::new(ctx, &format!("{name}1"), grid.x, grid.y, format)?,
            ])
        };
        let rgba32 = vk::Format::R32G32B32A32_SFLOAT;
        Ok(BmfrHistory {
            noisy: pair("bmfr.noisy", rgba32)?,
            normal: pair("bmfr.normal", vk::Format::R16G16B16A16_SFLOAT)?,
            position: pair("bmfr.position", rgba32)?,
            filtered: pair("bmfr.filtered", rgba32)?,
            frames: 0,
            origin: Vec3::ZERO,
        })
    }

    fn current(&self) -> usize {
        (self.frames % 2) as usize
    }

    /// GPU bytes of the state carried between frames (the per-eye memory cost of the filter).
    pub fn bytes(&self) -> u64 {
        [&self.noisy, &self.normal, &self.position, &self.filtered]
            .iter()
            .flat_map(|pair| pair.iter())
            .map(|i| i.width as u64 * i.height as u64 * i.texel_bytes())
            .sum()
    }
}

/// What the temporal passes need to know about the previous frame.
pub(crate) struct Reprojection<'a> {
    /// The previous frame's space; `None` drops all history.
    pub previous: Option<&'a SamplingParams>,
    /// Previous camera origin − this one (positions are camera-relative).
    pub camera_shift: Vec3,
}

pub struct Bmfr {
    pub settings: BmfrSettings,
    accumulate: AccumulatePass,
    fit: FitPass,
    weighted_sum: WeightedSumPass,
    accumulate_filtered: AccumulateFilteredPass,
    idle: IdlePass,
    pub history: BmfrHistory,
    /// Per block: BMFR_WEIGHT_TEXELS texels (10 × rgb weights, position offset, position scale).
    pub weights: Image,
    /// Each texel's evaluated fit (demodulated, ≥ 0), before the accumulation after the fit.
    pub fitted: Image,
    /// Re-modulated radiance, the denoiser's output.
    pub output: Image,
}

impl Bmfr {
    /// `variant`: the sampling space's kernel variant (`cartesian`, `visual_polar`).
    pub fn new(
        ctx: &Arc<Context>,
        grid: UVec2,
        variant: &str,
        settings: BmfrSettings,
    ) -> Result<Bmfr> {
        settings.validate()?;
        let blocks = block_count(grid);
        let rgba32 = vk::Format::R32G32B32A32_SFLOAT;
        Ok(Bmfr {
            settings,
            accumulate: AccumulatePass::new(ctx, variant)?,
            fit: FitPass::new(ctx, variant)?,
            weighted_sum: WeightedSumPass::new(ctx, variant)?,
            accumulate_filtered: AccumulateFilteredPass::new(ctx, variant)?,
            idle: IdlePass::new(ctx, variant)?,
            history: BmfrHistory::new(ctx, grid)?,
            weights: Image::new(
                ctx,
                "bmfr.weights",
                blocks.x * BMFR_WEIGHT_TEXELS,
                blocks.y,
                rgba32,
            )?,
            fitted: Image::new(ctx, "bmfr.fitted", grid.x, grid.y, rgba32)?,
            output: Image::new(ctx, "bmfr.output", grid.x, grid.y, rgba32)?,
        })
    }

    pub fn max_passes(&self) -> u32 {
        5
    }

    /// The block-grid offset the next recorded frame uses.
    pub fn next_block_offset(&self) -> IVec2 {
        IVec2::from(BLOCK_OFFSETS[(self.history.frames % 16) as usize])
    }

    /// Accumulated noisy radiance and history length (w) written by the last recorded frame.
    pub fn noisy(&self) -> &Image {
        &self.history.noisy[(self.history.frames.wrapping_sub(1) % 2) as usize]
    }

    /// Records one frame: accumulate → fit → weighted sum → accumulate the fit and re-modulate;
    /// returns `output`. The per-texel passes run over `frame.tiles`' live tiles; the idle pass
    /// writes the idle ones before the fit reads whole blocks. History is dropped on the first frame and whenever `frame.previous` is
    /// `None`.
    pub fn record(
        &mut self,
        rec: &mut FrameRecorder,
        g: &GBuffer,
        frame: &DenoiseFrame,
        scene: &DenoiseScene,
    ) -> Result<&Image> {
        let camera_origin = scene.camera_origin;
        let s = self.settings;
        let offset = self.next_block_offset();
        let h = &self.history;
        let (cur, prev) = (h.current(), 1 - h.current());
        let previous = if h.frames == 0 {
            None
        } else {
            frame.previous.as_ref()
        };
        let reprojection = Reprojection {
            previous,
            camera_shift: h.origin - camera_origin,
        };
        let (table, tiles) = (frame.sampling_table, &frame.tiles);
        self.accumulate.record(
            rec,
            g,
            scene.materials,
            h,
            prev,
            cur,
            &frame.current,
            table,
            tiles,
            &reprojection,
            s.alpha_noisy,
        )?;
        let idle = IdleTargets {
            history: h,
            cur,
            fitted: &self.fitted,
            output: &self.output,
        };
        self.idle.record(rec, &idle, &frame.current, table, tiles)?;
        let seed = h.frames as u32;
        self.fit.record(
            rec,
            h,
            cur,
            &self.weights,
            &frame.current,
            table,
            offset,
            seed,
            s.noise,
        )?;
        self.weighted_sum.record(
            rec,
            h,
            cur,
            &self.weights,
            &self.fitted,
            &frame.current,
            table,
            tiles,
            offset,
        )?;
        self.accumulate_filtered.record(
            rec,
            g,
            h,
            prev,
            cur,
            &self.fitted,
            &self.output,
            &frame.current,
            table,
            tiles,
            &reprojection,
            s.alpha_filtered,
        )?;
        self.history.frames += 1;
        self.history.origin = camera_origin;
        Ok(&self.output)
    }
}
