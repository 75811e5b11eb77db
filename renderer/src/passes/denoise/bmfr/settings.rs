//! BMFR's parameters.

use crate::error::{Error, Result};

/// Filter parameters; `Default` is the paper's (and a render profile's `[bmfr]` keys' defaults).
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BmfrSettings {
    /// Smallest blend weight of the new noisy sample and features before the fit
    /// (α = max(this, 1/history)).
    pub alpha_noisy: f32,
    /// The same for the fitted colour after the fit.
    pub alpha_filtered: f32,
    /// Amplitude of the uniform noise added to the features (not the constant) in the fit.
    pub noise: f32,
}

impl Default for BmfrSettings {
    fn default() -> Self {
        BmfrSettings {
            alpha_noisy: 0.2,
            alpha_filtered: 0.1,
            noise: 1e-2,
        }
    }
}

impl BmfrSettings {
    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(Error::Invalid(format!("bmfr: {what}")));
        // α = 1 would mean no accumulation at all; the passes use it to drop the history.
        let open_unit = |a: f32| a > 0.0 && a < 1.0;
        if !open_unit(self.alpha_noisy) || !open_unit(self.alpha_filtered) {
            return bad(format!(
                "alpha_noisy and alpha_filtered must be in (0, 1), got {} and {}",
                self.alpha_noisy, self.alpha_filtered
            ));
        }
        if !(self.noise.is_finite() && (0.0..=0.1).contains(&self.noise)) {
            return bad(format!("noise must be in [0, 0.1], got {}", self.noise));
        }
        Ok(())
    }
}
