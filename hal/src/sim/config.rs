//! Simulator parameters. Every field has a default from hal.md; TOML files may set any subset
//! (unknown keys are rejected). Tracker figures (rate, latency, accuracy, precision) come from the
//! headset profile unless overridden here.

use crate::error::HalError;
use serde::Deserialize;
use std::path::Path;

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimConfig {
    /// Same seed + same config + same query times → bit-identical samples.
    pub seed: u64,
    /// Fixation durations are gamma distributed (right-skewed) with this mean and SD.
    pub fixation_mean_ms: f64,
    pub fixation_sd_ms: f64,
    /// Random targets are drawn uniformly within ±[azimuth, elevation] degrees of straight ahead.
    pub target_range_deg: [f64; 2],
    /// Main sequence: peak velocity = max · (1 − exp(−A / scale)) °/s.
    pub saccade_peak_velocity_max_deg_s: f64,
    pub saccade_velocity_scale_deg: f64,
    /// Reaction time between a scripted target jump and the saccade toward it.
    pub saccade_latency_ms: f64,
    pub microsaccade_rate_hz: f64,
    pub microsaccade_amplitude_deg: [f64; 2],
    /// Fixational drift: Ornstein–Uhlenbeck offset around the fixation target, stationary SD
    /// per axis and time constant (the pull-back is what keeps drift from wandering off).
    pub drift_sd_deg: f64,
    pub drift_time_constant_ms: f64,
    pub blink_rate_per_min: f64,
    pub blink_duration_ms: [f64; 2],
    /// Chance that a random-mode fixation ends in smooth pursuit instead of a saccade.
    pub pursuit_probability: f64,
    pub pursuit_speed_deg_s: [f64; 2],
    pub pursuit_gain: f64,
    pub pursuit_max_speed_deg_s: f64,
    /// Position error that triggers a catch-up saccade during pursuit.
    pub catch_up_threshold_deg: f64,
    /// The tracker accuracy bias drifts to a new random value over this many seconds.
    pub bias_time_constant_s: f64,
    /// Reported convergence distance and per-eye ray convergence point.
    pub convergence_distance_m: f64,
    /// XrTime of tracker tick 0.
    pub start_time_ns: i64,
    pub rate_hz: Option<f32>,
    pub latency_ms: Option<f32>,
    pub accuracy_deg: Option<f32>,
    pub precision_deg: Option<f32>,
    /// Non-empty → scripted mode: targets come from here instead of random fixations.
    pub script: Vec<ScriptStep>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ScriptMotion {
    /// The target jumps at `time_ms`; the eye saccades after `saccade_latency_ms`.
    #[default]
    Jump,
    /// The target glides from the previous step's position (starting at its time) to this one,
    /// arriving at `time_ms`; the eye pursues it.
    Pursue,
}

#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScriptStep {
    pub time_ms: f64,
    pub azimuth_deg: f64,
    pub elevation_deg: f64,
    #[serde(default)]
    pub motion: ScriptMotion,
}

impl Default for SimConfig {
    fn default() -> Self {
        SimConfig {
            seed: 1,
            fixation_mean_ms: 275.0,
            fixation_sd_ms: 120.0,
            target_range_deg: [20.0, 15.0],
            saccade_peak_velocity_max_deg_s: 500.0,
            saccade_velocity_scale_deg: 15.0,
            saccade_latency_ms: 200.0,
            microsaccade_rate_hz: 1.5,
            microsaccade_amplitude_deg: [0.1, 1.0],
            drift_sd_deg: 0.1,
            drift_time_constant_ms: 300.0,
            blink_rate_per_min: 17.5,
            blink_duration_ms: [100.0, 400.0],
            pursuit_probability: 0.0,
            pursuit_speed_deg_s: [5.0, 30.0],
            pursuit_gain: 0.9,
            pursuit_max_speed_deg_s: 30.0,
            catch_up_threshold_deg: 2.0,
            bias_time_constant_s: 10.0,
            convergence_distance_m: 1.5,
            start_time_ns: 0,
            rate_hz: None,
            latency_ms: None,
            accuracy_deg: None,
            precision_deg: None,
            script: Vec::new(),
        }
    }
}

impl SimConfig {
    /// Default parameters with a different seed.
    pub fn seeded(seed: u64) -> Self {
        SimConfig {
            seed,
            ..SimConfig::default()
        }
    }

    pub fn load(path: &Path) -> Result<SimConfig, HalError> {
        let text =
            crate::file::read_text(path, crate::file::MAX_PROFILE_BYTES, "a simulator profile")?;
        Self::parse(&text, path)
    }

