//! Gaze prediction at a frame's display time from the tracker samples it can have
//! (`--gaze-predict off|hold|linear|saccade`).
//!
//! - `off`: the newest sample as measured (what a renderer without prediction shows).
//! - `hold`: the median of the current fixation's samples (the last 50 ms since the eye last
//!   jumped), which averages the tracker's noise away; a sample further from it than the noise
//!   allows is shown as it is, and starts a new fixation once the next sample confirms it.
//! - `linear`: `hold` plus the fixation's velocity (a line fitted to its samples) carried to the
//!   display time when it is significant against the noise and slow enough to be smooth pursuit.
//! - `saccade`: `linear`, plus saccade onset detection and landing prediction from the first
//!   samples of the saccade with the ballistic model of [`saccade`].
//!
//! In `hold`, `linear` and `saccade` a blink holds the fixation before it (not the samples of a
//! closing lid, which a saccade running into the blink is taken for), and the first valid sample
//! after it re-acquires the gaze (`PredictorParams::reacquire_samples`).
//!
//! Positions are angles in degrees, (atan(x/−z), atan(y/−z)) of the view-space direction, the
//! coordinates in which a flat recording screen is rectilinear. Every prediction but `off`'s is
//! clamped to the view both eyes share, so no prediction puts the fovea off the image.

pub mod saccade;

use crate::error::HalError;
use crate::hmd::HmdDescription;
use crate::sample::XrTime;
use glam::{DVec2, Vec3};
use saccade::{SaccadeFit, SaccadeModel, SaccadePrior};
use std::collections::VecDeque;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PredictMode {
    Off,
    Hold,
    Linear,
    Saccade,
}

impl PredictMode {
    pub const ALL: [PredictMode; 4] = [
        PredictMode::Off,
        PredictMode::Hold,
        PredictMode::Linear,
        PredictMode::Saccade,
    ];
    pub const NAMES: [&'static str; 4] = ["off", "hold", "linear", "saccade"];
    /// Chosen by `fovea gaze-eval` on the shared recordings (docs/guide/gaze-latency.md).
    pub const DEFAULT: PredictMode = PredictMode::Saccade;

    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    pub fn parse(s: &str) -> Result<PredictMode, HalError> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| HalError::Flag {
                flag: "--gaze-predict",
                reason: format!("`{s}`: expected one of {}", Self::NAMES.join(", ")),
            })
    }
}

/// What the predictor takes the eye to be doing at the newest sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EyeMotion {
    /// The newest sample, unfiltered (`off`, or a jump not yet told from noise).
    Newest,
    Fixation,
    Pursuit,
    Saccade,
    /// The tracker has no gaze (blink, lost pupil) or is re-acquiring after one.
    Blink,
}

impl EyeMotion {
    pub fn name(self) -> &'static str {
        match self {
            EyeMotion::Newest => "newest",
            EyeMotion::Fixation => "fixation",
            EyeMotion::Pursuit => "pursuit",
            EyeMotion::Saccade => "saccade",
            EyeMotion::Blink => "blink",
        }
    }
}

/// The predicted gaze for one display time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prediction {
    /// Unit view-space direction; `None` while the tracker has no gaze.
    pub direction: Option<Vec3>,
    /// With `direction` `None`: what to hold meanwhile (the fixation before the blink).
    pub hold: Option<Vec3>,
    pub motion: EyeMotion,
    /// The newest valid tracker sample behind the prediction (0 before any).
    pub sample_time: XrTime,
    /// Display time − `sample_time`: how far ahead the prediction reaches.
    pub horizon_ns: i64,
}

