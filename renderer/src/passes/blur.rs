//! Foveated blur (visual-polar.md §7): two separable Gaussian passes whose σ is 0 inside the
//! fovea and grows linearly beyond it, reaching `sigma_at_30` pixels at 30° (the paper's
//! normalised eccentricity) — 6.8 px for the 1280×1440 FOVE eye. The last axis can write the
//! display image itself (tone curve and sRGB encoding, the `ldr` variants), which saves the
//! tonemap's full-screen pass when nothing reads the blurred radiance.

use super::push_bytes;
use super::tonemap::{no_external_targets, LdrTarget, ToneTarget};
use crate::error::Result;
use crate::graph::{read_image, write_image, FrameRecorder};
use crate::layouts::{BlurPush, TonemapPush, BLUR_MAX_RADIUS};
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

/// Where the blur's last axis writes.
#[derive(Clone, Copy)]
pub enum BlurTarget<'a> {
    /// Radiance, into an image of the screen's size.
    Radiance(&'a Image),
    /// The display image (pass `blur_v_tonemap` in the timings).
    Display(ToneTarget<'a>),
}

pub struct BlurPass {
    hdr: Arc<ComputePipeline>,
    ldr: Arc<ComputePipeline>,
    /// Built only when the device can write storage images without a format (external targets).
    ldr_external: Option<Arc<ComputePipeline>>,
}

impl BlurPass {
    pub fn new(ctx: &Arc<Context>) -> Result<BlurPass> {
        let push = std::mem::size_of::<BlurPush>() as u32;
        let ldr_external = match ctx.storage_write_without_format {
            true => Some(ComputePipeline::shared(
                ctx,
                "passes/blur.ldr_external",
                push,
            )?),
            false => None,
        };
        Ok(BlurPass {
            hdr: ComputePipeline::shared(ctx, "passes/blur.hdr", push)?,
            ldr: ComputePipeline::shared(ctx, "passes/blur.ldr", push)?,
            ldr_external,
        })
    }

    /// `src` → (horizontal) → `scratch` → (vertical) → `dst`; `src` and `scratch` screen-sized.
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        shape: &BlurShape,
        src: &Image,
        scratch: &Image,
        dst: BlurTarget,
    ) -> Result<()> {
        let push = |axis: u32, tone: TonemapPush| BlurPush {
            shape: Vec4::new(
                shape.gaze.x,
                shape.gaze.y,
                shape.fovea_radius,
                shape.sigma_slope,
            ),
            config: UVec4::new(axis, BLUR_MAX_RADIUS, 0, 0),
            tone,
        };
        let size = [src.width, src.height, 1];
        let binds = [read_image("src", src), write_image("dst", scratch)];
        rec.dispatch(
            "blur_h",
            &self.hdr,
            &binds,
            push_bytes(&push(0, TonemapPush::default())),
            size,
        )?;
        match dst {
            BlurTarget::Radiance(image) => {
                let binds = [read_image("src", scratch), write_image("dst", image)];
                rec.dispatch(
                    "blur_v",
                    &self.hdr,
                    &binds,
                    push_bytes(&push(1, TonemapPush::default())),
                    size,
                )
            }
            BlurTarget::Display(target) => {
                let pipeline = match target.ldr {
                    LdrTarget::Own(_) => &self.ldr,
                    LdrTarget::External { .. } => {
                        self.ldr_external.as_ref().ok_or_else(no_external_targets)?
                    }
                };
                let binds = [read_image("src", scratch), target.bind("dst")];
                rec.dispatch(
                    "blur_v_tonemap",
                    pipeline,
                    &binds,
                    push_bytes(&push(1, target.push())),
                    size,
                )
            }
        }
    }
}
