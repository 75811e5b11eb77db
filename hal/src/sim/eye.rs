//! The noise-free eye: fixations (with drift and microsaccades), main-sequence saccades, smooth
//! pursuit with catch-up saccades, and a blink schedule. Time is seconds since tracker tick 0.

use super::config::{ScriptMotion, SimConfig};
use super::motion::{
    angle, direction_from_angles, offset_direction, Glide, Move, MIN_JERK_PEAK_SLOPE,
};
use glam::{DQuat, DVec2, DVec3};
use rand::Rng;
use rand_distr::{Distribution, Exp, Gamma, StandardNormal};
use rand_pcg::Pcg64;

/// What the eye is doing at a time (ground truth for tests and demos).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EyePhase {
    Fixation,
    Microsaccade,
    Saccade,
    Pursuit,
}

#[derive(Debug, Clone, Copy)]
struct Micro {
    start: f64,
    duration: f64,
    from: DVec2,
    to: DVec2,
}

#[derive(Debug, Clone, Copy)]
enum State {
    Fixating {
        target: DVec3,
        offset: DVec2,
        until: f64,
        next_micro: f64,
        micro: Option<Micro>,
    },
    /// `resume`: the pursuit a catch-up saccade interrupted.
    Saccading {
        mv: Move,
        resume: Option<Glide>,
    },
    Pursuing {
        glide: Glide,
        eye: DVec3,
    },
}

pub struct EyeModel {
    cfg: SimConfig,
    rng: Pcg64,
    fixation_durations: Gamma<f64>,
    state: State,
    /// Next script step to act on.
    script_index: usize,
    last_t: f64,
    direction: DVec3,
}

impl EyeModel {
    pub fn new(cfg: &SimConfig, rng: Pcg64) -> Self {
        let shape = (cfg.fixation_mean_ms / cfg.fixation_sd_ms).powi(2);
        let scale = cfg.fixation_sd_ms.powi(2) / cfg.fixation_mean_ms;
        let mut model = EyeModel {
            cfg: cfg.clone(),
            rng,
            // Validated config guarantees shape, scale > 0.
            fixation_durations: Gamma::new(shape, scale).expect("validated gamma parameters"),
            state: State::Saccading {
                mv: Move {
                    start: 0.0,
                    duration: 1.0,
                    from: DVec3::NEG_Z,
                    to: DVec3::NEG_Z,
                },
                resume: None,
            },
            script_index: 0,
            last_t: 0.0,
            direction: DVec3::NEG_Z,
        };
        model.start_fixation(0.0, DVec3::NEG_Z);
        model
    }

    /// Eye direction and phase at `t` (must not decrease between calls).
    pub fn advance(&mut self, t: f64) -> (DVec3, EyePhase) {
        self.apply_transitions(t);
        let dt = (t - self.last_t).max(0.0);
        self.last_t = t;
        let phase = match self.state {
            State::Fixating { .. } => self.evaluate_fixation(t, dt),
            State::Saccading { mv, .. } => {
                self.direction = mv.at(t);
                EyePhase::Saccade
            }
            State::Pursuing { glide, eye } => self.evaluate_pursuit(t, dt, glide, eye),
        };
        (self.direction, phase)
    }

    fn apply_transitions(&mut self, t: f64) {
        // Bounded: every transition either moves time forward or consumes a script step.
        for _ in 0..10_000 {
            match self.state {
                State::Fixating { until, target, .. } if t >= until => {
                    self.end_fixation(until, target)
                }
                State::Saccading { mv, resume } if t >= mv.end() => self.end_saccade(mv, resume),
                State::Pursuing { glide, eye } if t >= glide.end => self.end_pursuit(glide, eye),
                _ => return,
            }
        }
    }

    fn start_fixation(&mut self, at: f64, target: DVec3) {
        let until = if self.cfg.script.is_empty() {
            at + self.fixation_durations.sample(&mut self.rng) / 1000.0
        } else {
            self.next_script_action_time()
        };
        let next_micro = at + self.exponential(self.cfg.microsaccade_rate_hz);
        self.state = State::Fixating {
            target,
            offset: DVec2::ZERO,
            until,
            next_micro,
            micro: None,
        };
        self.direction = target;
        self.last_t = at;
    }

    fn next_script_action_time(&self) -> f64 {
        let Some(step) = self.cfg.script.get(self.script_index) else {
            return f64::INFINITY;
        };
        match step.motion {
            ScriptMotion::Jump => (step.time_ms + self.cfg.saccade_latency_ms) / 1000.0,
            ScriptMotion::Pursue => self.script_glide_start(),
        }
    }

