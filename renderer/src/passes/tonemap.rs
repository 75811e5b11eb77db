//! Exposure, tone curve and sRGB encoding into an 8-bit image: the engine's own RGBA8 image, or
//! an external one (a swapchain image) at an offset. The exposure is the frame's, on the GPU
//! (`passes::exposure`).

use super::push_bytes;
use crate::error::Result;
use crate::graph::{
    read_buffer, read_image, write_external, write_image, Bind, ExternalImage, FrameRecorder,
};
use crate::layouts::{TonemapPush, TONEMAP_ACES, TONEMAP_CLAMP, TONEMAP_NEUTRAL};
use crate::vk::{Buffer, ComputePipeline, Context, Image};
use glam::{UVec2, UVec4};
use std::sync::Arc;

/// The display transform. The engine's `RenderSettings` default to ACES at a fixed exposure
/// (exact, reproducible pictures); the `fovea` commands default to Neutral with automatic
/// exposure.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToneCurve {
    /// Plain clamp to [0, 1]: exact for images whose radiance stays below 1 (tests).
    Clamp,
    /// The fitted ACES filmic curve (Narkowicz): soft highlights, darker and more saturated
    /// mid-tones than authored.
    Aces,
    /// Khronos PBR Neutral: base colours under neutral light display as authored; only
    /// highlights are compressed (toward white, gradually desaturated).
    Neutral,
}

impl ToneCurve {
    pub const NAMES: [&'static str; 3] = ["neutral", "aces", "clamp"];

    pub fn name(self) -> &'static str {
        match self {
            ToneCurve::Clamp => "clamp",
            ToneCurve::Aces => "aces",
            ToneCurve::Neutral => "neutral",
        }
    }

    pub fn from_name(name: &str) -> Option<ToneCurve> {
        match name {
            "clamp" => Some(ToneCurve::Clamp),
            "aces" => Some(ToneCurve::Aces),
            "neutral" => Some(ToneCurve::Neutral),
            _ => None,
        }
    }
}

/// Where the tonemapped pixels go.
#[derive(Clone, Copy)]
pub enum LdrTarget<'a> {
    Own(&'a Image),
    /// An external image, the view's top-left pixel at `offset`.
    External {
        image: &'a ExternalImage,
        offset: UVec2,
    },
}

/// The display image of a frame and how radiance becomes its pixels: what the tonemap pass
/// writes, or the foveated blur's last axis when it writes the display image itself.
#[derive(Clone, Copy)]
pub struct ToneTarget<'a> {
    pub ldr: LdrTarget<'a>,
    /// The frame's `ExposureState`.
    pub exposure: &'a Buffer,
    pub curve: ToneCurve,
}

impl ToneTarget<'_> {
    /// The push constants of the tone mapping (`common/tone.glsl`).
    pub fn push(&self) -> TonemapPush {
        let op = match self.curve {
            ToneCurve::Clamp => TONEMAP_CLAMP,
            ToneCurve::Aces => TONEMAP_ACES,
            ToneCurve::Neutral => TONEMAP_NEUTRAL,
        };
        let offset = match self.ldr {
            LdrTarget::Own(_) => UVec2::ZERO,
            LdrTarget::External { offset, .. } => offset,
        };
        TonemapPush {
            config: UVec4::new(op, offset.x, offset.y, 0),
        }
    }

    /// The target's bindings: the display image, named `name`, and the exposure.
    pub fn binds(&self, name: &'static str) -> [Bind<'_>; 2] {
        let ldr = match self.ldr {
            LdrTarget::Own(image) => write_image(name, image),
            LdrTarget::External { image, .. } => write_external(name, image),
        };
        [ldr, read_buffer("exposure", self.exposure)]
    }
}

/// The error for an external target on a device that cannot write storage images without a
/// format.
pub(crate) fn no_external_targets() -> crate::Error {
    crate::Error::Invalid(
        "this device cannot write storage images without a format (shaderStorageImageWriteWithoutFormat): no external targets".into(),
    )
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
            true => Some(ComputePipeline::shared(
                ctx,
                "passes/tonemap.external",
                push,
            )?),
            false => None,
        };
        Ok(TonemapPass {
            own: ComputePipeline::shared(ctx, "passes/tonemap.own", push)?,
            external,
        })
    }

    /// `pass` names the dispatch in the timing report (the frame and the debug grid view differ).
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        pass: &'static str,
        hdr: &Image,
        target: &ToneTarget,
    ) -> Result<()> {
        let pipeline: &ComputePipeline = match target.ldr {
            LdrTarget::Own(_) => &self.own,
            LdrTarget::External { .. } => self.external.as_ref().ok_or_else(no_external_targets)?,
        };
        let [ldr, exposure] = target.binds("ldr");
        let binds = [read_image("hdr", hdr), ldr, exposure];
        rec.dispatch(
            pass,
            pipeline,
            &binds,
            push_bytes(&target.push()),
            [hdr.width, hdr.height, 1],
        )
    }
}