/// Tuning of the predictor (defaults chosen with `fovea gaze-eval` on the shared recordings).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PredictorParams {
    /// Longest stretch of a fixation averaged (seconds).
    pub fixation_window_s: f64,
    /// A sample this many noise deviations (per axis) from the fixation leaves it...
    pub jump_sigmas: f64,
    /// ...and never less than this many degrees.
    pub min_jump_deg: f64,
    /// Tracker noise assumed before it is measured (degrees, per axis).
    pub initial_noise_deg: f64,
    /// Pursuit: the fitted velocity must exceed this many standard errors...
    pub pursuit_sigmas: f64,
    /// ...and this speed (°/s); it is carried at most at `max_pursuit_deg_s`.
    pub min_pursuit_deg_s: f64,
    pub max_pursuit_deg_s: f64,
    /// Median of the amplitude prior before any saccade is seen (degrees).
    pub initial_saccade_deg: f64,
    /// One sample this many jump thresholds out starts a landing prediction (two always do).
    pub confirm_jumps: f64,
    /// Longest a saccade is followed before it counts as a new fixation (seconds).
    pub max_saccade_s: f64,
    /// Consistent samples needed after a blink before the gaze is trusted again.
    pub reacquire_samples: usize,
    pub model: SaccadeModel,
}

impl Default for PredictorParams {
    fn default() -> Self {
        PredictorParams {
            fixation_window_s: 0.05,
            jump_sigmas: 4.5,
            min_jump_deg: 0.8,
            initial_noise_deg: 0.15,
            pursuit_sigmas: 8.0,
            min_pursuit_deg_s: 2.0,
            max_pursuit_deg_s: 40.0,
            initial_saccade_deg: 7.0,
            confirm_jumps: 2.0,
            max_saccade_s: 0.15,
            reacquire_samples: 1,
            model: SaccadeModel::default(),
        }
    }
}

/// The samples of the current fixation.
#[derive(Debug, Clone, Default)]
struct Fixation {
    samples: VecDeque<(f64, DVec2)>,
}

/// A line through the fixation's samples.
#[derive(Debug, Clone, Copy)]
struct Line {
    mean_t: f64,
    mean: DVec2,
    velocity: DVec2,
    /// Standard error of each velocity component (°/s).
    velocity_se: f64,
}

impl Fixation {
    fn mean(&self) -> Option<DVec2> {
        let n = self.samples.len();
        (n > 0).then(|| self.samples.iter().map(|s| s.1).sum::<DVec2>() / n as f64)
    }

    /// Per-axis median: one sample still in flight at the start of a fixation does not drag it.
    fn centre(&self) -> Option<DVec2> {
        let n = self.samples.len();
        if n == 0 {
            return None;
        }
        let median = |f: fn(&DVec2) -> f64| {
            let mut v: Vec<f64> = self.samples.iter().map(|s| f(&s.1)).collect();
            v.sort_by(f64::total_cmp);
            if n % 2 == 1 {
                v[n / 2]
            } else {
                (v[n / 2 - 1] + v[n / 2]) / 2.0
            }
        };
        Some(DVec2::new(median(|p| p.x), median(|p| p.y)))
    }

    fn line(&self, noise_deg: f64) -> Option<Line> {
        let n = self.samples.len();
        if n < 3 {
            return None;
        }
        let mean_t = self.samples.iter().map(|s| s.0).sum::<f64>() / n as f64;
        let mean = self.mean()?;
        let stt: f64 = self.samples.iter().map(|s| (s.0 - mean_t).powi(2)).sum();
        if stt <= 0.0 {
            return None;
        }
        let velocity = self
            .samples
            .iter()
            .map(|s| (s.1 - mean) * (s.0 - mean_t))
            .sum::<DVec2>()
            / stt;
        Some(Line {
            mean_t,
            mean,
            velocity,
            velocity_se: noise_deg / stt.sqrt(),
        })
    }

    /// Per-axis spread of the samples around their line (or mean), when there are enough.
    fn noise(&self) -> Option<f64> {
        let n = self.samples.len();
        if n < 6 {
            return None;
        }
        let line = self.line(1.0)?;
        let ss: f64 = self
            .samples
            .iter()
            .map(|s| (s.1 - line.mean - line.velocity * (s.0 - line.mean_t)).length_squared())
            .sum();
        Some((ss / (2.0 * (n - 2) as f64)).sqrt())
    }

    fn restart(&mut self, t: f64, p: DVec2) {
        self.samples.clear();
        self.samples.push_back((t, p));
    }