    pub fn parse(text: &str, file: &Path) -> Result<SimConfig, HalError> {
        let cfg: SimConfig = toml::from_str(text).map_err(|e| HalError::Toml {
            file: file.to_path_buf(),
            message: e.to_string().trim_end().to_string(),
        })?;
        cfg.validate(file)?;
        Ok(cfg)
    }

    /// Range checks; `file` labels errors (use "<config>" for programmatic configs).
    pub fn validate(&self, file: &Path) -> Result<(), HalError> {
        let err = |key: &str, reason: &str| Err(HalError::invalid(file, key, reason.to_string()));
        let positive = [
            ("fixation_mean_ms", self.fixation_mean_ms),
            ("fixation_sd_ms", self.fixation_sd_ms),
            (
                "saccade_peak_velocity_max_deg_s",
                self.saccade_peak_velocity_max_deg_s,
            ),
            (
                "saccade_velocity_scale_deg",
                self.saccade_velocity_scale_deg,
            ),
            ("drift_time_constant_ms", self.drift_time_constant_ms),
            ("pursuit_max_speed_deg_s", self.pursuit_max_speed_deg_s),
            ("catch_up_threshold_deg", self.catch_up_threshold_deg),
            ("bias_time_constant_s", self.bias_time_constant_s),
            ("convergence_distance_m", self.convergence_distance_m),
        ];
        for (key, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return err(key, "must be a finite number > 0");
            }
        }
        let non_negative = [
            ("saccade_latency_ms", self.saccade_latency_ms),
            ("microsaccade_rate_hz", self.microsaccade_rate_hz),
            ("drift_sd_deg", self.drift_sd_deg),
            ("blink_rate_per_min", self.blink_rate_per_min),
        ];
        for (key, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return err(key, "must be a finite number >= 0");
            }
        }
        for (key, v) in [
            ("pursuit_probability", self.pursuit_probability),
            ("pursuit_gain", self.pursuit_gain),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return err(key, "must lie in 0..=1");
            }
        }
        let ranges = [
            (
                "microsaccade_amplitude_deg",
                self.microsaccade_amplitude_deg,
                0.0,
                5.0,
            ),
            ("blink_duration_ms", self.blink_duration_ms, 1.0, 5000.0),
            ("pursuit_speed_deg_s", self.pursuit_speed_deg_s, 0.1, 200.0),
        ];
        for (key, [a, b], lo, hi) in ranges {
            let ok = a.is_finite() && b.is_finite() && a >= lo && b <= hi && a <= b;
            if !ok {
                return err(
                    key,
                    &format!("must be [min, max] with {lo} <= min <= max <= {hi}"),
                );
            }
        }
        if !self
            .target_range_deg
            .iter()
            .all(|v| (0.0..=80.0).contains(v))
        {
            return err(
                "target_range_deg",
                "must be [azimuth, elevation] half-ranges within 0..=80 degrees",
            );
        }
        if self.blink_rate_per_min > 0.0
            && 60_000.0 / self.blink_rate_per_min <= self.mean_blink_ms()
        {
            return err(
                "blink_rate_per_min",
                "blinks would overlap: 60000 / rate must exceed the mean blink duration",
            );
        }
        let tracker = [
            ("rate_hz", self.rate_hz, true),
            ("latency_ms", self.latency_ms, false),
            ("accuracy_deg", self.accuracy_deg, false),
            ("precision_deg", self.precision_deg, false),
        ];
        for (key, v, strictly_positive) in tracker {
            if let Some(v) = v {
                let ok = v.is_finite() && if strictly_positive { v > 0.0 } else { v >= 0.0 };
                if !ok {
                    return err(
                        key,
                        "must be a finite number (> 0 for rate_hz, >= 0 otherwise)",
                    );
                }
            }
        }
        let mut prev = f64::NEG_INFINITY;
        for (i, s) in self.script.iter().enumerate() {
            let angles_ok = s.azimuth_deg.abs() < 89.0 && s.elevation_deg.abs() < 89.0;
            if !s.time_ms.is_finite() || s.time_ms < 0.0 || !angles_ok {
                return err(
                    &format!("script[{i}]"),
                    "time_ms must be >= 0 and angles within ±89°",
                );
            }
            if s.time_ms <= prev {
                return err(
                    &format!("script[{i}].time_ms"),
                    "script times must be strictly increasing",
                );
            }
            prev = s.time_ms;
        }
        Ok(())
    }

    pub(crate) fn mean_blink_ms(&self) -> f64 {
        0.5 * (self.blink_duration_ms[0] + self.blink_duration_ms[1])
    }

    /// Peak saccade velocity (°/s) for an amplitude, from the main sequence.
    pub fn main_sequence_peak_velocity(&self, amplitude_deg: f64) -> f64 {
        self.saccade_peak_velocity_max_deg_s
            * (1.0 - (-amplitude_deg / self.saccade_velocity_scale_deg).exp())
    }
}
