//! Denoisers (issue 5; shared/design/denoisers.md). They run in the sampling grid between the
//! tracer and the way to the screen — texel = sample, in Cartesian and Visual-Polar space alike —
//! and return re-modulated radiance of the grid's size. Each is a sibling module here (SVGF,
//! A-SVGF, BMFR; TAA, which runs after them, is `passes::taa`), one pass = one module + one
//! shader (a variant per sampling space, `shaders/passes/denoise/`) + one push-constant struct
//! in `layouts.glsl`; the grid addressing they share is `shaders/denoise/grid.glsl`.

pub mod asvgf;
pub mod bmfr;
pub mod modulate;
pub mod svgf;

use crate::error::{Error, Result};
use crate::graph::FrameRecorder;
use crate::passes::grid::{GradientTargets, GridFrame};
use crate::vk::{Context, Image};
use asvgf::{Asvgf, AsvgfSettings};
use bmfr::{Bmfr, BmfrSettings};
use glam::UVec2;
use std::sync::Arc;
use svgf::{Svgf, SvgfSettings};

/// Which denoiser runs after the tracer (`fovea render --denoiser`).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum DenoiserSettings {
    /// The tracer's 1-sample colour goes to the screen as is.
    #[default]
    None,
    Svgf(SvgfSettings),
    Asvgf(AsvgfSettings),
    Bmfr(BmfrSettings),
}

impl DenoiserSettings {
    /// The names `parse` accepts.
    pub const NAMES: &'static [&'static str] = &["none", "svgf", "asvgf", "bmfr"];

    /// A denoiser by name, with its defaults.
    pub fn parse(name: &str) -> Result<DenoiserSettings> {
        match name {
            "none" => Ok(DenoiserSettings::None),
            "svgf" => Ok(DenoiserSettings::Svgf(SvgfSettings::default())),
            "asvgf" => Ok(DenoiserSettings::Asvgf(AsvgfSettings::default())),
            "bmfr" => Ok(DenoiserSettings::Bmfr(BmfrSettings::default())),
            other => Err(Error::Invalid(format!(
                "denoiser '{other}': expected one of {}",
                Self::NAMES.join(", ")
            ))),
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            DenoiserSettings::None => "none",
            DenoiserSettings::Svgf(_) => "svgf",
            DenoiserSettings::Asvgf(_) => "asvgf",
            DenoiserSettings::Bmfr(_) => "bmfr",
        }
    }

    /// Whether the tracer must re-shade gradient samples (its `*_gradients` variant) and keep
    /// the visibility they are projected from.
    pub fn needs_gradients(&self) -> bool {
        matches!(self, DenoiserSettings::Asvgf(_))
    }
}

/// A denoiser with its per-eye state.
pub enum Denoiser {
    Svgf(Box<Svgf>),
    Asvgf(Box<Asvgf>),
    Bmfr(Box<Bmfr>),
}

impl Denoiser {
    /// `variant` is the sampling space's kernel variant (`SamplingSpace::shader_variant`).
    pub fn new(
        ctx: &Arc<Context>,
        settings: &DenoiserSettings,
        grid: UVec2,
        variant: &str,
    ) -> Result<Option<Denoiser>> {
        Ok(match settings {
            DenoiserSettings::None => None,
            DenoiserSettings::Svgf(s) => {
                Some(Denoiser::Svgf(Box::new(Svgf::new(ctx, grid, variant, *s)?)))
            }
            DenoiserSettings::Asvgf(s) => Some(Denoiser::Asvgf(Box::new(Asvgf::new(
                ctx, grid, variant, *s,
            )?))),
            DenoiserSettings::Bmfr(s) => {
                Some(Denoiser::Bmfr(Box::new(Bmfr::new(ctx, grid, variant, *s)?)))
            }
        })
    }

    /// GPU bytes of the history carried between frames.
    pub fn history_bytes(&self) -> u64 {
        match self {
            Denoiser::Svgf(s) => s.history.bytes(),
            Denoiser::Asvgf(a) => a.history_bytes(),
            Denoiser::Bmfr(b) => b.history.bytes(),
        }
    }

    /// Dispatches one frame records at most.
    pub fn max_passes(&self) -> u32 {
        match self {
            Denoiser::Svgf(s) => s.max_passes(),
            Denoiser::Asvgf(a) => a.max_passes(),
            Denoiser::Bmfr(b) => b.max_passes(),
        }
    }

    /// Records what must run before the tracer, while the G-buffer still holds last frame (A-SVGF's
    /// forward projection).
    pub fn record_before_trace(
        &mut self,
        rec: &mut FrameRecorder,
        frame: &GridFrame,
    ) -> Result<()> {
        match self {
            Denoiser::Svgf(_) | Denoiser::Bmfr(_) => Ok(()),
            Denoiser::Asvgf(a) => a.record_before_trace(rec, frame),
        }
    }

    /// What the tracer's gradient variant re-shades and writes (A-SVGF only).
    pub fn gradient_targets(&self) -> Option<GradientTargets<'_>> {
        match self {
            Denoiser::Svgf(_) | Denoiser::Bmfr(_) => None,
            Denoiser::Asvgf(a) => Some(a.gradient_targets()),
        }
    }

    /// Records the denoiser over this frame's G-buffer; returns the denoised radiance (grid-sized).
    pub fn record(&mut self, rec: &mut FrameRecorder, frame: &GridFrame) -> Result<&Image> {
        match self {
            Denoiser::Svgf(s) => s.record(rec, frame),
            Denoiser::Asvgf(a) => a.record(rec, frame),
            Denoiser::Bmfr(b) => b.record(rec, frame),
        }
    }
}
