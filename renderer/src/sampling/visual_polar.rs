//! Visual-Polar space (Koskela et al., EGSR 2019): the pure mapping math, no Vulkan.
//! See `shared/design/visual-polar.md`. `shaders/sampling/visual_polar_math.glsl` mirrors every
//! function here line for line (same constants, same f32 order of operations) so that a device test
//! can compare them; change both together.
//!
//! Grid: x (columns) = ρ, normalised u = x / width; y (rows) = φ ∈ [0, 2π), measured from +x toward
//! +y in pixels (y down). Fovea u < u_f: r linear in u. Periphery: u maps linearly onto the acuity
//! CDF fraction p ∈ [p_f, 1], e(p) through the inverse CDF, r = e / e_norm · r_max.
//!
//! Discrete clip layout (the triangular φ clip): a fovea column `c` (centre u_c = (c + ½)/width <
//! u_f) keeps `n(c) = clamp(floor(height · u_c/u_f + ½), 1, height)` rows, the first n(c) rows
//! (rows n(c).. of that column are clipped, i.e. the triangle is cut from the top-left corner).
//! Its rows still span the whole circle: row y of column c sits at φ = 2π · y / n(c). Since n ∝ r
//! the fovea has uniform areal density. Continuous grid coordinates use the same per-column step
//! (φ = 2π·y/n(floor x)), so forward and inverse are exact inverses and a jittered texel stays in its
//! column. Removed area ≈ u_f/2 of the grid, so u_f = 2 · clip_fraction.
//!
//! That is the paper's layout (`VpLayout::Paper`, this type's default; `fovea`'s render profile
//! defaults to the screen-clipped one). `VpLayout::ScreenClipped` keeps
//! the grid and the row counts but lays each column's rows on the on-screen part of its circle
//! only: `visual_polar_clipped.rs`. `VpLayout::ScreenAware` adds a ρ axis placed by the on-screen
//! acuity mass: `visual_polar_screen_axis.rs`.
//!
//! The ρ axis is the paper's normalised eccentricity by default (`Eccentricity::Normalized`).
//! `Eccentricity::Headset` makes it the true eccentricity in degrees through the eye's FOV
//! (`visual_polar_headset.rs`): the "radius" r of the formulas above becomes e itself (r_max =
//! e_norm = 1, r_f = fovea°), the CDF runs over [0, e_max] (e_max = the largest true eccentricity
//! of a screen corner for this gaze) and always uses the exact inverse (the quartic is a fit for
//! [0, 80]); φ stays the angle in pixels, so the rows, the clip and the φ mips are unchanged.
//!
//! The radial law r(u) is a parameter (`RadialLaw`): the paper's acuity law above, or Meng's
//! kernel log-polar law (`log_polar.rs`: no clip, grid = screen / σ, r_max = the law's extent).
//! Everything else — rows, φ wrap, arcs, mips, remap, the denoisers' grid addressing — is shared.

use super::acuity::*;
use super::composite::CompositeParams;
use super::log_polar::{LogPolarLaw, LogPolarParams};
use super::visual_polar_clipped::{on_screen_arcs, ColumnArcs};
use super::visual_polar_headset::{FovTangents, HeadsetAxis};
use super::visual_polar_screen_axis::{ScreenAxis, AXIS_KNOT_TEXELS};
use crate::error::{Error, Result};
use crate::layouts::SamplingParams;
use glam::{IVec2, UVec2, UVec4, Vec2, Vec4};
use std::f32::consts::TAU;

