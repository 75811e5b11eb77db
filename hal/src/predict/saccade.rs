//! The ballistic saccade model and its fit to a saccade's first samples.
//!
//! A saccade of amplitude A follows a minimum-jerk displacement profile A·(10τ³ − 15τ⁴ + 6τ⁵),
//! τ = (t − t0)/D(A), over the duration of the main sequence, D(A) = 21 ms + 2.2 ms/°·A (after
//! Arabadzhiyska et al. 2017, "Saccade landing position prediction for gaze-contingent
//! rendering", which fits a saccade's first samples to amplitude-indexed profiles). Early in a
//! saccade the displacement hardly depends on A (the eye accelerates alike), so the fit is a
//! maximum a posteriori estimate: the samples' likelihood times a log-normal prior on the
//! amplitude, whose median the predictor learns from the saccades it has seen. Once the samples
//! pass the velocity peak the likelihood dominates.

use glam::DVec2;

/// Position along a minimum-jerk movement, 0 at τ ≤ 0 and 1 at τ ≥ 1.
pub fn minimum_jerk(tau: f64) -> f64 {
    let t = tau.clamp(0.0, 1.0);
    t * t * t * (10.0 + t * (-15.0 + 6.0 * t))
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SaccadeModel {
    /// D(A) = duration_base_s + duration_per_deg_s · A.
    pub duration_base_s: f64,
    pub duration_per_deg_s: f64,
    /// Largest amplitude considered (degrees).
    pub max_amplitude_deg: f64,
    /// Spread of the amplitude prior (standard deviation of ln A).
    pub prior_log_sd: f64,
    /// Model error per degree of displacement (relative), added to the tracker noise.
    pub relative_error: f64,
    /// The duration may differ from D(A) by a factor e^z, z in this range, with a Gaussian
    /// prior of this spread on z (saccades of one amplitude vary, and trackers differ).
    pub duration_log_range: [f64; 2],
    pub duration_log_sd: f64,
}

impl Default for SaccadeModel {
    fn default() -> Self {
        SaccadeModel {
            duration_base_s: 0.021,
            duration_per_deg_s: 0.0022,
            max_amplitude_deg: 40.0,
            prior_log_sd: 0.8,
            relative_error: 0.05,
            duration_log_range: [-0.4, 0.8],
            duration_log_sd: 0.3,
        }
    }
}

impl SaccadeModel {
    pub fn duration_s(&self, amplitude_deg: f64) -> f64 {
        self.duration_base_s + self.duration_per_deg_s * amplitude_deg
    }

    /// Displacement (degrees) `elapsed_s` after the onset of a saccade of `amplitude_deg`.
    pub fn displacement(&self, amplitude_deg: f64, elapsed_s: f64) -> f64 {
        amplitude_deg * minimum_jerk(elapsed_s / self.duration_s(amplitude_deg))
    }
}

/// What the fit assumes before the samples speak, learnt from the saccades seen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SaccadePrior {
    /// The tracker's per-axis noise (degrees).
    pub noise_deg: f64,
    /// Median of the amplitude prior (degrees).
    pub amplitude_deg: f64,
    /// ln of the duration relative to the main sequence's D(A) (0: as the main sequence says).
    pub duration_log: f64,
}

/// A fitted saccade: from `start` along `direction` (unit), amplitude and onset time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SaccadeFit {
    pub start: DVec2,
    pub direction: DVec2,
    pub amplitude_deg: f64,
    pub onset_s: f64,
    pub duration_s: f64,
}

impl SaccadeFit {
    /// Where the eye is at `t_s` under the fit (the landing point from the end on).
    pub fn position(&self, t_s: f64) -> DVec2 {
        let tau = (t_s - self.onset_s) / self.duration_s;
        self.start + self.direction * self.amplitude_deg * minimum_jerk(tau)
    }

    pub fn landing(&self) -> DVec2 {
        self.start + self.direction * self.amplitude_deg
    }

    pub fn end_s(&self) -> f64 {
        self.onset_s + self.duration_s
    }
}

