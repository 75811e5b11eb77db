//! A-SVGF — SVGF with temporal gradients (Schied, Peters, Dachsbacher 2018; denoisers.md) on the
//! sampling grid. Per 3×3 stratum one sample of last frame (the brightest; with resampling one the
//! tracer picked) is forward-projected into this frame's grid (`forward`), where the tracer's
//! gradient variant traces that sample's path on that surface again with its random state, apart
//! from the texel's own sample: δ = f_i − f_{i−1} is then the change of the lighting alone.
//! The gradients are reconstructed at 1/3 resolution by joint-bilateral à-trous iterations
//! (`gradient`), and SVGF's temporal accumulation uses α_i = (1 − λ)·α + λ with
//! λ = |δ̂| / max(f_i, f_{i−1}) (its `*_adaptive` kernel variant); the rest is SVGF's.
//!
//! Visual-Polar: strata wrap on φ (on full circles; the screen-clipped layout's clipped arcs end)
//! and end at the grid on ρ (`shaders/denoise/strata.glsl`); the projection goes world → this
//! frame's screen → this frame's grid (this frame's gaze).

mod forward;
mod gradient;
mod settings;

pub use settings::{AsvgfSettings, MAX_GRADIENT_ITERATIONS};

use super::svgf::Svgf;
use crate::error::Result;
use crate::graph::FrameRecorder;
use crate::layouts::{AsvgfGradientSample, ASVGF_STRATUM};
use crate::passes::denoise::svgf::SvgfSettings;
use crate::passes::denoise::{Denoiser, DenoiserParams, OtherParams};
use crate::passes::grid::{GradientTargets, GridFrame};
use crate::passes::Pass;
use crate::vk::{Buffer, Context, Image};
use ash::vk;
use forward::Forward;
use glam::UVec2;
use gpu_allocator::MemoryLocation;
use gradient::Gradient;
use std::sync::Arc;

pub struct Asvgf {
    pub settings: AsvgfSettings,
    pub svgf: Svgf,
    forward: Pass<Forward>,
    gradient: Pass<Gradient>,
    /// One `AsvgfGradientSample` per stratum, cleared every frame (host-visible for inspection).
    pub samples: Buffer,
    /// Per stratum: δ, max f, 1 where the tracer re-shaded a sample (zeros elsewhere).
    raw: Image,
    /// Reconstruction ping-pong (strata-sized: δ̂, max f, confidence).
    ping: [Image; 2],
    /// Bytes of the G-buffer's visibility image, which carries last frame's samples to this one.
    visibility_bytes: u64,
    frames: u64,
}

impl Asvgf {
    /// `variant`: the sampling space's kernel variant (`cartesian`, `visual_polar`).
    pub fn new(
        ctx: &Arc<Context>,
        grid: UVec2,
        variant: &str,
        settings: AsvgfSettings,
    ) -> Result<Asvgf> {
        settings.validate()?;
        let strata = (grid + (ASVGF_STRATUM - 1)) / ASVGF_STRATUM;
        let count = strata.x as u64 * strata.y as u64;
        let image = |name: &str| {
            Image::new(
                ctx,
                name,
                strata.x,
                strata.y,
                vk::Format::R32G32B32A32_SFLOAT,
            )
        };
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
        let sample_bytes = std::mem::size_of::<AsvgfGradientSample>() as u64;
        Ok(Asvgf {
            settings,
            svgf: Svgf::adaptive(ctx, grid, variant, settings.svgf)?,
            forward: Pass::new(ctx, variant)?,
            gradient: Pass::new(ctx, variant)?,
            samples: Buffer::new(
                ctx,
                "asvgf.gradient_samples",
                count * sample_bytes,
                usage,
                MemoryLocation::GpuToCpu,
            )?,
            raw: image("asvgf.gradient_raw")?,
            ping: [image("asvgf.gradient0")?, image("asvgf.gradient1")?],
            visibility_bytes: grid.x as u64 * grid.y as u64 * 16,
            frames: 0,
        })
    }

