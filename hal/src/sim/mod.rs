//! Simulated FOVE 0 (or any profile): a noise-free eye model sampled by a simulated tracker that
//! adds precision noise, a slowly varying accuracy bias, and latency.
//!
//! Determinism: the eye, blink and tracker-noise streams use separate PCG generators derived from
//! the seed, and the simulation advances one tracker tick at a time regardless of how it is
//! queried, so the same seed and config always give the same sample for a tick.

mod config;
mod eye;
pub mod motion;

pub use config::{ScriptMotion, ScriptStep, SimConfig};
pub use eye::EyePhase;

use crate::error::HalError;
use crate::hmd::HmdDescription;
use crate::sample::{EyeState, GazeRay, GazeSample, SampleTimeKind, XrTime};
use crate::source::GazeSource;
use eye::{BlinkSchedule, EyeModel};
use glam::{DVec2, DVec3, Vec2, Vec3};
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rand_pcg::Pcg64;
use std::collections::VecDeque;
use std::path::Path;

/// How many past measurements stay queryable (for `sample_at` with an older time).
const HISTORY_LEN: usize = 512;

/// One tracker measurement plus the ground truth behind it.
#[derive(Debug, Clone, Copy)]
pub struct SimTick {
    /// What the tracker reports (before latency is applied).
    pub sample: GazeSample,
    /// The eye's true direction (no noise, no bias).
    pub truth: Vec3,
    pub phase: EyePhase,
    pub blinking: bool,
    /// Current accuracy bias, degrees (right, up).
    pub bias_deg: Vec2,
}

pub struct SimulatedFove {
    hmd: HmdDescription,
    cfg: SimConfig,
    eye: EyeModel,
    blinks: BlinkSchedule,
    noise_rng: Pcg64,
    bias: DVec2,
    bias_sd: f64,
    /// Bias keyframes (start of the current segment, end of it) drawn every time constant.
    bias_keys: [DVec2; 2],
    bias_segment: u64,
    next_tick: u64,
    latency_ns: i64,
    history: VecDeque<GazeSample>,
    /// Newest sample handed out (what `latest` returns).
    newest_available: Option<GazeSample>,
}

