//! Composite foveation (Andersson & Hansson 2020, comparators.md §E) as a radial law of the polar
//! space: a log-polar buffer with L from the screen diagonal whose columns inside the gaze disc
//! (r < r_G = d·tan a_G) are dropped — the paper's u_C = u + u_G, w_C = w + u_G — and a gaze
//! buffer tracing that disc at one sample per pixel. Here the gaze buffer is the polar space's
//! own fovea (r linear in u with Visual-Polar's triangular clip, rows ∝ column: uniform density)
//! rather than a separate Cartesian buffer, so the φ-mips, the remap and every denoiser's grid
//! addressing serve it unchanged. Buffer aspect as theirs: h = round(√(W·H / aspect) / σ),
//! w = round(h · aspect); the fovea adds round(2π r_G² / h) columns (its triangle's texels ≈ the
//! disc's pixels). Where the law starts past the disc: t = g + (u − u_f)/(1 − u_f)·(1 − g) with
//! g = the log-polar column of r_G. A mode with a_G = 0 is plain log-polar with their σ, α and
//! aspect. GLSL: the log-polar branch of `vp_r_of_u` / `vp_u_of_r` (visual_polar_math.glsl).

use super::log_polar::{LogPolarLaw, ALPHA_RANGE, SIGMA_RANGE};

/// The log-polar buffer's width / height: their modes use 0.33–1.2.
const ASPECT_RANGE: (f32, f32) = (0.05, 20.0);
use crate::error::{Error, Result};
use glam::{UVec2, Vec2};

/// Andersson & Hansson's four tuned modes (default: Composite, the one they recommend).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum CompositeMode {
    Fov,
    Kernel,
    #[default]
    Composite,
    CompositeKernel,
}