/// Bracket top of the exact inverse with the headset axis (true degrees never exceed 180).
pub const E_TOP_HEADSET_DEG: f32 = 180.0;
/// Bits of the flag slot (`SamplingParams::shape1.y`).
const FLAG_EXACT: u32 = 1;
const FLAG_CLIPPED: u32 = 2;
const FLAG_HEADSET: u32 = 4;
const FLAG_LOG_POLAR: u32 = 8;
const FLAG_SCREEN_AXIS: u32 = 16;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InverseCdf {
    /// The paper's fitted quartic (Eq. 3): no log/division on the GPU. Only defined for k = 1;
    /// other density exponents fall back to `Exact`.
    Polynomial,
    /// Newton on the CDF (Eq. 2 for k = 1, its generalisation for other k).
    Exact,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RadiusMode {
    /// r_max = largest distance from the gaze to a screen corner (the paper's): the whole screen
    /// is covered, the sample count is gaze-independent and the fovea grows near edges.
    FarthestCorner,
    /// A fixed r_max in pixels (screen parts beyond it get u > 1: clamp-to-edge when addressing).
    Fixed(f32),
}

/// How a column's φ rows are laid on its circle around the gaze.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VpLayout {
    /// The paper's: every column's rows span the whole circle, on the screen or not (with the gaze
    /// near a corner ≈ 76 % of the samples land off the screen).
    Paper,
    /// Each column's rows span only the on-screen part of its circle (at the column's centre
    /// radius): same grid, same rows per column, the whole budget on the screen
    /// (`visual_polar_clipped.rs`).
    ScreenClipped,
    /// The screen-clipped rows with the periphery's columns placed by the acuity mass on the
    /// screen, so samples per pixel follow acuity everywhere on it
    /// (`visual_polar_screen_axis.rs`).
    ScreenAware,
}

impl VpLayout {
    /// Whether rows are laid on the on-screen arcs only (both screen layouts).
    pub fn clips(self) -> bool {
        self != VpLayout::Paper
    }
}

/// How a column's normalised position u maps to a distance from the gaze.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RadialLaw {
    /// The paper's: linear fovea, then the acuity CDF (Koskela 2019).
    Acuity,
    /// Meng et al. 2018's kernel log-polar law (`log_polar.rs`); `axis_scale`, `clip_fraction`,
    /// `radius_mode` and the inverse CDF do not apply (σ, the extent and α replace them).
    LogPolar(LogPolarParams),
    /// Andersson & Hansson 2020's composite foveation (`composite.rs`): the log-polar law from the
    /// screen diagonal past a gaze disc traced at one sample per pixel as the fovea.
    Composite(CompositeParams),
}

/// What the ρ axis measures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Eccentricity {
    /// The paper's: a screen distance normalised so that r_max ↦ 80.
    Normalized,
    /// True degrees from the gaze direction through this eye's FOV (`visual_polar_headset.rs`).
    Headset(FovTangents),
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VisualPolarParams {
    /// Per-axis grid scale relative to the screen (2/3: 853×960 for 1280×1440).
    pub axis_scale: f32,
    /// Share of the grid removed by the fovea's triangular φ clip (0 < c < 0.5).
    pub clip_fraction: f32,
    /// Fovea radius as normalised eccentricity (80 ↦ r_max).
    pub fovea_deg: f32,
    /// Areal sample density ∝ V(e)^k (k = 1 is the paper's).
    pub density_exponent: f32,
    pub inverse_cdf: InverseCdf,
    pub radius_mode: RadiusMode,
    pub layout: VpLayout,
    pub eccentricity: Eccentricity,
    pub radial: RadialLaw,
}

impl Default for VisualPolarParams {
    fn default() -> Self {
        Self {
            axis_scale: 2.0 / 3.0,
            clip_fraction: 0.12,
            fovea_deg: ACUITY_KNEE_DEG,
            density_exponent: 1.0,
            inverse_cdf: InverseCdf::Polynomial,
            radius_mode: RadiusMode::FarthestCorner,
            layout: VpLayout::Paper,
            eccentricity: Eccentricity::Normalized,
            radial: RadialLaw::Acuity,
        }
    }
}

fn invalid(msg: String) -> Error {
    Error::Invalid(format!("visual-polar: {msg}"))
}

