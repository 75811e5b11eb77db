//! Foveated blur (visual-polar.md §7): two separable Gaussian passes whose σ is 0 inside the
//! fovea and grows linearly beyond it, reaching `sigma_at_30` pixels at 30° (the paper's
//! normalised eccentricity) — 6.8 px for the 1280×1440 FOVE eye. The last axis can write the
//! display image itself (tone curve and sRGB encoding, the `ldr` variants), which saves the
//! tonemap's full-screen pass when nothing reads the blurred radiance. `BlurSettings` scale σ to
//! the screen; `FoveatedBlur` is the pass with the screen-sized images a way back blurs with.

use crate::error::Result;
use crate::graph::{read_image, write_image, FrameRecorder};
use crate::layouts::{BlurPush, TonemapPush, BLUR_MAX_RADIUS};
use crate::passes::push_bytes;
use crate::passes::tonemap::{no_external_targets, LdrTarget, ToneTarget};
use crate::sampling::VisualPolar;
use crate::vk::{ComputePipeline, Context, Image};
use ash::vk;
use glam::{UVec2, UVec4, Vec2, Vec4};
use std::sync::Arc;

/// The paper's blur strength: σ = 6.8 px at 30° on the 1280×1440 FOVE 0 eye.
pub const FOVE_SIGMA_AT_30: f32 = 6.8;
/// Eccentricity (the paper's normalised degrees) at which the blur reaches its nominal σ.
const SIGMA_REFERENCE_DEG: f32 = 30.0;
/// Pixels of the screen the paper's σ was chosen for.
const FOVE_EYE_PIXELS: f32 = 1280.0 * 1440.0;

/// Where the foveated blur runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BlurSpace {
    /// On the remapped screen image, one pass per screen axis (the paper's).
    #[default]
    Screen,
    /// In the Visual-Polar grid before the remap, along φ and ρ (`blur_grid`): no
    /// full-screen blur pass. Spaces it cannot serve (screen-clipped layouts, the headset axis)
    /// and screen-space TAA, which must see the unblurred remap, keep the screen blur.
    Grid,
}

impl BlurSpace {
    pub fn name(self) -> &'static str {
        match self {
            BlurSpace::Screen => "screen",
            BlurSpace::Grid => "grid",
        }
    }
}

/// Foveated-blur settings; σ scales with resolution (per unit of screen length).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlurSettings {
    /// σ in pixels at 30° for a 1280×1440 screen (0 turns the blur off).
    pub sigma_at_30: f32,
    pub space: BlurSpace,
}

impl Default for BlurSettings {
    fn default() -> Self {
        BlurSettings {
            sigma_at_30: FOVE_SIGMA_AT_30,
            space: BlurSpace::default(),
        }
    }
}

impl BlurSettings {
    /// The blur for one gaze: σ = 0 inside `blur_start`, then growing at the paper's rate
    /// (`sigma_at_30`, scaled to this screen, at 30° for a blur starting at the fovea's edge).
    pub fn shape(&self, vp: &VisualPolar) -> BlurShape {
        let screen = vp.screen().as_vec2();
        let sigma_30 = self.sigma_at_30 * (screen.x * screen.y / FOVE_EYE_PIXELS).sqrt();
        let r_f = vp.r_fovea();
        let r_30 = vp.radius_of_eccentricity(SIGMA_REFERENCE_DEG);
        let slope = if r_30 > r_f {
            sigma_30 / (r_30 - r_f)
        } else {
            0.0
        };
        // The slope is the paper's (fovea edge → 30°); the blur starts where the space leaves the
        // image sharp (the fovea; log-polar: the buffer's inner half).
        BlurShape {
            gaze: vp.gaze(),
            fovea_radius: vp.blur_start(),
            sigma_slope: slope,
        }
    }
}

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
                let [dst, exposure] = target.binds("dst");
                let binds = [read_image("src", scratch), dst, exposure];
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

/// The foveated blur at the end of a way back, with its screen-sized scratch and output.
pub struct FoveatedBlur {
    pass: BlurPass,
    scratch: Image,
    /// Final linear radiance on the screen.
    pub blurred: Image,
}

impl FoveatedBlur {
    pub fn new(ctx: &Arc<Context>, screen: UVec2) -> Result<FoveatedBlur> {
        let image = |name: &str| {
            Image::new(
                ctx,
                name,
                screen.x,
                screen.y,
                vk::Format::R32G32B32A32_SFLOAT,
            )
        };
        Ok(FoveatedBlur {
            pass: BlurPass::new(ctx)?,
            scratch: image("screen.blur_scratch")?,
            blurred: image("screen.blurred")?,
        })
    }

    /// Blurs `src` around `axis`'s gaze into `blurred`; `src` itself when σ is 0.
    pub fn record<'a>(
        &'a self,
        rec: &mut FrameRecorder,
        settings: &BlurSettings,
        axis: &VisualPolar,
        src: &'a Image,
    ) -> Result<&'a Image> {
        if settings.sigma_at_30 <= 0.0 {
            return Ok(src);
        }
        self.pass.record(
            rec,
            &settings.shape(axis),
            src,
            &self.scratch,
            BlurTarget::Radiance(&self.blurred),
        )?;
        Ok(&self.blurred)
    }

    /// The blur of `src` around `axis`'s gaze, to record later: its last axis may write the
    /// display image itself (`PendingBlur::display`). `None` at σ 0 (nothing to blur).
    pub fn pending<'a>(
        &'a self,
        settings: &BlurSettings,
        axis: &VisualPolar,
        src: &'a Image,
    ) -> Option<PendingBlur<'a>> {
        (settings.sigma_at_30 > 0.0).then(|| PendingBlur {
            blur: self,
            shape: settings.shape(axis),
            src,
        })
    }
}

/// A foveated blur not yet recorded: the last step of a way back, left to the frame so that the
/// exposure can be metered on `src` (a blur barely moves a mean of log luminance) before the
/// blur's last axis writes the display image with it.
pub struct PendingBlur<'a> {
    blur: &'a FoveatedBlur,
    shape: BlurShape,
    /// The unblurred screen radiance.
    pub src: &'a Image,
}

impl<'a> PendingBlur<'a> {
    /// Records the blur into the screen's radiance image.
    pub fn radiance(self, rec: &mut FrameRecorder) -> Result<&'a Image> {
        let b = self.blur;
        b.pass.record(
            rec,
            &self.shape,
            self.src,
            &b.scratch,
            BlurTarget::Radiance(&b.blurred),
        )?;
        Ok(&b.blurred)
    }

    /// Records the blur, its last axis writing `target` (the tone mapping fused in).
    pub fn display(self, rec: &mut FrameRecorder, target: ToneTarget) -> Result<()> {
        let b = self.blur;
        b.pass.record(
            rec,
            &self.shape,
            self.src,
            &b.scratch,
            BlurTarget::Display(target),
        )
    }
}