impl CompositeMode {
    pub const NAMES: &'static [&'static str] = &["fov", "kernel", "composite", "composite-kernel"];

    pub fn parse(name: &str) -> Option<CompositeMode> {
        Some(match name {
            "fov" => CompositeMode::Fov,
            "kernel" => CompositeMode::Kernel,
            "composite" => CompositeMode::Composite,
            "composite-kernel" => CompositeMode::CompositeKernel,
            _ => return None,
        })
    }

    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// The mode's (σ, α, a_G in radians, aspect) from their paper, at viewing distance `d` px.
    pub fn params(self, viewing_distance_px: f32) -> CompositeParams {
        let (sigma, alpha, gaze_angle, aspect) = match self {
            CompositeMode::Fov => (0.75, 1.0, 0.0, 1.2),
            CompositeMode::Kernel => (1.0, 3.0, 0.0, 0.70),
            CompositeMode::Composite => (1.4, 1.0, 0.20, 0.33),
            CompositeMode::CompositeKernel => (1.3, 2.0, 0.15, 0.35),
        };
        CompositeParams {
            mode: self,
            sigma,
            alpha,
            gaze_angle,
            aspect,
            viewing_distance_px,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompositeParams {
    pub mode: CompositeMode,
    pub sigma: f32,
    pub alpha: f32,
    /// The gaze disc's half-angle a_G (radians; 0: no gaze buffer).
    pub gaze_angle: f32,
    /// The log-polar buffer's width / height.
    pub aspect: f32,
    /// The eye's distance to the image in pixels (a headset eye: width / (tan right − tan left)).
    pub viewing_distance_px: f32,
}

/// What the law makes of a screen: the grid, the law with its inner column, the fovea's width
/// in u and its radius.
pub struct CompositeLayout {
    pub grid: UVec2,
    pub law: LogPolarLaw,
    pub u_f: f32,
    pub r_f: f32,
}

impl CompositeParams {
    pub fn validate(&self) -> Result<()> {
        // σ and α within log-polar's own ranges.
        let within = |v: f32, (lo, hi): (f32, f32)| v >= lo && v <= hi;
        let ok = within(self.sigma, SIGMA_RANGE)
            && within(self.alpha, ALPHA_RANGE)
            && within(self.aspect, ASPECT_RANGE);
        if !(ok
            && (0.0..1.2).contains(&self.gaze_angle)
            && self.viewing_distance_px.is_finite()
            && self.viewing_distance_px > 0.0)
        {
            let ((s0, s1), (a0, a1), (p0, p1)) = (SIGMA_RANGE, ALPHA_RANGE, ASPECT_RANGE);
            return Err(Error::Invalid(format!(
                "composite: σ in [{s0}, {s1}], α in [{a0}, {a1}], aspect in [{p0}, {p1}], a_G in [0, 1.2) rad and a positive viewing distance, got {self:?}"
            )));
        }
        Ok(())
    }

    pub fn gaze_radius_px(&self) -> f32 {
        self.viewing_distance_px * self.gaze_angle.tan()
    }

    pub fn layout(&self, screen: UVec2) -> Result<CompositeLayout> {
        let (w_px, h_px) = (screen.x as f32, screen.y as f32);
        let rows = ((w_px * h_px / self.aspect).sqrt() / self.sigma)
            .round()
            .max(2.0);
        let columns = (rows * self.aspect).round().max(2.0);
        let mut law = LogPolarLaw::new(Vec2::new(w_px, h_px).length(), self.alpha)?;
        let r_g = self.gaze_radius_px();
        if r_g < 1.0 {
            return Ok(CompositeLayout {
                grid: UVec2::new(columns as u32, rows as u32),
                law,
                u_f: 0.0,
                r_f: 0.0,
            });
        }
        let fovea_columns = (std::f32::consts::TAU * r_g * r_g / rows).round().max(1.0);
        law.inner = law.u_of_r(r_g);
        if law.inner >= 1.0 {
            return Err(Error::Invalid(format!(
                "composite: the gaze disc (r_G = {r_g:.0} px) covers the whole {}×{} screen",
                screen.x, screen.y
            )));
        }
        let width = columns + fovea_columns;
        Ok(CompositeLayout {
            grid: UVec2::new(width as u32, rows as u32),
            law,
            u_f: fovea_columns / width,
            r_f: r_g,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{RadialLaw, SamplingSpace, VisualPolar, VisualPolarParams};

    fn space(mode: CompositeMode, screen: UVec2) -> VisualPolar {
        let radial = RadialLaw::Composite(mode.params(screen.x as f32 / 2.0));
        VisualPolar::new(
            screen,
            screen.as_vec2() * 0.5,
            VisualPolarParams {
                radial,
                ..Default::default()
            },
        )
        .unwrap()
    }

    /// Rays traced on the screen per screen pixel, texel centres, gaze centred, a 90° eye: within
    /// 0.06 of Andersson & Hansson's reported shares (154 %, 65.7 %, 37.5 %, 37.7 %).
    #[test]
    fn the_modes_trace_the_shares_their_paper_reports() {
        let screen = UVec2::new(320, 360);
        for (mode, paper) in [
            (CompositeMode::Fov, 1.54),
            (CompositeMode::Kernel, 0.657),
            (CompositeMode::Composite, 0.375),
            (CompositeMode::CompositeKernel, 0.377),
        ] {
            let vp = space(mode, screen);
            let g = vp.grid_size();
            let on_screen = (0..g.y)
                .flat_map(|y| (0..g.x).map(move |x| Vec2::new(x as f32, y as f32) + 0.5))
                .filter_map(|t| vp.grid_to_screen(t))
                .filter(|p| p.cmpge(Vec2::ZERO).all() && p.cmplt(screen.as_vec2()).all())
                .count();
            let share = on_screen as f64 / (screen.x * screen.y) as f64;
            assert!(
                (share - paper).abs() < 0.06,
                "{}: {share:.3} on screen vs the paper's {paper}",
                mode.name()
            );
        }
    }

    /// The gaze disc holds about one sample per pixel and the law continues at its edge.
    #[test]
    fn the_gaze_disc_is_one_sample_per_pixel_and_continuous() {
        let screen = UVec2::new(640, 720);
        let vp = space(CompositeMode::Composite, screen);
        let r_g = CompositeMode::Composite.params(320.0).gaze_radius_px();
        let fovea_columns = (vp.u_fovea() * vp.grid_size().x as f32).round() as u32;
        let fovea_samples: u64 = (0..fovea_columns)
            .map(|c| vp.rows_in_column(c) as u64)
            .sum();
        let disc = std::f64::consts::PI * (r_g as f64).powi(2);
        assert!(
            (fovea_samples as f64 / disc - 1.0).abs() < 0.03,
            "{fovea_samples} samples in a disc of {disc:.0} px"
        );
        let u_f = vp.u_fovea();
        assert!(
            (vp.r_of_u(u_f) - r_g).abs() < 1e-2 && (vp.r_of_u(u_f - 1e-4) - r_g).abs() < 0.1,
            "{} vs {r_g}",
            vp.r_of_u(u_f)
        );
        assert!(
            (vp.u_of_r(r_g) - u_f).abs() < 1e-5
                && (vp.u_of_r(3.0 * r_g) - vp.u_of_r(2.0 * r_g)) > 0.0
        );
        // The plain modes have no disc.
        assert_eq!(space(CompositeMode::Kernel, screen).u_fovea(), 0.0);
    }
}