impl SimulatedFove {
    /// `hmd` provides the tracker figures unless `cfg` overrides them.
    pub fn new(mut hmd: HmdDescription, cfg: SimConfig) -> Result<Self, HalError> {
        cfg.validate(Path::new("<simulator config>"))?;
        let t = &mut hmd.tracker;
        t.rate_hz = cfg.rate_hz.unwrap_or(t.rate_hz);
        t.latency_ms = cfg.latency_ms.unwrap_or(t.latency_ms);
        t.accuracy_deg = cfg.accuracy_deg.unwrap_or(t.accuracy_deg);
        t.precision_deg = cfg.precision_deg.unwrap_or(t.precision_deg);
        let seed = cfg.seed;
        let stream =
            |k: u64| Pcg64::seed_from_u64(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15).wrapping_add(k));
        // Mean 2D error magnitude of an isotropic Gaussian is σ·√(π/2): accuracy is that mean.
        let bias_sd = hmd.tracker.accuracy_deg as f64 / (std::f64::consts::PI / 2.0).sqrt();
        let mut noise_rng = stream(3);
        let mut key = || {
            DVec2::new(
                noise_rng.sample(StandardNormal),
                noise_rng.sample(StandardNormal),
            ) * bias_sd
        };
        let bias_keys = [key(), key()];
        Ok(SimulatedFove {
            latency_ns: (hmd.tracker.latency_ms as f64 * 1e6).round() as i64,
            eye: EyeModel::new(&cfg, stream(1)),
            blinks: BlinkSchedule::new(&cfg, stream(2)),
            noise_rng,
            bias: bias_keys[0],
            bias_sd,
            bias_keys,
            bias_segment: 0,
            next_tick: 0,
            history: VecDeque::with_capacity(HISTORY_LEN),
            newest_available: None,
            hmd,
            cfg,
        })
    }

    /// Default FOVE 0 with default behaviour for `seed`.
    pub fn fove0(seed: u64) -> Self {
        // Defaults are valid by construction (tested).
        SimulatedFove::new(HmdDescription::fove0(), SimConfig::seeded(seed))
            .expect("default config is valid")
    }

    pub fn config(&self) -> &SimConfig {
        &self.cfg
    }

    /// XrTime of tracker tick `k`.
    pub fn tick_time(&self, k: u64) -> XrTime {
        self.cfg.start_time_ns + (k as f64 * 1e9 / self.hmd.tracker.rate_hz as f64).round() as i64
    }

    /// Produce the next tracker measurement (ignores latency; the history keeps it for queries).
    pub fn step(&mut self) -> SimTick {
        let k = self.next_tick;
        self.next_tick += 1;
        let time = self.tick_time(k);
        let t = (time - self.cfg.start_time_ns) as f64 / 1e9;
        let (truth, phase) = self.eye.advance(t);
        let blinking = self.blinks.blinking(t);
        self.update_bias(t);
        let noise = DVec2::new(
            self.noise_rng.sample(StandardNormal),
            self.noise_rng.sample(StandardNormal),
        ) * self.hmd.tracker.precision_deg as f64;
        let sample = if blinking {
            GazeSample {
                time_kind: SampleTimeKind::Measured,
                eye_state: [EyeState::Closed; 2],
                ..GazeSample::no_gaze(time, k)
            }
        } else {
            self.measured_sample(time, k, motion::offset_direction(truth, self.bias + noise))
        };
        if self.history.len() == HISTORY_LEN {
            self.history.pop_front();
        }
        self.history.push_back(sample);
        SimTick {
            sample,
            truth: truth.as_vec3(),
            phase,
            blinking,
            bias_deg: self.bias.as_vec2(),
        }
    }

    /// Slowly varying accuracy bias: independent Gaussian keyframes every time constant, blended
    /// as cos·k0 + sin·k1 — smooth, and with exactly constant variance (cos² + sin² = 1), so the
    /// mean error equals the configured accuracy at every moment.
    fn update_bias(&mut self, t: f64) {
        let period = self.cfg.bias_time_constant_s;
        let segment = (t / period).floor().max(0.0) as u64;
        while self.bias_segment < segment {
            let next = DVec2::new(
                self.noise_rng.sample(StandardNormal),
                self.noise_rng.sample(StandardNormal),
            ) * self.bias_sd;
            self.bias_keys = [self.bias_keys[1], next];
            self.bias_segment += 1;
        }
        let phase = (t / period - segment as f64) * std::f64::consts::FRAC_PI_2;
        self.bias = self.bias_keys[0] * phase.cos() + self.bias_keys[1] * phase.sin();
    }

    fn measured_sample(&self, time: XrTime, k: u64, dir: DVec3) -> GazeSample {
        let distance = self.cfg.convergence_distance_m;
        let point = dir * distance;
        let eye_ray = |offset: Vec3| GazeRay {
            origin: offset,
            direction: (point - offset.as_dvec3()).normalize().as_vec3(),
        };
        GazeSample {
            eyes: Some([
                eye_ray(self.hmd.eyes[0].offset),
                eye_ray(self.hmd.eyes[1].offset),
            ]),
            convergence_distance: Some(distance as f32),
            ..GazeSample::looking(time, k, dir.as_vec3())
        }
    }

    /// Generate every measurement that exists by tracker time `t`.
    fn generate_until(&mut self, t: XrTime) {
        while self.tick_time(self.next_tick) <= t {
            self.step();
        }
        if self.history.is_empty() {
            self.step();
        }
    }
}

impl GazeSource for SimulatedFove {
    fn describe(&self) -> &HmdDescription {
        &self.hmd
    }

    fn begin_frame(&mut self, predicted_display_time: XrTime) -> Result<(), HalError> {
        self.sample_at(predicted_display_time);
        Ok(())
    }

    /// The newest measurement that has reached the application by `t` (taken `latency` earlier),
    /// reported with its real measurement time. Before the first one exists: tick 0 (clamped).
    fn sample_at(&mut self, t: XrTime) -> GazeSample {
        let available = t.saturating_sub(self.latency_ns);
        self.generate_until(available);
        let idx = self.history.partition_point(|s| s.time <= available);
        let sample = self.history[idx.saturating_sub(1)];
        if self.newest_available.is_none_or(|n| sample.time > n.time) {
            self.newest_available = Some(sample);
        }
        sample
    }

    fn latest(&self) -> GazeSample {
        self.newest_available
            .unwrap_or_else(|| GazeSample::no_gaze(self.cfg.start_time_ns, 0))
    }
}