impl VisualPolarParams {
    /// Range checks of every parameter, each error naming the parameter.
    pub fn validate(&self) -> Result<()> {
        if !(self.axis_scale.is_finite() && self.axis_scale > 0.0 && self.axis_scale <= 4.0) {
            return Err(invalid(format!(
                "axis_scale must be in (0, 4], got {}",
                self.axis_scale
            )));
        }
        if !(self.clip_fraction > 0.0 && self.clip_fraction < 0.5) {
            return Err(invalid(format!(
                "clip_fraction must be in (0, 0.5) (the fovea spans u_f = 2·clip_fraction), got {}",
                self.clip_fraction
            )));
        }
        if !(self.fovea_deg > 0.0 && self.fovea_deg < E_MAX_DEG) {
            return Err(invalid(format!(
                "fovea_deg must be in (0, {E_MAX_DEG}), got {}",
                self.fovea_deg
            )));
        }
        if !(self.density_exponent >= 0.0 && self.density_exponent <= 4.0) {
            return Err(invalid(format!(
                "density_exponent must be in [0, 4], got {}",
                self.density_exponent
            )));
        }
        if let RadiusMode::Fixed(r) = self.radius_mode {
            if !(r.is_finite() && r > 0.0) {
                return Err(invalid(format!(
                    "radius_mode Fixed(r) needs a finite r > 0 pixels, got {r}"
                )));
            }
        }
        match self.radial {
            RadialLaw::Acuity => {}
            RadialLaw::LogPolar(lp) => lp.validate()?,
            RadialLaw::Composite(c) => c.validate()?,
        }
        if self.radial != RadialLaw::Acuity {
            // Meng's buffer spans full circles on the screen's own distances, its extent set by L.
            if self.layout != VpLayout::Paper
                || self.eccentricity != Eccentricity::Normalized
                || self.radius_mode != RadiusMode::FarthestCorner
            {
                return Err(invalid(
                    "the log-polar law takes the paper layout, the normalized axis and the corner radius (its extent is set by L)".to_string(),
                ));
            }
        }
        if let Eccentricity::Headset(fov) = self.eccentricity {
            fov.check().map_err(invalid)?;
            // The on-screen arcs are computed for circles; the headset's iso-eccentricity curves
            // are conics.
            if self.layout != VpLayout::Paper {
                return Err(invalid(
                    "eccentricity = headset supports only the paper layout (layout = paper)"
                        .to_string(),
                ));
            }
            if self.radius_mode != RadiusMode::FarthestCorner {
                return Err(invalid(
                    "eccentricity = headset ends the ρ axis at the farthest corner's true eccentricity: \
                     radius_mode must be the farthest corner"
                        .to_string(),
                ));
            }
        }
        Ok(())
    }

    /// The clip that makes the fovea hold exactly the fraction p_f of the samples, i.e. density
    /// ∝ V^k everywhere (≈ 0.088 for k = 1): fovea share (u_f/2)/(1 − u_f/2) = p_f.
    pub fn acuity_exact_clip_fraction(&self) -> f32 {
        let p_f = fovea_fraction(self.fovea_deg, self.density_exponent);
        p_f / (1.0 + p_f)
    }
}

/// One gaze's Visual-Polar space on one screen. All derived constants are precomputed here and
/// handed unchanged to the GPU (`sampling_params`), so both sides compute from the same numbers.
#[derive(Clone, Copy, Debug)]
pub struct VisualPolar {
    screen: UVec2,
    gaze: Vec2,
    params: VisualPolarParams,
    grid: UVec2,
    /// Fovea width in u (clip triangle width).
    u_f: f32,
    /// CDF fraction at the fovea edge.
    p_f: f32,
    r_max: f32,
    /// Fovea radius in pixels: e(p_f)/e_norm · r_max (continuous with the periphery).
    r_f: f32,
    /// e(1): e_poly(1) ≈ 79.97 for the polynomial, 80 for the exact inverse.
    e_norm: f32,
    cdf_max: f32,
    exact: bool,
    /// The tangent-space geometry with `Eccentricity::Headset` (then r_max = e_norm = 1 and r_f
    /// = fovea°: the "radius" axis is the true eccentricity).
    headset: Option<HeadsetAxis>,
    /// Largest gaze-to-corner distance in pixels (= r_max on the paper's axis).
    r_corner_px: f32,
    /// The log-polar law (`RadialLaw::LogPolar`), for this gaze.
    log_polar: Option<LogPolarLaw>,
    /// The periphery's ρ axis by on-screen acuity mass (`VpLayout::ScreenAware`), for this gaze.
    screen_axis: Option<ScreenAxis>,
}