    fn add(&mut self, t: f64, p: DVec2, window_s: f64) {
        self.samples.push_back((t, p));
        while self.samples.front().is_some_and(|s| s.0 < t - window_s) {
            self.samples.pop_front();
        }
    }
}

/// A saccade in flight: where it left from and its samples so far.
#[derive(Debug, Clone)]
struct Track {
    start: DVec2,
    /// The fixation's last samples (the onset may lie among them).
    context: Vec<(f64, DVec2)>,
    /// The samples since the eye left.
    samples: Vec<(f64, DVec2)>,
    fit: Option<SaccadeFit>,
}

impl Track {
    /// The fit, once it rests on more than noise: two samples on the way, or one far out.
    fn usable_fit(&self, confirm_deg: f64) -> Option<SaccadeFit> {
        let far = |p: DVec2| (p - self.start).length() >= confirm_deg;
        let confirmed = self.samples.len() >= 2 || self.samples.iter().any(|s| far(s.1));
        self.fit.filter(|_| confirmed)
    }
}

pub struct Predictor {
    mode: PredictMode,
    params: PredictorParams,
    /// The view both eyes share, in angle coordinates: x from `bounds[0]` to `bounds[1]`, y from
    /// `bounds[2]` to `bounds[3]` (degrees).
    bounds: [f64; 4],
    newest: Option<(f64, Option<DVec2>)>,
    last_valid: Option<(XrTime, DVec2)>,
    fixation: Fixation,
    noise_deg: f64,
    track: Option<Track>,
    /// Median of the amplitude prior and the duration relative to the main sequence: learnt from
    /// the saccades seen.
    typical_saccade_deg: f64,
    duration_log: f64,
    /// During a blink and until re-acquired: the position held.
    blink_hold: Option<DVec2>,
    reacquire: Vec<(f64, DVec2)>,
    /// `hold`/`linear`: a sample that left the fixation, until the next tells a move from noise.
    pending: Option<(f64, DVec2)>,
}

fn to_angles(d: Vec3) -> DVec2 {
    let d = d.as_dvec3();
    let forward = (-d.z).max(1e-9);
    DVec2::new(
        d.x.atan2(forward).to_degrees(),
        d.y.atan2(forward).to_degrees(),
    )
}

fn to_direction(a: DVec2) -> Vec3 {
    let (x, y) = (a.x.to_radians().tan(), a.y.to_radians().tan());
    glam::DVec3::new(x, y, -1.0).normalize().as_vec3()
}

fn seconds(t: XrTime) -> f64 {
    t as f64 * 1e-9
}

impl Predictor {
    pub fn new(mode: PredictMode, hmd: &HmdDescription) -> Predictor {
        Predictor::with_params(mode, hmd, PredictorParams::default())
    }

    pub fn with_params(mode: PredictMode, hmd: &HmdDescription, params: PredictorParams) -> Self {
        let deg = |r: f32| (r as f64).to_degrees();
        let [l, r] = [&hmd.eyes[0].fov, &hmd.eyes[1].fov];
        // Directions whose tangents lie in the shared view; the angle coordinates of a tangent
        // are atan of it, i.e. the FOV's own angles.
        let bounds = [
            deg(l.angle_left.max(r.angle_left)),
            deg(l.angle_right.min(r.angle_right)),
            deg(l.angle_down.max(r.angle_down)),
            deg(l.angle_up.min(r.angle_up)),
        ];
        Predictor {
            mode,
            params,
            bounds,
            newest: None,
            last_valid: None,
            fixation: Fixation::default(),
            noise_deg: params.initial_noise_deg,
            track: None,
            typical_saccade_deg: params.initial_saccade_deg,
            duration_log: 0.0,
            blink_hold: None,
            reacquire: Vec::new(),
            pending: None,
        }
    }

    pub fn mode(&self) -> PredictMode {
        self.mode
    }

    fn clamp(&self, a: DVec2) -> DVec2 {
        let b = &self.bounds;
        DVec2::new(a.x.clamp(b[0], b[1]), a.y.clamp(b[2], b[3]))
    }

