//! Visual-Polar image → screen by backward mapping (visual-polar.md §6): bilinear along ρ,
//! wrapped trilinear along φ over the φ-only mips (clamped to the pixel's on-screen arc in the
//! screen-clipped layout); and the polar grids' way back around it (`RemapWayBack`).

use super::blur::{BlurSpace, FoveatedBlur};
use super::blur_grid::{GridBlur, GridBlurPass};
use super::frame::{ScreenOut, WayBackFrame, WayBackPasses};
use super::mip_phi::{MipPhiPass, PhiMips};
use crate::error::Result;
use crate::graph::{read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::{RemapPush, SamplingParams};
use crate::passes::taa::{ScreenTaa, TaaSettings};
use crate::passes::{push_bytes, VpLayoutPipelines};
use crate::sampling::SamplingSpace;
use crate::vk::{Buffer, Context, Image};
use ash::vk;
use glam::{UVec4, Vec2, Vec4};
use std::sync::Arc;

pub struct RemapPass {
    pipelines: VpLayoutPipelines,
}

impl RemapPass {
    pub fn new(ctx: &Arc<Context>) -> Result<RemapPass> {
        let size = std::mem::size_of::<RemapPush>() as u32;
        Ok(RemapPass {
            pipelines: VpLayoutPipelines::new(ctx, "passes/remap", size)?,
        })
    }

    /// Fills `screen` (screen size) from the mip stack of a VP image; `vp` and `columns` (its
    /// `VisualPolar::column_table`) hold the same space (gaze included) the image was traced with.
    /// `sample_offset`: where the samples sit in their texel minus ½ (a TAA jitter; zero for
    /// samples read as if centred).
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        vp: &SamplingParams,
        columns: &Buffer,
        mips: &PhiMips,
        screen: &Image,
        sample_offset: Vec2,
    ) -> Result<()> {
        let binds = [
            read_image("mips", &mips.image),
            write_image("screen_color", screen),
            read_texels("vp_columns", columns),
        ];
        let push = RemapPush {
            space: *vp,
            config: UVec4::new(mips.levels, 0, 0, 0),
            sample_offset: Vec4::new(sample_offset.x, sample_offset.y, 0.0, 0.0),
        };
        rec.dispatch(
            "remap",
            self.pipelines.for_space(vp),
            &binds,
            push_bytes(&push),
            [screen.width, screen.height, 1],
        )
    }
}

/// The way back of the polar grids (`WayBack::Remap`; visual-polar.md §6–7): φ-only mips →
/// remap → (screen-space TAA) → foveated blur, or the blur in the grid before the mips.
pub struct RemapWayBack {
    mip_phi: MipPhiPass,
    remap: RemapPass,
    mips: PhiMips,
    /// Remapped linear radiance (before the blur).
    remapped: Image,
    blur: FoveatedBlur,
    /// TAA between the remap and the blur (`--taa screen`).
    taa: Option<ScreenTaa>,
    /// Made for `BlurSpace::Grid` where the grid can take it and no screen-space TAA runs (it
    /// must see the unblurred remap).
    grid_blur: Option<GridBlur>,
}

impl RemapWayBack {
    /// `taa`: resolve in screen space after the remap with these settings; `blur`: where the
    /// foveated blur runs (the grid only where `GridBlurPass::supports` the space's grid).
    pub fn new(
        ctx: &Arc<Context>,
        space: &dyn SamplingSpace,
        taa: Option<TaaSettings>,
        blur: BlurSpace,
    ) -> Result<RemapWayBack> {
        let (grid, screen) = (space.grid_size(), space.screen_size());
        let grid_blur_fits = space.visual_polar().is_some_and(GridBlurPass::supports);
        let grid_blur = match (blur, taa) {
            (BlurSpace::Grid, None) if grid_blur_fits => Some(GridBlur::new(ctx, grid)?),
            _ => None,
        };
        Ok(RemapWayBack {
            grid_blur,
            mip_phi: MipPhiPass::new(ctx)?,
            remap: RemapPass::new(ctx)?,
            blur: FoveatedBlur::new(ctx, screen)?,
            mips: PhiMips::new(ctx, grid)?,
            remapped: Image::new(
                ctx,
                "screen.remapped",
                screen.x,
                screen.y,
                vk::Format::R32G32B32A32_SFLOAT,
            )?,
            taa: taa.map(|t| ScreenTaa::new(ctx, screen, t)).transpose()?,
        })
    }
}

impl WayBackPasses for RemapWayBack {
    /// Mips, remap, the screen-space TAA (when this was made with one and the frame is jittered)
    /// and the blur around the space's blur axis (none without one, or at σ 0), left pending
    /// for the frame to record (`ScreenOut::Unblurred`).
    fn record<'a>(
        &'a mut self,
        rec: &mut FrameRecorder,
        frame: &WayBackFrame<'a>,
    ) -> Result<ScreenOut<'a>> {
        let (params, columns, blur) = (&frame.grid.current, frame.grid.sampling_table, frame.blur);
        let axis = frame.space.blur_axis().filter(|_| blur.sigma_at_30 > 0.0);
        let vp_color = match (&self.grid_blur, axis) {
            (Some(g), Some(axis)) => g.record(rec, params, &blur.shape(axis), frame.radiance)?,
            _ => frame.radiance,
        };
        self.mip_phi
            .record(rec, params, columns, vp_color, &self.mips)?;
        // Samples jittered for the screen-space TAA are read where they were traced.
        let sample_offset = match (&self.taa, frame.jitter) {
            (Some(_), Some(jitter)) => jitter - Vec2::splat(0.5),
            _ => Vec2::ZERO,
        };
        self.remap.record(
            rec,
            params,
            columns,
            &self.mips,
            &self.remapped,
            sample_offset,
        )?;
        let resolved = match (&mut self.taa, frame.jitter) {
            (Some(resolver), Some(_)) => resolver.record(rec, &self.remapped, &frame.grid)?,
            _ => &self.remapped,
        };
        Ok(match axis {
            Some(_) if self.grid_blur.is_some() => ScreenOut::Radiance(resolved),
            Some(axis) => match self.blur.pending(blur, axis, resolved) {
                Some(pending) => ScreenOut::Unblurred(pending),
                None => ScreenOut::Radiance(resolved),
            },
            None => ScreenOut::Radiance(resolved),
        })
    }

    fn taa_history_bytes(&self) -> u64 {
        self.taa.as_ref().map_or(0, ScreenTaa::history_bytes)
    }
}