    fn script_glide_start(&self) -> f64 {
        self.script_index
            .checked_sub(1)
            .map_or(0.0, |i| self.cfg.script[i].time_ms / 1000.0)
    }

    fn end_fixation(&mut self, at: f64, target: DVec3) {
        let from = self.direction;
        if let Some(step) = self.cfg.script.get(self.script_index).copied() {
            let goal = direction_from_angles(step.azimuth_deg, step.elevation_deg);
            let start = self.script_glide_start();
            self.script_index += 1;
            match step.motion {
                ScriptMotion::Jump => self.start_saccade(at, from, goal, None),
                ScriptMotion::Pursue => {
                    let glide = Glide {
                        start,
                        end: step.time_ms / 1000.0,
                        from: target,
                        to: goal,
                    };
                    self.state = State::Pursuing { glide, eye: from };
                    self.last_t = at;
                }
            }
            return;
        }
        let goal = self.random_target();
        if self.rng.random::<f64>() < self.cfg.pursuit_probability {
            let [lo, hi] = self.cfg.pursuit_speed_deg_s;
            let speed = self.rng.random_range(lo..=hi);
            let duration = angle(target, goal).to_degrees() / speed;
            self.state = State::Pursuing {
                glide: Glide {
                    start: at,
                    end: at + duration,
                    from: target,
                    to: goal,
                },
                eye: from,
            };
            self.last_t = at;
        } else {
            self.start_saccade(at, from, goal, None);
        }
    }

    fn start_saccade(&mut self, at: f64, from: DVec3, to: DVec3, resume: Option<Glide>) {
        let amplitude = angle(from, to).to_degrees();
        if amplitude < 1e-6 {
            return self.start_fixation(at, to);
        }
        let duration = self.saccade_duration(amplitude);
        self.state = State::Saccading {
            mv: Move {
                start: at,
                duration,
                from,
                to,
            },
            resume,
        };
        self.last_t = at;
    }

    /// Duration that makes a minimum-jerk movement reach the main-sequence peak velocity.
    /// (hal.md's 2.2 ms/°·A + 21 ms cannot hold together with the peak-velocity formula for a
    /// smooth profile; the peak velocity is what the renderer's motion depends on, so it wins.)
    fn saccade_duration(&self, amplitude_deg: f64) -> f64 {
        MIN_JERK_PEAK_SLOPE * amplitude_deg / self.cfg.main_sequence_peak_velocity(amplitude_deg)
    }

    fn end_saccade(&mut self, mv: Move, resume: Option<Glide>) {
        self.direction = mv.to;
        match resume {
            Some(glide) if glide.end > mv.end() => {
                self.state = State::Pursuing { glide, eye: mv.to };
                self.last_t = mv.end();
            }
            _ => self.start_fixation(mv.end(), mv.to),
        }
    }

    fn end_pursuit(&mut self, glide: Glide, eye: DVec3) {
        self.direction = eye;
        // A small residual error is absorbed into the fixation; a large one needs a saccade.
        if angle(eye, glide.to).to_degrees() > 0.5 {
            self.start_saccade(glide.end, eye, glide.to, None);
        } else {
            self.start_fixation(glide.end, eye);
        }
    }

    fn evaluate_fixation(&mut self, t: f64, dt: f64) -> EyePhase {
        let State::Fixating {
            target,
            mut offset,
            until,
            mut next_micro,
            mut micro,
        } = self.state
        else {
            return EyePhase::Fixation;
        };
        if micro.is_none() && t >= next_micro {
            micro = Some(self.plan_microsaccade(next_micro, offset));
        }
        let mut phase = EyePhase::Fixation;
        match micro {
            Some(m) if t < m.start + m.duration => {
                offset =
                    m.from + (m.to - m.from) * super::motion::min_jerk((t - m.start) / m.duration);
                phase = EyePhase::Microsaccade;
            }
            Some(m) => {
                offset = m.to;
                micro = None;
                next_micro = m.start + m.duration + self.exponential(self.cfg.microsaccade_rate_hz);
            }
            None => offset = self.drift(offset, dt),
        }
        self.state = State::Fixating {
            target,
            offset,
            until,
            next_micro,
            micro,
        };
        self.direction = offset_direction(target, offset);
        phase
    }

