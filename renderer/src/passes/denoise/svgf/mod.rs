//! SVGF — spatiotemporal variance-guided filtering (Schied et al. 2017; denoisers.md) on the
//! sampling grid: temporal accumulation of demodulated radiance and luminance moments →
//! variance (spatial while the history is short) → à-trous wavelet iterations, the first of
//! which becomes next frame's colour history → re-modulation by albedo.
//!
//! Visual-Polar (visual-polar.md §5): taps wrap on φ, end at the grid on ρ and keep the angle
//! across columns of different height; reprojection maps the tracer's previous *screen* position
//! with the previous frame's space (gaze) and takes bilinear taps in each column's own rows.

mod atrous;
mod idle;
mod temporal;
mod variance;

use super::modulate::ModulatePass;
use super::DenoiseFrame;
use crate::error::{Error, Result};
use crate::graph::FrameRecorder;
use crate::passes::trace::GBuffer;
use crate::vk::{Context, Image};
use ash::vk;
use atrous::AtrousPass;
use glam::UVec2;
use idle::IdlePass;
use std::sync::Arc;
use temporal::TemporalPass;
use variance::VariancePass;

/// Filter parameters; `Default` is the paper's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SvgfSettings {
    /// Smallest blend weight of the new colour sample (α = max(this, 1/history)).
    pub alpha_color: f32,
    /// The same for the luminance moments.
    pub alpha_moments: f32,
    /// History length cap in frames.
    pub max_history: u32,
    /// Below this history length the variance is estimated spatially (7×7).
    pub variance_history: u32,
    /// À-trous iterations (5×5 taps, spacing 2^i); the first one's output is the colour history.
    pub atrous_iterations: u32,
    /// Luminance edge-stop σ_l (in units of the local standard deviation).
    pub sigma_luminance: f32,
    /// Depth edge-stop σ_z (in units of the depth gradient × distance).
    pub sigma_depth: f32,
    /// Normal edge-stop exponent σ_n.
    pub sigma_normal: f32,
}

impl Default for SvgfSettings {
    fn default() -> Self {
        SvgfSettings {
            alpha_color: 0.2,
            alpha_moments: 0.2,
            max_history: 32,
            variance_history: 4,
            atrous_iterations: 5,
            sigma_luminance: 4.0,
            sigma_depth: 1.0,
            sigma_normal: 128.0,
        }
    }
}

/// Most à-trous iterations accepted: 2^9 texels apart is wider than any grid.
pub const MAX_ATROUS_ITERATIONS: u32 = 10;

impl SvgfSettings {
    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(Error::Invalid(format!("svgf: {what}")));
        let unit = |a: f32| a > 0.0 && a <= 1.0;
        if !unit(self.alpha_color) || !unit(self.alpha_moments) {
            return bad(format!(
                "alphas must be in (0, 1], got {} and {}",
                self.alpha_color, self.alpha_moments
            ));
        }
        if self.max_history == 0 {
            return bad("max_history must be at least 1".into());
        }
        if !(1..=MAX_ATROUS_ITERATIONS).contains(&self.atrous_iterations) {
            return bad(format!(
                "atrous_iterations must be in 1..={MAX_ATROUS_ITERATIONS}, got {}",
                self.atrous_iterations
            ));
        }
        let sigmas = [self.sigma_luminance, self.sigma_depth, self.sigma_normal];
        if !sigmas.iter().all(|s| s.is_finite() && *s > 0.0) {
            return bad(format!(
                "σ_l, σ_z, σ_n must be finite and > 0, got {sigmas:?}"
            ));
        }
        Ok(())
    }
}

/// Per-eye temporal state: everything SVGF carries from one frame to the next, allocated once.
/// Moments and surfaces ping-pong by frame parity (a frame reads the other half at reprojected
/// positions while writing its own); the colour history is read by the temporal pass before the
/// first à-trous iteration overwrites it in the same frame.
pub struct SvgfHistory {
    /// Colour history: the first à-trous iteration's output (rgb demodulated, a variance).
    pub color: Image,
    /// x m1, y m2 (luminance moments), z history length in frames.
    pub moments: [Image; 2],
    /// Packed surface the moments belong to (normal, depth, depth gradient, mesh).
    pub surface: [Image; 2],
    /// Frames recorded so far; the parity picks this frame's half.
    frames: u64,
}

