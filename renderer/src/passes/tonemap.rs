//! Exposure, tone curve and sRGB encoding into an RGBA8 image.

use super::push_bytes;
use crate::error::Result;
use crate::graph::{read_image, write_image, FrameRecorder};
use crate::layouts::{TonemapPush, TONEMAP_ACES, TONEMAP_CLAMP};
use crate::vk::{ComputePipeline, Context, Image};
use glam::{UVec4, Vec4};
use std::sync::Arc;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ToneCurve {
    /// Plain clamp to [0, 1]: exact for images whose radiance stays below 1 (tests).
    Clamp,
    /// The fitted ACES filmic curve.
    #[default]
    Aces,
}

pub struct TonemapPass {
    pipeline: ComputePipeline,
}

impl TonemapPass {
    pub fn new(ctx: &Arc<Context>) -> Result<TonemapPass> {
        Ok(TonemapPass { pipeline: ComputePipeline::new(ctx, "passes/tonemap", std::mem::size_of::<TonemapPush>() as u32)? })
    }

    /// `pass` names the dispatch in the timing report (the frame and the debug grid view differ).
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        pass: &'static str,
        hdr: &Image,
        ldr: &Image,
        exposure: f32,
        curve: ToneCurve,
    ) -> Result<()> {
        let binds = [read_image("hdr", hdr), write_image("ldr", ldr)];
        let op = match curve {
            ToneCurve::Clamp => TONEMAP_CLAMP,
            ToneCurve::Aces => TONEMAP_ACES,
        };
        let push = TonemapPush { params: Vec4::new(exposure, 0.0, 0.0, 0.0), config: UVec4::new(op, 0, 0, 0) };
        rec.dispatch(pass, &self.pipeline, &binds, push_bytes(&push), [ldr.width, ldr.height, 1])
    }
}