impl VisualPolar {
    /// Checks the parameters (they come from the user: TOML and CLI) and precomputes the space.
    /// Errors name the offending parameter; nothing here panics.
    pub fn new(screen: UVec2, gaze: Vec2, params: VisualPolarParams) -> Result<Self> {
        params.validate()?;
        if screen.x == 0 || screen.y == 0 {
            return Err(invalid(format!(
                "screen size must be non-zero, got {}x{}",
                screen.x, screen.y
            )));
        }
        if !gaze.is_finite() {
            return Err(invalid(format!(
                "gaze must be finite, got ({}, {})",
                gaze.x, gaze.y
            )));
        }
        let composite = match params.radial {
            RadialLaw::Composite(c) => Some(c.layout(screen)?),
            _ => None,
        };
        let axis_scale = match params.radial {
            RadialLaw::Acuity | RadialLaw::Composite(_) => params.axis_scale,
            RadialLaw::LogPolar(lp) => 1.0 / lp.sigma,
        };
        let grid = match &composite {
            Some(c) => c.grid,
            None => (screen.as_vec2() * axis_scale)
                .round()
                .as_uvec2()
                .max(UVec2::ONE),
        };
        let k = params.density_exponent;
        let headset = match params.eccentricity {
            Eccentricity::Normalized => None,
            Eccentricity::Headset(fov) => Some(HeadsetAxis::new(fov, screen, gaze)),
        };
        // The quartic is a fit for k = 1 on [0, 80] only.
        let exact = params.inverse_cdf == InverseCdf::Exact || k != 1.0 || headset.is_some();
        let r_corner_px = {
            let far = gaze.max(screen.as_vec2() - gaze).abs();
            far.length()
        };
        let log_polar = match params.radial {
            RadialLaw::Acuity => None,
            RadialLaw::LogPolar(lp) => {
                Some(LogPolarLaw::new(lp.extent_px(screen, gaze), lp.alpha)?)
            }
            RadialLaw::Composite(_) => composite.as_ref().map(|c| c.law),
        };
        let (cdf_max, r_max, r_f, e_norm) = match headset {
            None => {
                let r_max = match (params.radius_mode, params.radial) {
                    (_, RadialLaw::LogPolar(lp)) => lp.extent_px(screen, gaze),
                    (_, RadialLaw::Composite(_)) => screen.as_vec2().length(),
                    (RadiusMode::FarthestCorner, _) => r_corner_px,
                    (RadiusMode::Fixed(r), _) => r,
                };
                let (e_f, e_norm) = if exact {
                    (params.fovea_deg, E_MAX_DEG)
                } else {
                    (
                        inverse_cdf_poly(fovea_fraction(params.fovea_deg, k)),
                        inverse_cdf_poly(1.0),
                    )
                };
                (cdf(E_MAX_DEG, k), r_max, e_f / e_norm * r_max, e_norm)
            }
            Some(axis) => (cdf(axis.e_max, k), 1.0, params.fovea_deg, 1.0),
        };
        let mut vp = Self {
            screen,
            gaze,
            params,
            grid,
            // Log-polar columns keep every row (u_f = 0: no clip); composite's gaze disc is the fovea.
            u_f: match (&composite, log_polar) {
                (Some(c), _) => c.u_f,
                (None, Some(_)) => 0.0,
                (None, None) => 2.0 * params.clip_fraction,
            },
            p_f: cdf(params.fovea_deg, k) / cdf_max,
            r_max,
            r_f: composite
                .as_ref()
                .filter(|c| c.u_f > 0.0)
                .map_or(r_f, |c| c.r_f),
            e_norm,
            cdf_max,
            exact,
            headset,
            r_corner_px,
            log_polar,
            screen_axis: None,
        };
        if params.layout == VpLayout::ScreenAware {
            // No mass beyond the fovea on the screen (a screen inside the fovea): the paper's axis.
            vp.screen_axis = ScreenAxis::new(
                gaze,
                screen,
                vp.r_f,
                vp.r_max,
                vp.e_norm / vp.r_max,
                params.density_exponent,
            );
        }
        if let Some(axis) = headset {
            if !axis.e_max.is_finite() || axis.e_max <= params.fovea_deg {
                return Err(invalid(format!(
                    "eccentricity = headset: the farthest screen corner is only {}° from the gaze, not beyond the \
                     fovea ({}°): check the FOV tangents and fovea_deg",
                    axis.e_max, params.fovea_deg
                )));
            }
        }
        // Guards against parameter combinations that pass the range checks but break the math
        // (e.g. an extreme density exponent overflowing the CDF).
        if !(vp.r_max > 0.0
            && vp.r_f.is_finite()
            && vp.r_f > 0.0
            && vp.cdf_max.is_finite()
            && vp.cdf_max > 0.0)
            || !(vp.p_f > 0.0 && vp.p_f < 1.0)
        {
            return Err(invalid(format!(
                "parameters give a degenerate space (r_max {}, fovea radius {} px, p_f {}, cdf_max {}): check \
                 density_exponent and fovea_deg",
                vp.r_max, vp.r_f, vp.p_f, vp.cdf_max
            )));
        }
        Ok(vp)
    }