    /// Dispatches (and fills) one frame records at most.
    pub fn max_passes(&self) -> u32 {
        self.svgf.max_passes() + self.settings.gradient_iterations + 2
    }

    /// GPU bytes carried between frames: SVGF's history and the visibility the projection reads.
    pub fn history_bytes(&self) -> u64 {
        self.svgf.history.bytes() + self.visibility_bytes
    }

    /// Before the tracer: clears the gradient samples and projects last frame's into them (none on
    /// the first frame or without a previous frame).
    pub fn record_before_trace(
        &mut self,
        rec: &mut FrameRecorder,
        frame: &GridFrame,
    ) -> Result<()> {
        rec.fill_buffer("asvgf_clear", &self.samples, 0)?;
        let project = self.frames > 0 && frame.previous.is_some();
        self.forward
            .record(rec, frame, &self.gradient_targets(), project)
    }

    /// The tracer's gradient-variant inputs and outputs.
    pub fn gradient_targets(&self) -> GradientTargets<'_> {
        GradientTargets {
            samples: &self.samples,
            gradient: &self.raw,
        }
    }

    /// After the tracer: reconstructs the gradients, then SVGF with the adaptive α.
    pub fn record(&mut self, rec: &mut FrameRecorder, frame: &GridFrame) -> Result<&Image> {
        let s = self.settings;
        let mut src = &self.raw;
        for i in 0..s.gradient_iterations {
            let dst = &self.ping[(i % 2) as usize];
            self.gradient.record(rec, frame, (src, dst), 1 << i, &s)?;
            src = dst;
        }
        let gradient = &self.ping[((s.gradient_iterations - 1) % 2) as usize];
        self.frames += 1;
        self.svgf.record_adaptive(rec, frame, gradient)
    }

    /// The gradient samples of the last recorded frame.
    pub fn read_samples(&self) -> Result<Vec<AsvgfGradientSample>> {
        let strata = self.strata();
        let mut out = vec![AsvgfGradientSample::default(); (strata.x * strata.y) as usize];
        self.samples.read_into(&mut out)?;
        Ok(out)
    }

    /// The reconstructed gradient of the last recorded frame (δ̂, max f, confidence per stratum).
    pub fn gradient(&self) -> &Image {
        &self.ping[((self.settings.gradient_iterations - 1) % 2) as usize]
    }

    /// Size of the strata grid.
    pub fn strata(&self) -> UVec2 {
        UVec2::new(self.raw.width, self.raw.height)
    }
}

impl DenoiserParams for AsvgfSettings {
    const NAME: &'static str = "asvgf";
    const NEEDS_GRADIENTS: bool = true;

    fn validate(&self) -> Result<()> {
        AsvgfSettings::validate(self)
    }

    fn build(&self, ctx: &Arc<Context>, grid: UVec2, variant: &str) -> Result<Box<dyn Denoiser>> {
        Ok(Box::new(Asvgf::new(ctx, grid, variant, *self)?))
    }

    /// The SVGF stages take SVGF's parameters (a render profile's `[svgf]`).
    fn complete(&mut self, others: &dyn OtherParams) {
        let svgf = others.params(SvgfSettings::NAME);
        if let Some(svgf) = svgf.and_then(|p| p.downcast_ref::<SvgfSettings>()) {
            self.svgf = *svgf;
        }
    }
}

impl Denoiser for Asvgf {
    fn history_bytes(&self) -> u64 {
        Asvgf::history_bytes(self)
    }

    fn max_passes(&self) -> u32 {
        Asvgf::max_passes(self)
    }

    fn record_before_trace(&mut self, rec: &mut FrameRecorder, frame: &GridFrame) -> Result<()> {
        Asvgf::record_before_trace(self, rec, frame)
    }

    fn gradient_targets(&self) -> Option<GradientTargets<'_>> {
        Some(Asvgf::gradient_targets(self))
    }

    fn record(&mut self, rec: &mut FrameRecorder, frame: &GridFrame) -> Result<&Image> {
        Asvgf::record(self, rec, frame)
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}
