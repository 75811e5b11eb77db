//! SVGF — spatiotemporal variance-guided filtering (Schied et al. 2017; denoisers.md) on the
//! sampling grid: temporal accumulation of demodulated radiance and luminance moments →
//! variance (spatial while the history is short) → à-trous wavelet iterations, the first of
//! which becomes next frame's colour history → re-modulation by albedo.
//!
//! Visual-Polar (visual-polar.md §5): taps wrap on φ, end at the grid on ρ and keep the angle
//! across columns of different height; reprojection maps the tracer's previous *screen* position
//! with the previous frame's space (gaze) and takes bilinear taps in each column's own rows.

mod atrous;
mod history;
mod idle;
mod settings;
mod temporal;
mod variance;

pub use history::SvgfHistory;
pub use settings::{SvgfSettings, MAX_ATROUS_ITERATIONS};

use super::modulate::Modulate;
use crate::error::Result;
use crate::graph::FrameRecorder;
use crate::passes::denoise::{Denoiser, DenoiserParams};
use crate::passes::grid::GridFrame;
use crate::passes::Pass;
use crate::vk::{Context, Image};
use ash::vk;
use atrous::Atrous;
use glam::UVec2;
use idle::Idle;
use std::sync::Arc;
use temporal::Temporal;
use variance::Variance;

pub struct Svgf {
    pub settings: SvgfSettings,
    temporal: Pass<Temporal>,
    variance: Pass<Variance>,
    atrous: Pass<Atrous>,
    idle: Pass<Idle>,
    modulate: Pass<Modulate>,
    pub history: SvgfHistory,
    /// Temporal output: accumulated colour, variance.
    accum: Image,
    /// À-trous ping-pong (colour, variance).
    ping: [Image; 2],
    /// Re-modulated radiance, the denoiser's output.
    pub output: Image,
}

impl Svgf {
    /// `variant`: the sampling space's kernel variant (`cartesian`, `visual_polar`).
    pub fn new(
        ctx: &Arc<Context>,
        grid: UVec2,
        variant: &str,
        settings: SvgfSettings,
    ) -> Result<Svgf> {
        Svgf::build(ctx, grid, variant, variant, settings)
    }

    /// SVGF whose temporal accumulation takes A-SVGF's reconstructed gradient (`record_adaptive`).
    pub(crate) fn adaptive(
        ctx: &Arc<Context>,
        grid: UVec2,
        variant: &str,
        settings: SvgfSettings,
    ) -> Result<Svgf> {
        Svgf::build(ctx, grid, variant, &format!("{variant}_adaptive"), settings)
    }

    fn build(
        ctx: &Arc<Context>,
        grid: UVec2,
        variant: &str,
        temporal_variant: &str,
        settings: SvgfSettings,
    ) -> Result<Svgf> {
        settings.validate()?;
        let image =
            |name: &str| Image::new(ctx, name, grid.x, grid.y, vk::Format::R32G32B32A32_SFLOAT);
        Ok(Svgf {
            settings,
            temporal: Pass::new(ctx, temporal_variant)?,
            variance: Pass::new(ctx, variant)?,
            atrous: Pass::new(ctx, variant)?,
            idle: Pass::new(ctx, variant)?,
            modulate: Pass::single(ctx)?,
            history: SvgfHistory::new(ctx, grid)?,
            accum: image("svgf.accum")?,
            ping: [image("svgf.ping0")?, image("svgf.ping1")?],
            output: image("svgf.output")?,
        })
    }

    pub fn max_passes(&self) -> u32 {
        4 + self.settings.atrous_iterations
    }

    /// Moments and history length (x m1, y m2, z frames) written by the last recorded frame.
    pub fn moments(&self) -> &Image {
        &self.history.moments[(self.history.frames.wrapping_sub(1) % 2) as usize]
    }

    /// Records one frame: temporal → variance → à-trous iterations → modulate; returns `output`.
    /// All but the modulation run over `frame.tiles`' live tiles; the idle pass fills in the
    /// history a later frame reads of the idle ones.
    /// History is dropped on the first frame and whenever `frame.previous` is `None`.
    pub fn record(&mut self, rec: &mut FrameRecorder, frame: &GridFrame) -> Result<&Image> {
        self.record_with(rec, frame, None)
    }

    /// `record` for SVGF built by `adaptive`: `gradient` (per 3×3 stratum: δ̂, max f, confidence)
    /// sets each texel's temporal α.
    pub(crate) fn record_adaptive(
        &mut self,
        rec: &mut FrameRecorder,
        frame: &GridFrame,
        gradient: &Image,
    ) -> Result<&Image> {
        self.record_with(rec, frame, Some(gradient))
    }

    fn record_with(
        &mut self,
        rec: &mut FrameRecorder,
        frame: &GridFrame,
        gradient: Option<&Image>,
    ) -> Result<&Image> {
        let s = self.settings;
        let h = &self.history;
        let frame = &GridFrame {
            previous: if h.frames == 0 { None } else { frame.previous },
            ..*frame
        };
        self.temporal
            .record(rec, frame, (h, &self.accum), &s, gradient)?;
        self.idle.record(rec, frame, h)?;
        self.variance
            .record(rec, frame, h, (&self.accum, &self.ping[0]), &s)?;
        // Iteration 0 writes the colour history; then the two ping images alternate.
        let mut src = &self.ping[0];
        for i in 0..s.atrous_iterations {
            let dst = if i == 0 {
                &h.color
            } else {
                &self.ping[(i % 2) as usize]
            };
            self.atrous.record(rec, frame, (src, dst), 1 << i, &s)?;
            src = dst;
        }
        let albedo = &frame.gbuffer.albedo;
        self.modulate
            .record(rec, "svgf_modulate", src, albedo, &self.output)?;
        self.history.frames += 1;
        Ok(&self.output)
    }
}

impl DenoiserParams for SvgfSettings {
    const NAME: &'static str = "svgf";

    fn validate(&self) -> Result<()> {
        SvgfSettings::validate(self)
    }

    fn build(&self, ctx: &Arc<Context>, grid: UVec2, variant: &str) -> Result<Box<dyn Denoiser>> {
        Ok(Box::new(Svgf::new(ctx, grid, variant, *self)?))
    }
}

impl Denoiser for Svgf {
    fn history_bytes(&self) -> u64 {
        self.history.bytes()
    }

    fn max_passes(&self) -> u32 {
        Svgf::max_passes(self)
    }

    fn record(&mut self, rec: &mut FrameRecorder, frame: &GridFrame) -> Result<&Image> {
        Svgf::record(self, rec, frame)
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}