    pub fn screen(&self) -> UVec2 {
        self.screen
    }
    pub fn gaze(&self) -> Vec2 {
        self.gaze
    }
    pub fn params(&self) -> &VisualPolarParams {
        &self.params
    }
    pub fn grid_size(&self) -> UVec2 {
        self.grid
    }
    /// Pixels the ρ axis ends at: r_max on the paper's axis; with the headset axis the largest
    /// gaze-to-corner distance (where that axis ends too, at e_max).
    pub fn r_max(&self) -> f32 {
        match self.headset {
            None => self.r_max,
            Some(_) => self.r_corner_px,
        }
    }
    /// Fovea radius on screen in pixels (headset axis: the mean over directions of the fovea's
    /// edge, which is not a circle there).
    pub fn r_fovea(&self) -> f32 {
        match &self.headset {
            None => self.r_f,
            Some(axis) => axis.mean_distance(self.params.fovea_deg),
        }
    }
    /// Where the foveated blur starts (pixels): the fovea's edge; with the log-polar law the
    /// outer half of the buffer (u ≥ ½, comparators.md §D: Meng blurs the outer half).
    pub fn blur_start(&self) -> f32 {
        match (self.params.radial, self.log_polar) {
            // Andersson & Hansson blur beyond a sixth of the diagonal.
            (RadialLaw::Composite(_), _) => self.screen.as_vec2().length() / 6.0,
            (_, Some(law)) => law.r_of_u(0.5),
            _ => self.r_fovea(),
        }
    }

    /// The log-polar law, with `RadialLaw::LogPolar`.
    pub fn log_polar(&self) -> Option<&LogPolarLaw> {
        self.log_polar.as_ref()
    }

    /// The screen-aware ρ axis, with `VpLayout::ScreenAware` (unless no acuity mass lies on the
    /// screen beyond the fovea).
    pub fn screen_axis(&self) -> Option<&ScreenAxis> {
        self.screen_axis.as_ref()
    }

    /// The tangent-space geometry, with `Eccentricity::Headset`.
    pub fn headset(&self) -> Option<&HeadsetAxis> {
        self.headset.as_ref()
    }
    /// Whether the radial axis runs through the exact inverse CDF (not the paper's quartic).
    pub fn exact_inverse_cdf(&self) -> bool {
        self.exact
    }
    /// True eccentricity (degrees) of a screen position, with `Eccentricity::Headset`.
    pub fn true_eccentricity(&self, s: Vec2) -> Option<f32> {
        self.headset.map(|axis| axis.eccentricity(s - self.gaze))
    }
    /// Width of the clip triangle in normalised u: clipped area u_f/2 = clip_fraction.
    pub fn u_fovea(&self) -> f32 {
        self.u_f
    }
    pub fn p_fovea(&self) -> f32 {
        self.p_f
    }

    /// Screen distance (pixels) of eccentricity `e`: the paper's normalised one (e_norm ↦
    /// r_max), or with the headset axis true degrees (mean distance over directions).
    pub fn radius_of_eccentricity(&self, e: f32) -> f32 {
        match &self.headset {
            None => e / self.e_norm * self.r_max,
            Some(axis) => axis.mean_distance(e),
        }
    }

    /// The paper's normalised eccentricity of a screen distance (pixels). The headset axis has
    /// no single answer (use `true_eccentricity`); it gets the paper's scale with r_max().
    pub fn eccentricity_of_radius(&self, r: f32) -> f32 {
        match self.headset {
            None => r / self.r_max * self.e_norm,
            Some(_) => r / self.r_corner_px * E_MAX_DEG,
        }
    }

    /// Rows of φ that column `col` keeps (the triangular clip; see the module docs).
    pub fn rows_in_column(&self, col: u32) -> u32 {
        let h = self.grid.y;
        let u_c = (col as f32 + 0.5) / self.grid.x as f32;
        if u_c >= self.u_f {
            return h;
        }
        ((h as f32 * u_c / self.u_f + 0.5).floor() as u32).clamp(1, h)
    }

    pub fn is_valid_texel(&self, t: IVec2) -> bool {
        t.x >= 0
            && t.y >= 0
            && (t.x as u32) < self.grid.x
            && (t.y as u32) < self.rows_in_column(t.x as u32)
    }

