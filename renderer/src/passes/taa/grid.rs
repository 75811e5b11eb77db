//! TAA in the sampling grid, as the paper does: the tracer jitters each frame by a Halton(2, 3)
//! offset inside the grid texel (Visual-Polar: inside the VP texel), and one pass reprojects the
//! history through the previous frame's grid, clips it toward this frame's 3×3 YCoCg
//! neighbourhood and blends it with luma weights. It runs after the denoiser (or on the raw
//! colour) and before the way back to the screen.

use super::TaaSettings;
use crate::error::Result;
use crate::graph::{read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::TaaPush;
use crate::passes::grid::GridFrame;
use crate::passes::{Kernel, Pass};
use crate::vk::{Context, Image};
use ash::vk;
use glam::{UVec2, Vec2, Vec4};
use std::sync::Arc;

/// The grid TAA's resolve (`shaders/passes/taa.comp`, a variant per sampling space).
pub struct TaaKernel;

impl Kernel for TaaKernel {
    const SHADER: &'static str = "passes/taa";
    type Push = TaaPush;
}

/// Per-eye TAA: the pass and its ping-pong history, allocated once.
pub struct Taa {
    pub settings: TaaSettings,
    pass: Pass<TaaKernel>,
    /// Resolved colour by frame parity; this frame's half is also the pass's output.
    history: [Image; 2],
    /// The packed surface each history texel belongs to (disocclusion test).
    surface: [Image; 2],
    frames: u64,
}

impl Taa {
    /// `variant`: the sampling space's kernel variant (`cartesian`, `visual_polar`).
    pub fn new(
        ctx: &Arc<Context>,
        grid: UVec2,
        variant: &str,
        settings: TaaSettings,
    ) -> Result<Taa> {
        settings.validate()?;
        let image = |name: &str, format| Image::new(ctx, name, grid.x, grid.y, format);
        let (rgba, surface) = (
            vk::Format::R32G32B32A32_SFLOAT,
            vk::Format::R32G32B32A32_UINT,
        );
        Ok(Taa {
            settings,
            pass: Pass::new(ctx, variant)?,
            history: [image("taa.history0", rgba)?, image("taa.history1", rgba)?],
            surface: [
                image("taa.surface0", surface)?,
                image("taa.surface1", surface)?,
            ],
            frames: 0,
        })
    }

    /// GPU bytes carried between frames.
    pub fn history_bytes(&self) -> u64 {
        self.history
            .iter()
            .chain(&self.surface)
            .map(|i| i.width as u64 * i.height as u64 * i.texel_bytes())
            .sum()
    }

    /// Resolves `color` (grid-sized radiance) against the history; `jitter` is the offset the
    /// tracer used this frame (`TaaSettings::jitter`). History is dropped on the first frame and
    /// whenever `frame.previous` is `None`. Returns the resolved image (next frame's history).
    pub fn record(
        &mut self,
        rec: &mut FrameRecorder,
        color: &Image,
        frame: &GridFrame,
        jitter: Vec2,
    ) -> Result<&Image> {
        let g = frame.gbuffer;
        let cur = (self.frames % 2) as usize;
        let previous = if self.frames == 0 {
            None
        } else {
            frame.previous
        };
        let binds = [
            read_image("color", color),
            read_image("normal_depth", &g.normal_depth),
            read_image("position", &g.position),
            read_image("ids", &g.ids),
            read_image("motion", &g.motion),
            read_image("prev_history", &self.history[1 - cur]),
            read_image("prev_surface", &self.surface[1 - cur]),
            write_image("history", &self.history[cur]),
            write_image("surface", &self.surface[cur]),
            read_texels("grid_columns", frame.sampling_table),
        ];
        let (current, p) = (&frame.current, previous.as_ref().unwrap_or(&frame.current));
        let reset = if previous.is_none() { 1.0 } else { 0.0 };
        let push = TaaPush {
            space: *current,
            prev: p.frame(),
            params: Vec4::new(self.settings.current_weight, reset, jitter.x, jitter.y),
        };
        let out = &self.history[cur];
        self.pass
            .dispatch(rec, "taa", &binds, &push, [out.width, out.height, 1])?;
        self.frames += 1;
        Ok(&self.history[cur])
    }
}