    fn jump_deg(&self) -> f64 {
        (self.params.jump_sigmas * self.noise_deg).max(self.params.min_jump_deg)
    }

    /// The next tracker sample (times increasing): its measurement time and direction, `None`
    /// when it has no gaze.
    pub fn push(&mut self, time: XrTime, direction: Option<Vec3>) {
        let t = seconds(time);
        let p = direction.filter(|d| d.is_finite()).map(to_angles);
        self.newest = Some((t, p));
        match p {
            Some(p) => {
                self.last_valid = Some((time, p));
                if self.mode != PredictMode::Off {
                    self.on_valid(t, p);
                }
            }
            None => self.on_invalid(),
        }
    }

    fn on_invalid(&mut self) {
        self.pending = None;
        if self.blink_hold.is_none() {
            // A "saccade" that runs into a blink is the lid closing: hold where the eye was.
            let before = self.track.take().map(|t| t.start);
            self.blink_hold = before.or(self.fixation.mean());
        }
        self.reacquire.clear();
    }

    fn on_valid(&mut self, t: f64, p: DVec2) {
        if self.blink_hold.is_some() {
            // Re-acquire: trust the tracker again once it gives consistent samples.
            self.reacquire.push((t, p));
            let n = self.params.reacquire_samples.max(1);
            if self.reacquire.len() < n {
                return;
            }
            let recent = &self.reacquire[self.reacquire.len() - n..];
            let spread = recent
                .iter()
                .map(|s| (s.1 - recent[0].1).length())
                .fold(0.0, f64::max);
            if spread <= self.jump_deg() {
                self.fixation.samples = recent.iter().copied().collect();
                self.blink_hold = None;
                self.reacquire.clear();
            }
            return;
        }
        if self.mode == PredictMode::Saccade && self.track.is_some() {
            self.follow_saccade(t, p);
            return;
        }
        let expected = match self.fixation_line() {
            Some(line) => line.mean + line.velocity * (t - line.mean_t),
            None => match self.fixation.centre() {
                Some(m) => m,
                None => {
                    self.fixation.restart(t, p);
                    return;
                }
            },
        };
        let jump = self.jump_deg();
        if let Some((tp, pp)) = self.pending.take() {
            if (p - pp).length() <= jump {
                // Two samples together away from the fixation: the eye is at a new place.
                self.fixation.restart(tp, pp);
                self.fixation.add(t, p, self.params.fixation_window_s);
                return;
            }
            if (p - expected).length() > jump {
                // Still on the move.
                self.pending = Some((t, p));
                return;
            }
            // Back at the fixation: the sample before was noise.
        }
        if (p - expected).length() > jump {
            if self.mode == PredictMode::Saccade {
                let n = self.fixation.samples.len();
                let mut track = Track {
                    start: expected,
                    context: self
                        .fixation
                        .samples
                        .iter()
                        .skip(n.saturating_sub(2))
                        .copied()
                        .collect(),
                    samples: vec![(t, p)],
                    fit: None,
                };
                self.refit(&mut track);
                self.track = Some(track);
            } else {
                self.pending = Some((t, p));
            }
            return;
        }
        self.fixation.add(t, p, self.params.fixation_window_s);
        if let Some(noise) = self.fixation.noise() {
            self.noise_deg = (0.9 * self.noise_deg + 0.1 * noise).clamp(0.02, 1.0);
        }
    }

    fn refit(&self, track: &mut Track) {
        let all: Vec<(f64, DVec2)> = track
            .context
            .iter()
            .chain(&track.samples)
            .copied()
            .collect();
        track.fit = saccade::fit(
            &self.params.model,
            track.start,
            &all,
            track.samples[0].0,
            &SaccadePrior {
                noise_deg: self.noise_deg,
                amplitude_deg: self.typical_saccade_deg,
                duration_log: self.duration_log,
            },
        );
    }

