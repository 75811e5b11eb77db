//! SVGF's parameters.

use crate::error::{Error, Result};

/// Filter parameters; `Default` is the paper's (and a render profile's `[svgf]` keys' defaults).
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SvgfSettings {
    /// Smallest blend weight of the new colour sample (α = max(this, 1/history)).
    pub alpha_color: f32,
    /// The same for the luminance moments.
    pub alpha_moments: f32,
    /// History length cap in frames.
    pub max_history: u32,
    /// Below this history length the variance is estimated spatially (7×7).
    pub variance_history: u32,
    /// À-trous iterations (5×5 taps, spacing 2^i); the first one's output is the colour history.
    pub atrous_iterations: u32,
    /// Luminance edge-stop σ_l (in units of the local standard deviation).
    pub sigma_luminance: f32,
    /// Depth edge-stop σ_z (in units of the depth gradient × distance).
    pub sigma_depth: f32,
    /// Normal edge-stop exponent σ_n.
    pub sigma_normal: f32,
}

impl Default for SvgfSettings {
    fn default() -> Self {
        SvgfSettings {
            alpha_color: 0.2,
            alpha_moments: 0.2,
            max_history: 32,
            variance_history: 4,
            atrous_iterations: 5,
            sigma_luminance: 4.0,
            sigma_depth: 1.0,
            sigma_normal: 128.0,
        }
    }
}

/// Most à-trous iterations accepted: 2^9 texels apart is wider than any grid.
pub const MAX_ATROUS_ITERATIONS: u32 = 10;

impl SvgfSettings {
    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(Error::Invalid(format!("svgf: {what}")));
        let unit = |a: f32| a > 0.0 && a <= 1.0;
        if !unit(self.alpha_color) || !unit(self.alpha_moments) {
            return bad(format!(
                "alphas must be in (0, 1], got {} and {}",
                self.alpha_color, self.alpha_moments
            ));
        }
        if self.max_history == 0 {
            return bad("max_history must be at least 1".into());
        }
        if !(1..=MAX_ATROUS_ITERATIONS).contains(&self.atrous_iterations) {
            return bad(format!(
                "atrous_iterations must be in 1..={MAX_ATROUS_ITERATIONS}, got {}",
                self.atrous_iterations
            ));
        }
        let sigmas = [self.sigma_luminance, self.sigma_depth, self.sigma_normal];
        if !sigmas.iter().all(|s| s.is_finite() && *s > 0.0) {
            return bad(format!(
                "σ_l, σ_z, σ_n must be finite and > 0, got {sigmas:?}"
            ));
        }
        Ok(())
    }
}
