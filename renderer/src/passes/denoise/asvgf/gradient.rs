//! One iteration of A-SVGF's gradient reconstruction: joint-bilateral à-trous on the strata grid
//! (the first iteration reads the raw gradient samples, the others the previous iteration).

use super::AsvgfSettings;
use crate::error::Result;
use crate::graph::{read_buffer, read_image, write_image, Bind, FrameRecorder};
use crate::layouts::{AsvgfGradientPush, SamplingParams};
use crate::passes::push_bytes;
use crate::passes::trace::GBuffer;
use crate::vk::{Buffer, ComputePipeline, Context, Image};
use glam::{UVec4, Vec4};
use std::sync::Arc;

/// What an iteration filters.
pub enum GradientSource<'a> {
    /// The tracer's re-shaded samples (first iteration).
    Samples(&'a Buffer),
    /// The previous iteration's output.
    Image(&'a Image),
}

pub struct GradientPass {
    from_samples: ComputePipeline,
    from_image: ComputePipeline,
}

impl GradientPass {
    pub fn new(ctx: &Arc<Context>, variant: &str) -> Result<GradientPass> {
        let push = std::mem::size_of::<AsvgfGradientPush>() as u32;
        let shader = |suffix: &str| format!("passes/denoise/asvgf_gradient.{variant}{suffix}");
        Ok(GradientPass {
            from_samples: ComputePipeline::new(ctx, &shader("_samples"), push)?,
            from_image: ComputePipeline::new(ctx, &shader(""), push)?,
        })
    }

    /// `src` → `dst` (strata-sized: δ, max f, confidence), taps `step` strata apart.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        g: &GBuffer,
        src: GradientSource,
        dst: &Image,
        step: u32,
        space: &SamplingParams,
        s: &AsvgfSettings,
    ) -> Result<()> {
        let (source, pipeline): (Bind, _) = match src {
            GradientSource::Samples(b) => (read_buffer("gradient_samples", b), &self.from_samples),
            GradientSource::Image(i) => (read_image("src", i), &self.from_image),
        };
        let binds = [source, read_image("normal_depth", &g.normal_depth), read_image("position", &g.position), write_image("dst", dst)];
        let push = AsvgfGradientPush {
            vp_grid: space.grid,
            vp_gaze: space.gaze,
            vp_shape0: space.shape0,
            vp_shape1: space.shape1,
            params: Vec4::new(s.gradient_sigma_depth, s.gradient_sigma_normal, 0.0, 0.0),
            config: UVec4::new(step, 0, 0, 0),
        };
        rec.dispatch("asvgf_gradient", pipeline, &binds, push_bytes(&push), [dst.width, dst.height, 1])
    }
}
