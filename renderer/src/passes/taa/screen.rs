//! TAA after the remap, in screen space (beyond the paper, which lists it as future work). The
//! tracer jitters each Visual-Polar sample by the frame's Halton offset inside its VP texel, the
//! remap reads the samples where they were traced (`RemapPass` sample offset), and this pass
//! accumulates the screen images: one jitter cycle sweeps each pixel over a whole VP texel, which
//! in the periphery spans many pixels — so the neighbourhood that clips the history is spaced by
//! the local texel footprint (see `taa_screen.comp`). Runs between the remap and the foveated blur;
//! the history is screen-sized and unblurred.

use super::TaaSettings;
use crate::error::Result;
use crate::graph::{read_buffer, read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::TaaScreenPush;
use crate::passes::grid::GridFrame;
use crate::passes::{push_bytes, VpLayoutPipelines};
use crate::vk::{Context, Image};
use ash::vk;
use glam::{UVec2, Vec4};
use std::sync::Arc;

/// Per-eye screen-space TAA: the pass and its ping-pong history (colour + the depth it was
/// resolved with), allocated once.
pub struct ScreenTaa {
    pub settings: TaaSettings,
    pipelines: VpLayoutPipelines,
    history: [Image; 2],
    frames: u64,
}

impl ScreenTaa {
    pub fn new(ctx: &Arc<Context>, screen: UVec2, settings: TaaSettings) -> Result<ScreenTaa> {
        settings.validate()?;
        let image = |name: &str| {
            Image::new(
                ctx,
                name,
                screen.x,
                screen.y,
                vk::Format::R32G32B32A32_SFLOAT,
            )
        };
        Ok(ScreenTaa {
            settings,
            pipelines: VpLayoutPipelines::new(
                ctx,
                "passes/taa_screen",
                std::mem::size_of::<TaaScreenPush>() as u32,
            )?,
            history: [image("taa_screen.history0")?, image("taa_screen.history1")?],
            frames: 0,
        })
    }

    /// GPU bytes carried between frames.
    pub fn history_bytes(&self) -> u64 {
        self.history
            .iter()
            .map(|i| i.width as u64 * i.height as u64 * i.texel_bytes())
            .sum()
    }

    /// Resolves the remapped `color` (screen-sized) against the history; returns the resolved
    /// image (next frame's history). `frame`: the Visual-Polar grid the remapped image came from
    /// (its G-buffer's depths reproject; the cameras are in its frame data).
    pub fn record(
        &mut self,
        rec: &mut FrameRecorder,
        color: &Image,
        frame: &GridFrame,
    ) -> Result<&Image> {
        let cur = (self.frames % 2) as usize;
        let reset = self.frames == 0 || frame.previous.is_none();
        let binds = [
            read_buffer("frame", frame.frame_data),
            read_image("color", color),
            read_image("normal_depth", &frame.gbuffer.normal_depth),
            read_image("position", &frame.gbuffer.position),
            read_image("prev_history", &self.history[1 - cur]),
            write_image("history", &self.history[cur]),
            read_texels("vp_columns", frame.sampling_table),
        ];
        let push = TaaScreenPush {
            space: frame.current,
            params: Vec4::new(
                self.settings.current_weight,
                if reset { 1.0 } else { 0.0 },
                0.0,
                0.0,
            ),
        };
        let out = &self.history[cur];
        rec.dispatch(
            "taa_screen",
            self.pipelines.for_space(&frame.current),
            &binds,
            push_bytes(&push),
            [out.width, out.height, 1],
        )?;
        self.frames += 1;
        Ok(&self.history[cur])
    }
}