    /// Number of traced texels (all columns' kept rows).
    pub fn sample_count(&self) -> u64 {
        (0..self.grid.x)
            .map(|c| self.rows_in_column(c) as u64)
            .sum()
    }

    /// Normalised ρ coordinate → the axis value: screen distance (pixels) on the paper's axis,
    /// true eccentricity (degrees) on the headset's.
    pub fn r_of_u(&self, u: f32) -> f32 {
        if let Some(law) = &self.log_polar {
            if u < self.u_f {
                return u / self.u_f * self.r_f;
            }
            return law.r_of_u(law.inner + (u - self.u_f) / (1.0 - self.u_f) * (1.0 - law.inner));
        }
        if u < self.u_f {
            return u / self.u_f * self.r_f;
        }
        if let Some(axis) = &self.screen_axis {
            return axis.r_of_p((u - self.u_f) / (1.0 - self.u_f));
        }
        let e = if self.exact {
            // The tail fraction 1 − p straight from u (see `inverse_cdf_exact`).
            let q = (1.0 - u) / (1.0 - self.u_f) * (1.0 - self.p_f);
            let e_top = if self.headset.is_some() {
                E_TOP_HEADSET_DEG
            } else {
                E_MAX_DEG
            };
            inverse_cdf_exact(
                q,
                self.params.density_exponent,
                self.cdf_max,
                self.e_max(),
                e_top,
            )
        } else {
            inverse_cdf_poly(self.p_f + (u - self.u_f) / (1.0 - self.u_f) * (1.0 - self.p_f))
        };
        e / self.e_norm * self.r_max
    }

    /// The axis value of the screen offset `d` from the gaze, `r = |d|`: r itself, or the true
    /// eccentricity with the headset axis. GLSL: `vp_axis_of_offset`.
    pub fn axis_of_offset(&self, d: Vec2, r: f32) -> f32 {
        match &self.headset {
            None => r,
            Some(axis) => axis.eccentricity(d),
        }
    }

    /// Normalised ρ and pixel angle φ → screen offset from the gaze. GLSL: `vp_offset_of`.
    pub fn offset_of(&self, u: f32, phi: f32) -> Vec2 {
        let dir = Vec2::new(phi.cos(), phi.sin());
        let a = self.r_of_u(u);
        match &self.headset {
            None => a * dir,
            Some(axis) => axis.distance(a, dir) * dir,
        }
    }

    /// Axis value (see `r_of_u`) → normalised ρ coordinate (inverse of `r_of_u`).
    pub fn u_of_r(&self, r: f32) -> f32 {
        if let Some(law) = &self.log_polar {
            if self.u_f > 0.0 && r < self.r_f {
                return r / self.r_f * self.u_f;
            }
            return self.u_f + (law.u_of_r(r) - law.inner) / (1.0 - law.inner) * (1.0 - self.u_f);
        }
        if r < self.r_f {
            return r / self.r_f * self.u_f;
        }
        if let Some(axis) = &self.screen_axis {
            return self.u_f + axis.p_of_r(r) * (1.0 - self.u_f);
        }
        let e = r / self.r_max * self.e_norm;
        if self.exact {
            // Through the tail, like r_of_u, so both directions stay well conditioned at e_max.
            let q = cdf_tail(e, self.params.density_exponent, self.e_max(), self.cdf_max)
                / self.cdf_max;
            return 1.0 - q / (1.0 - self.p_f) * (1.0 - self.u_f);
        }
        let p = poly_fraction_of(e, self.cdf_max);
        self.u_f + (p - self.p_f) / (1.0 - self.p_f) * (1.0 - self.u_f)
    }

    /// The eccentricity the CDF is normalised at: 80 on the paper's axis, the farthest corner's
    /// true eccentricity on the headset's.
    fn e_max(&self) -> f32 {
        self.headset.map_or(E_MAX_DEG, |axis| axis.e_max)
    }

    /// The column a continuous grid x belongs to (clamped, so u = 1 stays in the last column).
    pub fn column_of(&self, x: f32) -> u32 {
        (x.max(0.0).floor() as u32).min(self.grid.x - 1)
    }

    /// Screen position (pixels, y down) → continuous grid coordinates (texel units). y ∈ [0, n(col)).
    /// Follows the layout; GLSL: `vp_layout_screen_to_vp` (`vp_screen_to_vp` is the paper's).
    pub fn screen_to_vp(&self, s: Vec2) -> Vec2 {
        match self.params.layout {
            VpLayout::Paper => self.paper_screen_to_vp(s),
            VpLayout::ScreenClipped | VpLayout::ScreenAware => self.clipped_screen_to_vp(s),
        }
    }

