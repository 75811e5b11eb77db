//! Foveated blur (visual-polar.md §7): two separable Gaussian passes whose σ is 0 inside the
//! fovea and grows linearly beyond it, reaching `sigma_at_30` pixels at 30° (the paper's
//! normalised eccentricity) — 6.8 px for the 1280×1440 FOVE eye.

use super::push_bytes;
use crate::error::Result;
use crate::graph::{read_image, write_image, FrameRecorder};
use crate::layouts::{BlurPush, BLUR_MAX_RADIUS};
use crate::vk::{ComputePipeline, Context, Image};
use glam::{UVec4, Vec2, Vec4};
use std::sync::Arc;

/// Where the blur starts and how fast it grows, in screen pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlurShape {
    pub gaze: Vec2,
    /// No blur within this distance of the gaze.
    pub fovea_radius: f32,
    /// σ (pixels) per pixel of distance beyond the fovea.
    pub sigma_slope: f32,
}

impl BlurShape {
    pub fn sigma_at(&self, r: f32) -> f32 {
        self.sigma_slope * (r - self.fovea_radius).max(0.0)
    }
}

pub struct BlurPass {
    pipeline: std::sync::Arc<ComputePipeline>,
}

impl BlurPass {
    pub fn new(ctx: &Arc<Context>) -> Result<BlurPass> {
        Ok(BlurPass { pipeline: ComputePipeline::shared(ctx, "passes/blur", std::mem::size_of::<BlurPush>() as u32)? })
    }

    /// `src` → (horizontal) → `scratch` → (vertical) → `dst`; all three screen-sized.
    pub fn record(&self, rec: &mut FrameRecorder, shape: &BlurShape, src: &Image, scratch: &Image, dst: &Image) -> Result<()> {
        for (axis, name, from, to) in [(0, "blur_h", src, scratch), (1, "blur_v", scratch, dst)] {
            let binds = [read_image("src", from), write_image("dst", to)];
            let push = BlurPush {
                shape: Vec4::new(shape.gaze.x, shape.gaze.y, shape.fovea_radius, shape.sigma_slope),
                config: UVec4::new(axis, BLUR_MAX_RADIUS, 0, 0),
            };
            rec.dispatch(name, &self.pipeline, &binds, push_bytes(&push), [to.width, to.height, 1])?;
        }
        Ok(())
    }
}
