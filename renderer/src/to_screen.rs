//! Back to the screen from a Visual-Polar grid (visual-polar.md §6–7): φ-only mips → remap by
//! backward mapping → (screen-space TAA, optional) → foveated blur. Owns the passes and their
//! screen-sized images.

use crate::error::Result;
use crate::graph::FrameRecorder;
use crate::passes::blur::{BlurPass, BlurShape, BlurTarget};
use crate::passes::blur_grid::GridBlurPass;
use crate::passes::denoise::taa::TaaSettings;
use crate::passes::denoise::taa_screen::{ScreenTaa, ScreenTaaFrame};
use crate::passes::mip_phi::{MipPhiPass, PhiMips};
use crate::passes::remap::RemapPass;
use crate::passes::tonemap::ToneTarget;
use crate::sampling::VisualPolar;
use crate::vk::{Buffer, Context, Image};
use ash::vk;
use glam::{UVec2, Vec2};
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
    /// In the Visual-Polar grid before the remap, along φ and ρ (`passes::blur_grid`): no
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

/// What a way back leaves: radiance on the screen to tone-map, or the display image already
/// written (the blur's last axis wrote it).
pub enum ScreenOut<'a> {
    Radiance(&'a Image),
    Shown,
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

    /// As `record`, but with a `display` target the last axis writes the display image itself
    /// (σ 0: `src` is left to tone-map as before).
    pub fn record_to<'a>(
        &'a self,
        rec: &mut FrameRecorder,
        settings: &BlurSettings,
        axis: &VisualPolar,
        src: &'a Image,
        display: Option<ToneTarget>,
    ) -> Result<ScreenOut<'a>> {
        match display {
            Some(target) if settings.sigma_at_30 > 0.0 => {
                self.pass.record(
                    rec,
                    &settings.shape(axis),
                    src,
                    &self.scratch,
                    BlurTarget::Display(target),
                )?;
                Ok(ScreenOut::Shown)
            }
            _ => self
                .record(rec, settings, axis, src)
                .map(ScreenOut::Radiance),
        }
    }
}

/// The grid blur's pass and its two grid-sized images.
struct GridBlur {
    pass: GridBlurPass,
    scratch: Image,
    blurred: Image,
}

pub struct ToScreen {
    mip_phi: MipPhiPass,
    remap: RemapPass,
    pub mips: PhiMips,
    /// Remapped linear radiance (before the blur).
    pub remapped: Image,
    blur: FoveatedBlur,
    /// TAA between the remap and the blur (`--taa screen`).
    pub taa: Option<ScreenTaa>,
    /// Built for `BlurSpace::Grid` (and no screen-space TAA).
    grid_blur: Option<GridBlur>,
}

impl ToScreen {
    /// `taa`: resolve in screen space after the remap with these settings; `blur`: where the
    /// foveated blur runs (the grid only without screen-space TAA; the caller asks for the grid
    /// only for a space `GridBlurPass::supports`).
    pub fn new(
        ctx: &Arc<Context>,
        grid: UVec2,
        screen: UVec2,
        taa: Option<TaaSettings>,
        blur: BlurSpace,
    ) -> Result<ToScreen> {
        let image = |name: &str| {
            Image::new(
                ctx,
                name,
                screen.x,
                screen.y,
                vk::Format::R32G32B32A32_SFLOAT,
            )
        };
        let grid_image =
            |name: &str| Image::new(ctx, name, grid.x, grid.y, vk::Format::R32G32B32A32_SFLOAT);
        let grid_blur = match (blur, taa) {
            (BlurSpace::Grid, None) => Some(GridBlur {
                pass: GridBlurPass::new(ctx)?,
                scratch: grid_image("grid.blur_scratch")?,
                blurred: grid_image("grid.blurred")?,
            }),
            _ => None,
        };
        Ok(ToScreen {
            grid_blur,
            mip_phi: MipPhiPass::new(ctx)?,
            remap: RemapPass::new(ctx)?,
            blur: FoveatedBlur::new(ctx, screen)?,
            mips: PhiMips::new(ctx, grid)?,
            remapped: image("screen.remapped")?,
            taa: taa.map(|t| ScreenTaa::new(ctx, screen, t)).transpose()?,
        })
    }

    /// Records mips, remap, the screen-space TAA (when this was built with one; `taa` then
    /// carries the frame's jitter and G-buffer) and (unless σ is 0) the blur; returns the screen
    /// radiance to show, or, given a `display` target, writes it there from the blur's last axis.
    /// `columns` is a texel buffer holding `vp.column_table()` (the renderer's `sampling_table`).
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &mut self,
        rec: &mut FrameRecorder,
        vp: &VisualPolar,
        columns: &Buffer,
        vp_color: &Image,
        blur: &BlurSettings,
        taa: Option<&ScreenTaaFrame>,
        display: Option<ToneTarget>,
    ) -> Result<ScreenOut<'_>> {
        let params = vp.sampling_params();
        // The blur in the grid where this was built for it (the view checked once that its
        // space can take it); then the remap's output is the picture.
        let grid_blur = self.grid_blur.as_ref().filter(|_| blur.sigma_at_30 > 0.0);
        let vp_color = match grid_blur {
            Some(g) => {
                g.pass.record(
                    rec,
                    &params,
                    &blur.shape(vp),
                    vp_color,
                    &g.scratch,
                    &g.blurred,
                )?;
                &g.blurred
            }
            None => vp_color,
        };
        self.mip_phi
            .record(rec, &params, columns, vp_color, &self.mips)?;
        // Samples jittered for the screen-space TAA are read where they were traced.
        let sample_offset = match (&self.taa, taa) {
            (Some(_), Some(frame)) => frame.jitter - Vec2::splat(0.5),
            _ => Vec2::ZERO,
        };
        self.remap.record(
            rec,
            &params,
            columns,
            &self.mips,
            &self.remapped,
            sample_offset,
        )?;
        let resolved = match (&mut self.taa, taa) {
            (Some(resolver), Some(frame)) => resolver.record(rec, &self.remapped, frame)?,
            _ => &self.remapped,
        };
        if grid_blur.is_some() {
            return Ok(ScreenOut::Radiance(resolved));
        }
        self.blur.record_to(rec, blur, vp, resolved, display)
    }
}
