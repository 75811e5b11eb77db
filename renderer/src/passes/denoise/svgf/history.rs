//! What SVGF carries from one frame to the next.

use crate::error::Result;
use crate::vk::{Context, Image};
use ash::vk;
use glam::UVec2;
use std::sync::Arc;

/// Per-eye temporal state: everything SVGF carries from one frame to the next, allocated once.
/// Moments and surfaces ping-pong by frame parity (a frame reads the other half at reprojected
/// positions while writing its own); the colour history is read by the temporal pass before the
/// first à-trous iteration overwrites it in the same frame.
pub struct SvgfHistory {
    /// Colour history: the first à-trous iteration's output (rgb demodulated, a variance).
    pub color: Image,
    /// x m1, y m2 (luminance moments), z history length in frames.
    pub moments: [Image; 2],
    /// Packed surface the moments belong to (normal, depth, depth gradient, mesh).
    pub surface: [Image; 2],
    /// Frames recorded so far; the parity picks this frame's half.
    pub(super) frames: u64,
}

impl SvgfHistory {
    pub(super) fn new(ctx: &Arc<Context>, grid: UVec2) -> Result<SvgfHistory> {
        let image = |name: &str, format| Image::new(ctx, name, grid.x, grid.y, format);
        let rgba = vk::Format::R32G32B32A32_SFLOAT;
        let surface = vk::Format::R32G32B32A32_UINT;
        Ok(SvgfHistory {
            color: image("svgf.history_color", rgba)?,
            moments: [image("svgf.moments0", rgba)?, image("svgf.moments1", rgba)?],
            surface: [
                image("svgf.surface0", surface)?,
                image("svgf.surface1", surface)?,
            ],
            frames: 0,
        })
    }

    pub(super) fn current(&self) -> usize {
        (self.frames % 2) as usize
    }

    /// GPU bytes of the state carried between frames (the per-eye memory cost of the filter).
    pub fn bytes(&self) -> u64 {
        [
            &self.color,
            &self.moments[0],
            &self.moments[1],
            &self.surface[0],
            &self.surface[1],
        ]
        .iter()
        .map(|i| i.width as u64 * i.height as u64 * i.texel_bytes())
        .sum()
    }
}
