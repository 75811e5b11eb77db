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
mod history;
mod idle;
mod settings;
mod weighted_sum;

pub use fit::{block_count, BLOCK_OFFSETS};
pub use history::BmfrHistory;
pub use settings::BmfrSettings;

use crate::error::Result;
use crate::graph::FrameRecorder;
use crate::layouts::BMFR_WEIGHT_TEXELS;
use crate::passes::denoise::{Denoiser, DenoiserParams};
use crate::passes::grid::GridFrame;
use crate::passes::Pass;
use crate::vk::{Context, Image};
use accumulate::Accumulate;
use accumulate_filtered::AccumulateFiltered;
use ash::vk;
use fit::{Blocks, Fit};
use glam::{IVec2, UVec2};
use history::{FrameTargets, Reprojection};
use idle::Idle;
use std::sync::Arc;
use weighted_sum::WeightedSum;

pub struct Bmfr {
    pub settings: BmfrSettings,
    accumulate: Pass<Accumulate>,
    fit: Pass<Fit>,
    weighted_sum: Pass<WeightedSum>,
    accumulate_filtered: Pass<AccumulateFiltered>,
    idle: Pass<Idle>,
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
            accumulate: Pass::new(ctx, variant)?,
            fit: Pass::new(ctx, variant)?,
            weighted_sum: Pass::new(ctx, variant)?,
            accumulate_filtered: Pass::new(ctx, variant)?,
            idle: Pass::new(ctx, variant)?,
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
    pub fn record(&mut self, rec: &mut FrameRecorder, frame: &GridFrame) -> Result<&Image> {
        let camera_origin = frame.camera_origin;
        let s = self.settings;
        let blocks = Blocks {
            offset: self.next_block_offset(),
            seed: self.history.frames as u32,
            noise: s.noise,
        };
        let h = &self.history;
        let reprojection = Reprojection {
            previous: if h.frames == 0 {
                None
            } else {
                frame.previous.as_ref()
            },
            camera_shift: h.origin - camera_origin,
        };
        let targets = FrameTargets {
            history: h,
            fitted: &self.fitted,
            output: &self.output,
        };
        self.accumulate
            .record(rec, frame, h, &reprojection, s.alpha_noisy)?;
        self.idle.record(rec, frame, &targets)?;
        self.fit.record(rec, frame, h, &self.weights, &blocks)?;
        self.weighted_sum
            .record(rec, frame, h, (&self.weights, &self.fitted), &blocks)?;
        self.accumulate_filtered
            .record(rec, frame, &targets, &reprojection, s.alpha_filtered)?;
        self.history.frames += 1;
        self.history.origin = camera_origin;
        Ok(&self.output)
    }
}

impl DenoiserParams for BmfrSettings {
    const NAME: &'static str = "bmfr";

    fn validate(&self) -> Result<()> {
        BmfrSettings::validate(self)
    }

    fn build(&self, ctx: &Arc<Context>, grid: UVec2, variant: &str) -> Result<Box<dyn Denoiser>> {
        Ok(Box::new(Bmfr::new(ctx, grid, variant, *self)?))
    }
}

impl Denoiser for Bmfr {
    fn history_bytes(&self) -> u64 {
        self.history.bytes()
    }

    fn max_passes(&self) -> u32 {
        Bmfr::max_passes(self)
    }

    fn record(&mut self, rec: &mut FrameRecorder, frame: &GridFrame) -> Result<&Image> {
        Bmfr::record(self, rec, frame)
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}
