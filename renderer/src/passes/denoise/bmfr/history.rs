//! What BMFR carries from one frame to the next, and what its temporal passes know of the
//! previous frame.

use crate::error::Result;
use crate::layouts::SamplingParams;
use crate::vk::{Context, Image};
use ash::vk;
use glam::{UVec2, Vec3};
use std::sync::Arc;

/// Per-eye temporal state: everything BMFR carries from one frame to the next, allocated once,
/// in halves that ping-pong by frame parity (a frame reads the other half at reprojected
/// positions while writing its own).
pub struct BmfrHistory {
    /// Accumulated noisy demodulated radiance (rgb) and history length (w).
    pub noisy: [Image; 2],
    /// Accumulated normal.
    pub normal: [Image; 2],
    /// Accumulated camera-relative position (xyz; w the texel's world footprint, negative for an
    /// emitter, 0 = a miss).
    pub position: [Image; 2],
    /// Accumulated fitted colour (demodulated).
    pub filtered: [Image; 2],
    /// Frames recorded so far; the parity picks this frame's half and `% 16` the block offset.
    pub(super) frames: u64,
    /// The camera origin of the last recorded frame (positions are relative to it).
    pub(super) origin: Vec3,
}

impl BmfrHistory {
    pub(super) fn new(ctx: &Arc<Context>, grid: UVec2) -> Result<BmfrHistory> {
        let pair = |name: &str, format| -> Result<[Image; 2]> {
            Ok([
                Image::new(ctx, &format!("{name}0"), grid.x, grid.y, format)?,
                Image::new(ctx, &format!("{name}1"), grid.x, grid.y, format)?,
            ])
        };
        let rgba32 = vk::Format::R32G32B32A32_SFLOAT;
        Ok(BmfrHistory {
            noisy: pair("bmfr.noisy", rgba32)?,
            normal: pair("bmfr.normal", vk::Format::R16G16B16A16_SFLOAT)?,
            position: pair("bmfr.position", rgba32)?,
            filtered: pair("bmfr.filtered", rgba32)?,
            frames: 0,
            origin: Vec3::ZERO,
        })
    }

    pub(super) fn current(&self) -> usize {
        (self.frames % 2) as usize
    }

    /// GPU bytes of the state carried between frames (the per-eye memory cost of the filter).
    pub fn bytes(&self) -> u64 {
        [&self.noisy, &self.normal, &self.position, &self.filtered]
            .iter()
            .flat_map(|pair| pair.iter())
            .map(|i| i.width as u64 * i.height as u64 * i.texel_bytes())
            .sum()
    }
}

/// What the temporal passes need to know about the previous frame.
pub(super) struct Reprojection<'a> {
    /// The previous frame's space; `None` drops all history.
    pub previous: Option<&'a SamplingParams>,
    /// Previous camera origin − this one (positions are camera-relative).
    pub camera_shift: Vec3,
}

/// The images BMFR writes per texel in a frame: this frame's history half, the evaluated fit and
/// the output.
pub(super) struct FrameTargets<'a> {
    pub history: &'a BmfrHistory,
    pub fitted: &'a Image,
    pub output: &'a Image,
}