    fn plan_microsaccade(&mut self, start: f64, from: DVec2) -> Micro {
        let [lo, hi] = self.cfg.microsaccade_amplitude_deg;
        let amplitude = if hi > lo {
            self.rng.random_range(lo..=hi)
        } else {
            lo
        };
        let heading = self.rng.random_range(0.0..std::f64::consts::TAU);
        let step = DVec2::new(heading.cos(), heading.sin()) * amplitude;
        // Microsaccades are corrective: never carry the eye further than `hi` from the target.
        let to = if (from + step).length() > hi {
            from - step
        } else {
            from + step
        };
        let duration = self.saccade_duration(amplitude.max(1e-3));
        Micro {
            start,
            duration,
            from,
            to,
        }
    }

    /// Exact Ornstein–Uhlenbeck step, valid for any dt.
    fn drift(&mut self, offset: DVec2, dt: f64) -> DVec2 {
        let decay = (-dt * 1000.0 / self.cfg.drift_time_constant_ms).exp();
        let sd = self.cfg.drift_sd_deg * (1.0 - decay * decay).sqrt();
        let n = DVec2::new(
            self.rng.sample(StandardNormal),
            self.rng.sample(StandardNormal),
        );
        offset * decay + n * sd
    }

    fn evaluate_pursuit(&mut self, t: f64, dt: f64, glide: Glide, mut eye: DVec3) -> EyePhase {
        if let Some((speed, axis)) = glide.velocity() {
            let eye_speed =
                (speed * self.cfg.pursuit_gain).min(self.cfg.pursuit_max_speed_deg_s.to_radians());
            if t > glide.start {
                eye = (DQuat::from_axis_angle(axis, eye_speed * dt) * eye).normalize();
            }
        }
        self.direction = eye;
        self.state = State::Pursuing { glide, eye };
        if angle(eye, glide.at(t)).to_degrees() > self.cfg.catch_up_threshold_deg {
            // Aim where the target will be when the saccade lands.
            let rough = self.saccade_duration(angle(eye, glide.at(t)).to_degrees());
            let aim = glide.at(t + rough);
            self.start_saccade(t, eye, aim, Some(glide));
            return EyePhase::Saccade;
        }
        EyePhase::Pursuit
    }

    fn random_target(&mut self) -> DVec3 {
        let [az, el] = self.cfg.target_range_deg;
        let a = if az > 0.0 {
            self.rng.random_range(-az..=az)
        } else {
            0.0
        };
        let e = if el > 0.0 {
            self.rng.random_range(-el..=el)
        } else {
            0.0
        };
        direction_from_angles(a, e)
    }

    fn exponential(&mut self, rate_hz: f64) -> f64 {
        match Exp::new(rate_hz) {
            Ok(d) if rate_hz > 0.0 => d.sample(&mut self.rng),
            _ => f64::INFINITY,
        }
    }
}

/// Blinks as an independent renewal process: gap (exponential) then duration (uniform), tuned so
/// the long-run rate equals `blink_rate_per_min`.
pub struct BlinkSchedule {
    rng: Pcg64,
    mean_gap_s: f64,
    duration_ms: [f64; 2],
    start: f64,
    end: f64,
}

impl BlinkSchedule {
    pub fn new(cfg: &SimConfig, rng: Pcg64) -> Self {
        let mean_gap_s = if cfg.blink_rate_per_min > 0.0 {
            60.0 / cfg.blink_rate_per_min - cfg.mean_blink_ms() / 1000.0
        } else {
            f64::INFINITY
        };
        let mut s = BlinkSchedule {
            rng,
            mean_gap_s,
            duration_ms: cfg.blink_duration_ms,
            start: 0.0,
            end: 0.0,
        };
        s.schedule_after(0.0);
        s
    }

    fn schedule_after(&mut self, t: f64) {
        let gap = if self.mean_gap_s.is_finite() {
            Exp::new(1.0 / self.mean_gap_s).map_or(f64::INFINITY, |d| d.sample(&mut self.rng))
        } else {
            f64::INFINITY
        };
        let [lo, hi] = self.duration_ms;
        let duration = if hi > lo {
            self.rng.random_range(lo..=hi)
        } else {
            lo
        } / 1000.0;
        self.start = t + gap;
        self.end = self.start + duration;
    }

    /// Whether the eyes are closed at `t` (must not decrease between calls).
    pub fn blinking(&mut self, t: f64) -> bool {
        while t >= self.end {
            let after = self.end;
            self.schedule_after(after);
        }
        t >= self.start
    }
}