impl SvgfHistory {
    fn new(ctx: &Arc<Context>, grid: UVec2) -> Result<SvgfHistory> {
        let image = |name: &str, format| Image::new(ctx, name, grid.x, grid.y, format);
        let rgba = vk::Format::R32G32B32A32_SFLOAT;
        let surface = vk::Format::R32G32B32A32_UINT;
        Ok(SvgfHistory {
            color: image("svgf.history_color", rgba)?,
            moments: [image("svgf.moments0", rgba)?, image("svgf.moments1", rgba)?],
            surface: [
                image("svgf.surface0", surface)?,
                image("svgf.surface1", surface)?,
            ],
            frames: 0,
        })
    }

    fn current(&self) -> usize {
        (self.frames % 2) as usize
    }

    /// GPU bytes of the state carried between frames (the per-eye memory cost of the filter).
    pub fn bytes(&self) -> u64 {
        [
            &self.color,
            &self.moments[0],
            &self.moments[1],
            &self.surface[0],
            &self.surface[1],
        ]
        .iter()
        .map(|i| i.width as u64 * i.height as u64 * i.texel_bytes())
        .sum()
    }
}

pub struct Svgf {
    pub settings: SvgfSettings,
    temporal: TemporalPass,
    variance: VariancePass,
    atrous: AtrousPass,
    idle: IdlePass,
    modulate: ModulatePass,
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
            temporal: TemporalPass::new(ctx, temporal_variant)?,
            variance: VariancePass::new(ctx, variant)?,
            atrous: AtrousPass::new(ctx, variant)?,
            idle: IdlePass::new(ctx, variant)?,
            modulate: ModulatePass::new(ctx)?,
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
    pub fn record(
        &mut self,
        rec: &mut FrameRecorder,
        g: &GBuffer,
        frame: &DenoiseFrame,
    ) -> Result<&Image> {
        self.record_with(rec, g, frame, None)
    }

    /// `record` for SVGF built by `adaptive`: `gradient` (per 3×3 stratum: δ̂, max f, confidence)
    /// sets each texel's temporal α.
    pub(crate) fn record_adaptive(
        &mut self,
        rec: &mut FrameRecorder,
        g: &GBuffer,
        frame: &DenoiseFrame,
        gradient: &Image,
    ) -> Result<&Image> {
        self.record_with(rec, g, frame, Some(gradient))
    }

    fn record_with(
        &mut self,
        rec: &mut FrameRecorder,
        g: &GBuffer,
        frame: &DenoiseFrame,
        gradient: Option<&Image>,
    ) -> Result<&Image> {
        let s = self.settings;
        let h = &self.history;
        let (cur, prev) = (h.current(), 1 - h.current());
        let previous = if h.frames == 0 { None } else { frame.previous };
        let (table, tiles) = (frame.sampling_table, &frame.tiles);
        self.temporal.record(
            rec,
            g,
            h,
            prev,
            cur,
            &self.accum,
            &frame.current,
            table,
            tiles,
            previous.as_ref(),
            &s,
            gradient,
        )?;
        self.idle
            .record(rec, h, cur, &frame.current, table, tiles)?;
        self.variance.record(
            rec,
            g,
            &self.accum,
            &h.moments[cur],
            &self.ping[0],
            &frame.current,
            table,
            tiles,
            &s,
        )?;
        // Iteration 0 writes the colour history; then the two ping images alternate.
        let mut src = &self.ping[0];
        for i in 0..s.atrous_iterations {
            let dst = if i == 0 {
                &h.color
            } else {
                &self.ping[(i % 2) as usize]
            };
            self.atrous
                .record(rec, g, src, dst, 1 << i, &frame.current, table, tiles, &s)?;
            src = dst;
        }
        self.modulate
            .record(rec, "svgf_modulate", src, &g.albedo, &self.output)?;
        self.history.frames += 1;
        Ok(&self.output)
    }
}