    /// Continuous grid coordinates → screen position (pixels). Follows the layout; GLSL:
    /// `vp_layout_vp_to_screen` (`vp_vp_to_screen` is the paper's).
    pub fn vp_to_screen(&self, g: Vec2) -> Vec2 {
        match self.params.layout {
            VpLayout::Paper => self.paper_vp_to_screen(g),
            VpLayout::ScreenClipped | VpLayout::ScreenAware => self.clipped_vp_to_screen(g),
        }
    }

    /// The paper layout's `screen_to_vp` (GLSL `vp_screen_to_vp`).
    pub fn paper_screen_to_vp(&self, s: Vec2) -> Vec2 {
        let d = s - self.gaze;
        let r = d.length();
        let mut phi = d.y.atan2(d.x);
        if phi < 0.0 {
            phi += TAU;
        }
        let x = self.u_of_r(self.axis_of_offset(d, r)) * self.grid.x as f32;
        let n = self.rows_in_column(self.column_of(x)) as f32;
        // atan2 may round to exactly 2π after the wrap: keep y inside [0, n).
        let y = phi / TAU * n;
        Vec2::new(x, if y >= n { 0.0 } else { y })
    }

    /// The paper layout's `vp_to_screen` (GLSL `vp_vp_to_screen`). φ wraps (any y is accepted).
    pub fn paper_vp_to_screen(&self, g: Vec2) -> Vec2 {
        let n = self.rows_in_column(self.column_of(g.x)) as f32;
        let phi = g.y / n * TAU;
        self.gaze + self.offset_of(g.x / self.grid.x as f32, phi)
    }

    /// The parameters as the GPU gets them (binding `sampling`; unpacked by `vp_unpack` in
    /// `visual_polar_math.glsl`, which derives r_max = e_norm = 1 for the headset axis):
    /// grid = (grid w, grid h, screen w, screen h), shape1.y = flags (1 exact inverse CDF,
    /// 2 rows on the on-screen arcs, 4 headset axis, 8 log-polar law, 16 the screen-aware ρ axis,
    /// its knots in the sampling table), and by axis
    /// - paper (normalised): gaze = (x, y, r_max, k), shape0 = (u_f, p_f, r_f, e_norm),
    ///   shape1 = (cdf_max, flags, fovea° (informative), 0);
    /// - headset: gaze = (x, y, G.x, k), shape0 = (u_f, p_f, fovea°, G.y),
    ///   shape1 = (e_max, flags, scale.x, scale.y) (G: gaze in tangent space, scale: tangent
    ///   units per pixel; the GPU derives cdf_max = cdf(e_max, k) as `new` does).
    pub fn sampling_params(&self) -> SamplingParams {
        let flags = self.exact as u32 * FLAG_EXACT
            + self.params.layout.clips() as u32 * FLAG_CLIPPED
            + self.screen_axis.is_some() as u32 * FLAG_SCREEN_AXIS
            + self.headset.is_some() as u32 * FLAG_HEADSET
            + self.log_polar.is_some() as u32 * FLAG_LOG_POLAR;
        let grid = UVec4::new(self.grid.x, self.grid.y, self.screen.x, self.screen.y);
        let k = self.params.density_exponent;
        match &self.headset {
            None => SamplingParams {
                grid,
                gaze: Vec4::new(self.gaze.x, self.gaze.y, self.r_max, k),
                // Log-polar: shape0.y = the law's inner column instead of p_f (unused by the law).
                shape0: Vec4::new(
                    self.u_f,
                    self.log_polar.map_or(self.p_f, |law| law.inner),
                    self.r_f,
                    self.e_norm,
                ),
                // Log-polar: shape1.zw = (α, L) instead of (fovea°, 0).
                shape1: match &self.log_polar {
                    None => Vec4::new(self.cdf_max, flags as f32, self.params.fovea_deg, 0.0),
                    Some(law) => Vec4::new(self.cdf_max, flags as f32, law.alpha, law.l),
                },
            },
            Some(axis) => SamplingParams {
                grid,
                gaze: Vec4::new(self.gaze.x, self.gaze.y, axis.gaze_tan.x, k),
                shape0: Vec4::new(self.u_f, self.p_f, self.r_f, axis.gaze_tan.y),
                shape1: Vec4::new(axis.e_max, flags as f32, axis.scale.x, axis.scale.y),
            },
        }
    }
}

