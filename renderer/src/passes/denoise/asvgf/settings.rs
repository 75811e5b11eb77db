//! A-SVGF's parameters.

use crate::error::{Error, Result};
use crate::passes::denoise::svgf::SvgfSettings;

/// Gradient parameters; SVGF's own (`svgf`) apply to the filter after the adaptive α. A render
/// profile's `[asvgf]` gives the gradient keys; `svgf` comes from its `[svgf]`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AsvgfSettings {
    #[serde(skip)]
    pub svgf: SvgfSettings,
    /// À-trous iterations of the gradient reconstruction (5×5 taps, spacing 2^i strata).
    pub gradient_iterations: u32,
    /// Depth edge-stop σ_z of the reconstruction (as SVGF's).
    pub gradient_sigma_depth: f32,
    /// Normal edge-stop exponent σ_n of the reconstruction.
    pub gradient_sigma_normal: f32,
}

impl Default for AsvgfSettings {
    fn default() -> Self {
        AsvgfSettings {
            svgf: SvgfSettings::default(),
            gradient_iterations: 4,
            gradient_sigma_depth: 1.0,
            gradient_sigma_normal: 128.0,
        }
    }
}

/// Most reconstruction iterations accepted: 2^7 strata apart spans any grid.
pub const MAX_GRADIENT_ITERATIONS: u32 = 8;

impl AsvgfSettings {
    pub fn validate(&self) -> Result<()> {
        self.svgf.validate()?;
        let bad = |what: String| Err(Error::Invalid(format!("asvgf: {what}")));
        if !(1..=MAX_GRADIENT_ITERATIONS).contains(&self.gradient_iterations) {
            return bad(format!(
                "gradient_iterations must be in 1..={MAX_GRADIENT_ITERATIONS}, got {}",
                self.gradient_iterations
            ));
        }
        let sigmas = [self.gradient_sigma_depth, self.gradient_sigma_normal];
        if !sigmas.iter().all(|s| s.is_finite() && *s > 0.0) {
            return bad(format!(
                "gradient σ_z, σ_n must be finite and > 0, got {sigmas:?}"
            ));
        }
        Ok(())
    }
}
