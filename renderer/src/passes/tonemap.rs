//! Exposure, tone curve and sRGB encoding into an 8-bit image: the engine's own RGBA8 image, or
//! an external one (a swapchain image) at an offset.

use super::push_bytes;
use crate::error::Result;
use crate::graph::{read_image, write_external, write_image, Bind, ExternalImage, FrameRecorder};
use crate::layouts::{TonemapPush, TONEMAP_ACES, TONEMAP_CLAMP};
use crate::vk::{ComputePipeline, Context, Image};
use glam::{UVec2, UVec4, Vec4};
use std::sync::Arc;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ToneCurve {
    /// Plain clamp to [0, 1]: exact for images whose radiance stays below 1 (tests).
    Clamp,
    /// The fitted ACES filmic curve.
    #[default]
    Aces,
}

/// Where the tonemapped pixels go.
#[derive(Clone, Copy)]
pub enum LdrTarget<'a> {
    Own(&'a Image),
    /// An external image, the view's top-left pixel at `offset`.
    External { image: &'a ExternalImage, offset: UVec2 },
}

pub struct TonemapPass {
    own: Arc<ComputePipeline>,
    /// Built only when the device can write storage images without a format (external targets).
    external: Option<Arc<ComputePipeline>>,
}

impl TonemapPass {
    pub fn new(ctx: &Arc<Context>) -> Result<TonemapPass> {
        let push = std::mem::size_of::<TonemapPush>() as u32;
        let external = match ctx.storage_write_without_format {
            true => Some(ComputePipeline::shared(ctx, "passes/tonemap.external", push)?),
            false => None,
        };
        Ok(TonemapPass { own: ComputePipeline::shared(ctx, "passes/tonemap.own", push)?, external })
    }

    /// `pass` names the dispatch in the timing report (the frame and the debug grid view differ).
    pub fn record(&self, rec: &mut FrameRecorder, pass: &'static str, hdr: &Image, ldr: LdrTarget, exposure: f32, curve: ToneCurve) -> Result<()> {
        let op = match curve {
            ToneCurve::Clamp => TONEMAP_CLAMP,
            ToneCurve::Aces => TONEMAP_ACES,
        };
        let (pipeline, target, offset): (&ComputePipeline, Bind, UVec2) = match ldr {
            LdrTarget::Own(image) => (&self.own, write_image("ldr", image), UVec2::ZERO),
            LdrTarget::External { image, offset } => {
                let pipeline = self.external.as_ref().ok_or_else(|| crate::Error::Invalid(
                    "this device cannot write storage images without a format (shaderStorageImageWriteWithoutFormat): no external targets".into(),
                ))?;
                (pipeline, write_external("ldr", image), offset)
            }
        };
        let binds = [read_image("hdr", hdr), target];
        let push = TonemapPush { params: Vec4::new(exposure, 0.0, 0.0, 0.0), config: UVec4::new(op, offset.x, offset.y, 0) };
        rec.dispatch(pass, pipeline, &binds, push_bytes(&push), [hdr.width, hdr.height, 1])
    }
}
