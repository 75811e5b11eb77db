//! `fixed-foveation`: Visual-Polar held on the lens centre whatever the eye does — the fixed
//! foveated rendering a headset ships without eye tracking (and what the invalid-gaze policy falls
//! back to when tracking is lost). As a method it measures what eye tracking buys: the same
//! samples, filters and way back as `vp`, but the fovea stays where the lens axis meets the
//! screen, so quality per ring around the real gaze drops as the eye looks away. Every kernel is
//! Visual-Polar's (its parameters are a VP space centred on the lens); only `gaze()` follows the
//! eye, for the reports and the rings.

use super::{FovTangents, SamplingSpace, SpaceCapabilities, VisualPolar, VisualPolarParams};
use crate::error::{Error, Result};
use crate::layouts::SamplingParams;
use glam::{UVec2, Vec2};

#[derive(Clone, Copy, Debug)]
pub struct FixedFoveation {
    /// Centred on the lens for good.
    vp: VisualPolar,
    /// Where the eye looks this frame (recorded; sampling ignores it).
    gaze: Vec2,
}

impl FixedFoveation {
    pub fn new(
        screen: UVec2,
        lens_centre: Vec2,
        params: VisualPolarParams,
    ) -> Result<FixedFoveation> {
        let vp = VisualPolar::new(screen, lens_centre, params)?;
        Ok(FixedFoveation {
            vp,
            gaze: lens_centre,
        })
    }

    /// Where the eye's optical axis (view direction, tangent 0) meets its screen: the screen
    /// centre for a symmetric FOV, towards the wider side otherwise. Kept on the screen, for an
    /// FOV that does not contain its own axis.
    pub fn lens_centre(screen: UVec2, fov: FovTangents) -> Vec2 {
        let s = screen.as_vec2();
        let fraction = Vec2::new(
            fov.left / (fov.left + fov.right),
            fov.up / (fov.up + fov.down),
        );
        let fraction = if fraction.is_finite() {
            fraction
        } else {
            Vec2::splat(0.5)
        };
        (fraction * s).clamp(Vec2::ZERO, s)
    }

    /// The Visual-Polar space the kernels run (centred on the lens).
    pub fn visual_polar_space(&self) -> &VisualPolar {
        &self.vp
    }
}

impl SamplingSpace for FixedFoveation {
    fn name(&self) -> &'static str {
        "fixed-foveation"
    }
    fn shader_variant(&self) -> &'static str {
        self.vp.shader_variant()
    }
    fn trace_variant(&self) -> &'static str {
        self.vp.trace_variant()
    }
    fn grid_size(&self) -> UVec2 {
        self.vp.grid_size()
    }
    fn screen_size(&self) -> UVec2 {
        self.vp.screen()
    }
    fn sample_count(&self) -> u64 {
        self.vp.sample_count()
    }
    fn params(&self) -> SamplingParams {
        self.vp.sampling_params()
    }
    fn write_sampling_table(&self, out: &mut Vec<[f32; 4]>) {
        self.vp.write_sampling_table(out);
    }
    fn grid_to_screen(&self, grid: Vec2) -> Option<Vec2> {
        self.vp.grid_to_screen(grid)
    }
    fn screen_to_grid(&self, screen: Vec2) -> Option<Vec2> {
        self.vp.screen_to_grid(screen)
    }
    fn gaze(&self) -> Vec2 {
        self.gaze
    }
    /// Records the gaze; the samples stay on the lens.
    fn set_gaze(&mut self, gaze: Vec2) -> Result<()> {
        if !gaze.is_finite() {
            return Err(Error::Invalid(format!(
                "fixed foveation: gaze must be finite, got ({}, {})",
                gaze.x, gaze.y
            )));
        }
        self.gaze = gaze;
        Ok(())
    }
    /// The lens-centred VP space: the renderer maps it back and blurs around the lens.
    fn visual_polar(&self) -> Option<&VisualPolar> {
        Some(&self.vp)
    }
    fn blur_axis(&self) -> Option<&VisualPolar> {
        Some(&self.vp)
    }
    fn capabilities(&self) -> SpaceCapabilities {
        self.vp.capabilities()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_stay_on_the_lens_while_the_gaze_moves() {
        let screen = UVec2::new(320, 360);
        let fov = FovTangents::from_angles_deg(-45.0, 45.0, -48.4, 48.4);
        let centre = FixedFoveation::lens_centre(screen, fov);
        assert!(
            (centre - Vec2::new(160.0, 180.0)).length() < 1e-3,
            "{centre}"
        );
        let mut s = FixedFoveation::new(screen, centre, VisualPolarParams::default()).unwrap();
        let before = (
            s.params(),
            s.sample_count(),
            s.grid_to_screen(Vec2::new(3.5, 7.5)),
        );
        s.set_gaze(Vec2::new(20.0, 30.0)).unwrap();
        assert_eq!(s.gaze(), Vec2::new(20.0, 30.0));
        assert_eq!(
            (
                s.params(),
                s.sample_count(),
                s.grid_to_screen(Vec2::new(3.5, 7.5))
            ),
            before
        );
        assert_eq!(s.visual_polar().unwrap().gaze(), centre);
        assert!(s.set_gaze(Vec2::new(f32::NAN, 0.0)).is_err());
    }

    #[test]
    fn the_lens_centre_follows_an_asymmetric_fov() {
        let screen = UVec2::new(1000, 800);
        // 30° to the nose, 60° to the temple; 45° up and down.
        let c = FixedFoveation::lens_centre(
            screen,
            FovTangents::from_angles_deg(-30.0, 60.0, -45.0, 45.0),
        );
        let expected = 1000.0 * 30f32.to_radians().tan()
            / (30f32.to_radians().tan() + 60f32.to_radians().tan());
        assert!(
            (c.x - expected).abs() < 1e-2 && (c.y - 400.0).abs() < 1e-3,
            "{c}"
        );
        // An FOV that does not contain its axis keeps the centre on the screen.
        let off = FixedFoveation::lens_centre(
            screen,
            FovTangents::from_angles_deg(10.0, 60.0, -45.0, 45.0),
        );
        assert!(off.x >= 0.0 && off.x <= 1000.0, "{off}");
    }
}