/// Fits the model to a saccade leaving `start` (the fixation's position): `samples` (time in
/// seconds, position in degrees) are the last ones of the fixation and those since, of which the
/// first moving one is at `moving_s`; the onset lies between the sample before it (or half a
/// sample period earlier: that one may have moved less than the noise) and it.
/// `prior`: what the saccades seen so far suggest.
pub fn fit(
    model: &SaccadeModel,
    start: DVec2,
    samples: &[(f64, DVec2)],
    moving_s: f64,
    prior: &SaccadePrior,
) -> Option<SaccadeFit> {
    let noise_deg = prior.noise_deg;
    let &(_, last_p) = samples.last()?;
    let still_s = samples
        .iter()
        .map(|s| s.0)
        .filter(|&t| t < moving_s)
        .fold(f64::NEG_INFINITY, f64::max);
    let first_s = if still_s.is_finite() {
        still_s - (moving_s - still_s) / 2.0
    } else {
        moving_s
    };
    let direction = (last_p - start).try_normalize()?;
    let along: Vec<(f64, f64)> = samples
        .iter()
        .map(|&(t, p)| (t, (p - start).dot(direction)))
        .collect();
    let reached = along.iter().map(|a| a.1).fold(0.0, f64::max);
    let sd = |d: f64| (noise_deg * noise_deg + (model.relative_error * d).powi(2)).sqrt();
    let prior_ln = prior.amplitude_deg.max(0.1).ln();
    // Grids: amplitude log-spaced from most of what the eye has covered; duration around the
    // main sequence's; onset between the first sample and the first moving one.
    const AMPLITUDES: usize = 64;
    const DURATIONS: usize = 13;
    const ONSETS: usize = 24;
    let lo = (reached * 0.8).max(0.2);
    let hi = model.max_amplitude_deg.max(lo * 1.01);
    let mut best: Option<(f64, f64, f64, f64)> = None;
    for i in 0..AMPLITUDES {
        let a = lo * (hi / lo).powf(i as f64 / (AMPLITUDES - 1) as f64);
        let amplitude_prior = ((a.ln() - prior_ln) / model.prior_log_sd).powi(2);
        for k in 0..DURATIONS {
            let z = model.duration_log_range[0]
                + (model.duration_log_range[1] - model.duration_log_range[0]) * k as f64
                    / (DURATIONS - 1) as f64;
            let duration = model.duration_s(a) * z.exp();
            let prior =
                amplitude_prior + ((z - prior.duration_log) / model.duration_log_sd).powi(2);
            for j in 0..ONSETS {
                let t0 = first_s + (moving_s - first_s) * j as f64 / ONSETS as f64;
                let mut cost = prior;
                for &(t, d) in &along {
                    let r = (a * minimum_jerk((t - t0) / duration) - d) / sd(d);
                    cost += r * r;
                }
                if best.is_none_or(|b| cost < b.0) {
                    best = Some((cost, a, t0, duration));
                }
            }
        }
    }
    let (_, amplitude_deg, onset_s, duration_s) = best?;
    Some(SaccadeFit {
        start,
        direction,
        amplitude_deg,
        onset_s,
        duration_s,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimum_jerk_runs_from_zero_to_one_symmetrically() {
        assert_eq!(minimum_jerk(-1.0), 0.0);
        assert_eq!(minimum_jerk(2.0), 1.0);
        assert!((minimum_jerk(0.5) - 0.5).abs() < 1e-12);
        assert!((minimum_jerk(0.3) + minimum_jerk(0.7) - 1.0).abs() < 1e-12);
    }

    /// Samples well past the velocity peak pin the amplitude, whatever the prior says.
    #[test]
    fn samples_past_the_peak_determine_the_amplitude() {
        let m = SaccadeModel::default();
        for amplitude in [4.0, 8.0, 15.0] {
            let (onset, period) = (0.1003, 1.0 / 120.0);
            let d = m.duration_s(amplitude);
            let samples: Vec<(f64, DVec2)> = (0..)
                .map(|k| 0.1 + k as f64 * period)
                .take_while(|&t| t < onset + 0.85 * d)
                .map(|t| (t, DVec2::new(m.displacement(amplitude, t - onset), 0.0)))
                .collect();
            for prior in [3.0, 20.0] {
                let p = SaccadePrior {
                    noise_deg: 0.05,
                    amplitude_deg: prior,
                    duration_log: 0.0,
                };
                let f = fit(&m, DVec2::ZERO, &samples, 0.1 + period, &p).unwrap();
                assert!(
                    (f.amplitude_deg - amplitude).abs() < 0.12 * amplitude,
                    "A {amplitude}, prior {prior}: {f:?}"
                );
                assert!((f.direction - DVec2::X).length() < 1e-9);
            }
        }
    }
}