    fn follow_saccade(&mut self, t: f64, p: DVec2) {
        let Some(mut track) = self.track.take() else {
            return;
        };
        let jump = self.jump_deg();
        let previous = track.samples.last().map_or(p, |s| s.1);
        let reached = track
            .samples
            .iter()
            .map(|s| (s.1 - track.start).length())
            .fold(0.0, f64::max);
        let distance = (p - track.start).length();
        if distance <= jump && reached < self.params.confirm_jumps * jump {
            // Off and back: noise (or a microsaccade), not a saccade.
            self.fixation.add(t, p, self.params.fixation_window_s);
            return;
        }
        let stopped = (p - previous).length() <= jump;
        let ended = track.fit.is_some_and(|f| t >= f.end_s()) && stopped;
        // Turning back by more than the noise: the movement is over (or was never ballistic).
        let turned = distance < reached - jump;
        if ended || turned || t - track.samples[0].0 > self.params.max_saccade_s {
            let amplitude = (previous - track.start).length();
            if let (true, Some(fit)) = (ended && amplitude > 2.0 * jump, track.fit) {
                // The priors follow the saccades seen (geometric running means): their size, and
                // how long this eye and tracker take for one.
                let ln = 0.8 * self.typical_saccade_deg.ln() + 0.2 * amplitude.ln();
                self.typical_saccade_deg = ln.exp();
                let seen = (fit.duration_s / self.params.model.duration_s(fit.amplitude_deg)).ln();
                self.duration_log = 0.8 * self.duration_log + 0.2 * seen;
            }
            self.fixation.restart(t, p);
            return;
        }
        track.samples.push((t, p));
        self.refit(&mut track);
        self.track = Some(track);
    }

    fn fixation_line(&self) -> Option<Line> {
        if self.mode == PredictMode::Hold {
            return None;
        }
        let line = self.fixation.line(self.noise_deg)?;
        let speed = line.velocity.length();
        let significant = speed > self.params.pursuit_sigmas * line.velocity_se
            && speed > self.params.min_pursuit_deg_s;
        significant.then(|| Line {
            velocity: line.velocity * (speed.min(self.params.max_pursuit_deg_s) / speed),
            ..line
        })
    }

    /// The gaze for display time `t` from the samples pushed so far.
    pub fn predict(&self, t: XrTime) -> Prediction {
        let sample_time = self.last_valid.map_or(0, |s| s.0);
        let prediction = |a: Option<DVec2>, motion| Prediction {
            direction: a.map(to_direction),
            hold: None,
            motion,
            sample_time,
            horizon_ns: t - sample_time,
        };
        let newest_valid = self.newest.and_then(|n| n.1);
        if self.mode == PredictMode::Off {
            return prediction(newest_valid, EyeMotion::Newest);
        }
        if let Some(hold) = self.blink_hold {
            let hold = self.clamp(hold);
            return match newest_valid {
                // Re-acquiring: the tracker has gaze again, not yet trusted.
                Some(_) => prediction(Some(hold), EyeMotion::Blink),
                None => Prediction {
                    hold: Some(to_direction(hold)),
                    ..prediction(None, EyeMotion::Blink)
                },
            };
        }
        if newest_valid.is_none() {
            return prediction(None, EyeMotion::Blink);
        }
        let ts = seconds(t);
        if let Some((_, p)) = self.pending {
            return prediction(Some(self.clamp(p)), EyeMotion::Newest);
        }
        if let Some(track) = &self.track {
            let confirm = self.params.confirm_jumps * self.jump_deg();
            // Not yet told from noise: the newest sample, as without prediction.
            let position = match track.usable_fit(confirm) {
                Some(fit) => fit.position(ts),
                None => track.samples[track.samples.len() - 1].1,
            };
            return prediction(Some(self.clamp(position)), EyeMotion::Saccade);
        }
        if let Some(line) = self.fixation_line() {
            let a = line.mean + line.velocity * (ts - line.mean_t);
            return prediction(Some(self.clamp(a)), EyeMotion::Pursuit);
        }
        let centre = self.fixation.centre().or(newest_valid);
        prediction(centre.map(|m| self.clamp(m)), EyeMotion::Fixation)
    }
}
