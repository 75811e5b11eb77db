//! `random-acuity` (Koskela et al. 2018, comparators.md): Visual-Polar's texels and sample count,
//! but each texel's sample lies at a position drawn afresh every frame, uniformly over the grid's
//! kept texels (clipped draws rejected, at most `RANDOM_ACUITY_TRIES`) and mapped by
//! Visual-Polar's mapping: the same acuity density, with neighbouring lanes tracing unrelated
//! rays — the comparator for the coherence Visual-Polar's grid buys. Way back: each sample
//! splatted to its pixel, push-pull filled, the same foveated blur. Paper layout only (the draw
//! is over the grid, not the screen). GLSL: sampling/random_acuity.glsl.

use super::random::unit_hash;
use super::{SamplingSpace, SpaceCapabilities, VisualPolar, VisualPolarParams, VpLayout, WayBack};
use crate::error::{Error, Result};
use crate::layouts::{SamplingParams, RANDOM_ACUITY_TRIES, SPARSE_SALT_POSITION};
use glam::{IVec2, UVec2, Vec2};

#[derive(Clone, Copy, Debug)]
pub struct RandomAcuity {
    vp: VisualPolar,
}

impl RandomAcuity {
    pub fn new(screen: UVec2, gaze: Vec2, params: VisualPolarParams) -> Result<RandomAcuity> {
        if params.layout != VpLayout::Paper {
            return Err(Error::Invalid("random acuity: draws over the paper's Visual-Polar layout only (layout = \"paper\")".into()));
        }
        let vp = VisualPolar::new(screen, gaze, params)?;
        if vp.log_polar().is_some() {
            return Err(Error::Invalid(
                "random acuity: draws from the acuity density, not the log-polar law".into(),
            ));
        }
        Ok(RandomAcuity { vp })
    }

    /// The Visual-Polar space whose density the draws follow.
    pub fn visual_polar_space(&self) -> &VisualPolar {
        &self.vp
    }

    /// Where `texel`'s sample lies in the grid this frame (`frame`, `seed` as in FrameData.frame):
    /// the GPU's draw (`random_acuity_grid_position`).
    pub fn grid_position(&self, texel: UVec2, frame: u32, seed: u32) -> Option<Vec2> {
        if !self.vp.is_valid_texel(texel.as_ivec2()) {
            return None;
        }
        let size = self.vp.grid_size().as_vec2();
        let last = self.vp.grid_size().as_ivec2() - 1;
        (0..RANDOM_ACUITY_TRIES).find_map(|k| {
            let salt = SPARSE_SALT_POSITION.wrapping_add(2 * k);
            let draw = Vec2::new(
                unit_hash(texel.to_array(), frame, seed, salt),
                unit_hash(texel.to_array(), frame, seed, salt + 1),
            ) * size;
            let t: IVec2 = draw.floor().as_ivec2().min(last);
            self.vp.is_valid_texel(t).then_some(draw)
        })
    }

    /// Screen position of `texel`'s sample this frame (may lie off the screen, as VP's do).
    pub fn screen_position(&self, texel: UVec2, frame: u32, seed: u32) -> Option<Vec2> {
        self.grid_position(texel, frame, seed)
            .map(|g| self.vp.paper_vp_to_screen(g))
    }

    /// The samples one frame traces (every kept texel whose draw succeeded).
    pub fn traced_count(&self, frame: u32, seed: u32) -> u64 {
        let g = self.vp.grid_size();
        (0..g.y)
            .flat_map(|y| (0..g.x).map(move |x| UVec2::new(x, y)))
            .filter(|&t| self.grid_position(t, frame, seed).is_some())
            .count() as u64
    }
}

impl SamplingSpace for RandomAcuity {
    fn name(&self) -> &'static str {
        "random-acuity"
    }
    fn shader_variant(&self) -> &'static str {
        "random_acuity"
    }
    /// As Visual-Polar's: specialised for the normalised axis unless the headset's is used, and
    /// for the quartic inverse CDF unless the exact one is.
    fn trace_variant(&self) -> &'static str {
        match (self.vp.headset(), self.vp.exact_inverse_cdf()) {
            (None, false) => "random_acuity_polynomial",
            (None, true) => "random_acuity",
            (Some(_), _) => "random_acuity_headset",
        }
    }
    fn grid_size(&self) -> UVec2 {
        self.vp.grid_size()
    }
    fn screen_size(&self) -> UVec2 {
        self.vp.screen()
    }
    /// Visual-Polar's count: the texels that draw (a draw fails about once in 10⁷ texels).
    fn sample_count(&self) -> u64 {
        self.vp.sample_count()
    }
    /// Visual-Polar's parameters: the draw maps through its mapping.
    fn params(&self) -> SamplingParams {
        self.vp.sampling_params()
    }
    fn write_sampling_table(&self, out: &mut Vec<[f32; 4]>) {
        self.vp.write_sampling_table(out);
    }
    /// Where a draw at `grid` lands: Visual-Polar's mapping (the texels themselves have no fixed
    /// place on the screen).
    fn grid_to_screen(&self, grid: Vec2) -> Option<Vec2> {
        self.vp.grid_to_screen(grid)
    }
    fn screen_to_grid(&self, screen: Vec2) -> Option<Vec2> {
        self.vp.screen_to_grid(screen)
    }
    fn gaze(&self) -> Vec2 {
        self.vp.gaze()
    }
    fn set_gaze(&mut self, gaze: Vec2) -> Result<()> {
        self.vp = VisualPolar::new(self.vp.screen(), gaze, *self.vp.params())?;
        Ok(())
    }
    fn blur_axis(&self) -> Option<&VisualPolar> {
        Some(&self.vp)
    }
    fn capabilities(&self) -> SpaceCapabilities {
        SpaceCapabilities {
            way_back: WayBack::Splat,
            temporal_filters: false,
            filters_note: "(its samples move to new positions every frame)",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_land_in_kept_texels_and_change_every_frame() {
        let screen = UVec2::new(320, 360);
        let s = RandomAcuity::new(screen, screen.as_vec2() * 0.5, VisualPolarParams::default())
            .unwrap();
        let vp = s.visual_polar_space();
        let mut moved = 0;
        let g = vp.grid_size();
        for y in 0..g.y {
            for x in 0..g.x {
                let t = UVec2::new(x, y);
                let a = s.grid_position(t, 3, 1);
                assert_eq!(a.is_some(), vp.is_valid_texel(t.as_ivec2()), "{t}");
                if let Some(a) = a {
                    assert!(vp.is_valid_texel(a.floor().as_ivec2()), "{a}");
                    moved += (s.grid_position(t, 4, 1) != Some(a)) as u32;
                }
            }
        }
        assert_eq!(s.traced_count(3, 1), s.sample_count());
        assert!(moved as u64 == s.sample_count(), "{moved}");
        assert!(RandomAcuity::new(
            screen,
            Vec2::ZERO,
            VisualPolarParams {
                layout: VpLayout::ScreenClipped,
                ..Default::default()
            }
        )
        .is_err());
    }
}