/// Whether packed parameters (`VisualPolar::sampling_params`) select the screen-clipped layout
/// (the flag slot; Cartesian parameters are all zero, i.e. no).
pub fn params_select_clipped_layout(p: &SamplingParams) -> bool {
    (p.shape1.y as u32) & FLAG_CLIPPED != 0
}

/// Whether packed parameters need a general VP kernel rather than the one specialised for the
/// paper's layout, normalised axis and quartic inverse CDF (lavapipe runs both sides of a branch,
/// so the default pays for neither the screen-clipped mapping, the headset axis nor the exact
/// CDF that the remap's screen → VP mapping evaluates).
pub fn params_need_general_kernel(p: &SamplingParams) -> bool {
    (p.shape1.y as u32) & (FLAG_CLIPPED | FLAG_HEADSET | FLAG_EXACT | FLAG_LOG_POLAR) != 0
}

impl VisualPolar {
    /// Column `col`'s arcs in the active layout: the full circle in the paper's; in the
    /// screen-clipped one the on-screen part of the circle at the column's centre radius.
    pub fn column_arcs(&self, col: u32) -> ColumnArcs {
        match self.params().layout {
            VpLayout::Paper => ColumnArcs::FULL,
            VpLayout::ScreenClipped | VpLayout::ScreenAware => {
                let u_c = (col as f32 + 0.5) / self.grid_size().x as f32;
                on_screen_arcs(self.gaze(), self.r_of_u(u_c), self.screen())
            }
        }
    }

    /// The per-column table the GPU reads: two RGBA32F texels per column (`ColumnArcs::texels`),
    /// then the screen-aware axis' knots (`AXIS_KNOT_TEXELS` texels, zero in the other layouts);
    /// GLSL looks them up through `vp_column_arcs` and `vp_axis_knot`. Recomputed whenever the
    /// gaze moves.
    pub fn column_table(&self) -> Vec<[f32; 4]> {
        let mut table = Vec::new();
        self.write_column_table(&mut table);
        table
    }

    /// `column_table` into a caller-owned vector (cleared first; the render loop reuses it).
    pub fn write_column_table(&self, out: &mut Vec<[f32; 4]>) {
        out.clear();
        out.extend((0..self.grid_size().x).flat_map(|c| self.column_arcs(c).texels()));
        match self.screen_axis() {
            Some(axis) => out.extend(axis.texels()),
            None => out.extend([[0.0; 4]; AXIS_KNOT_TEXELS]),
        }
    }

    /// Grid → screen in the screen-clipped layout (GLSL `vp_clipped_vp_to_screen`): row y of a
    /// column with n rows sits at arc position y/n·A.
    pub fn clipped_vp_to_screen(&self, g: Vec2) -> Vec2 {
        let col = self.column_of(g.x);
        let n = self.rows_in_column(col) as f32;
        let arcs = self.column_arcs(col);
        let phi = arcs.phi_of_arc(g.y / n * arcs.total());
        let r = self.r_of_u(g.x / self.grid_size().x as f32);
        self.gaze() + r * Vec2::new(phi.cos(), phi.sin())
    }

    /// Screen → grid in the screen-clipped layout (GLSL `vp_clipped_screen_to_vp`); y ∈ [0, n).
    /// Angles just outside the column's arcs clamp to the nearest arc end.
    pub fn clipped_screen_to_vp(&self, s: Vec2) -> Vec2 {
        let d = s - self.gaze();
        let r = d.length();
        let mut phi = d.y.atan2(d.x);
        if phi < 0.0 {
            phi += TAU;
        }
        let x = self.u_of_r(r) * self.grid_size().x as f32;
        let col = self.column_of(x);
        let n = self.rows_in_column(col) as f32;
        let arcs = self.column_arcs(col);
        let y = arcs.arc_row(arcs.arc_of_phi(phi).0, n);
        // y = n is φ = 2π on a full circle (row 0) or a clipped arc's far end (its last row).
        let y = if y < n {
            y
        } else if arcs.wraps() {
            0.0
        } else {
            f32::from_bits(n.to_bits() - 1)
        };
        Vec2::new(x, y)
    }
}

#[cfg(test)]
#[path = "visual_polar_tests.rs"]
mod tests;
