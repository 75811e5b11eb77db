//! How far the gaze a frame is foveated with lies from where the eye is when the frame is seen:
//! a recording played through the latency model and a predictor ([`DelayedGaze`]), frame by frame
//! at the display rate, each frame's angular error against the recording at its display time
//! (`fovea gaze-eval`; no rendering).

use crate::hmd::angle_between_deg;
use crate::hmd::HmdDescription;
use crate::latency::{DelayedGaze, LatencyModel};
use crate::predict::{PredictMode, Predictor, PredictorParams};
use crate::sample::{Eye, GazeSample, XrTime};
use crate::source::{GazeOrigin, GazeSource};
use crate::trace::{Playback, Trace};
use crate::HalError;
use glam::{DVec2, Vec3};

/// Frame errors above these count in `share_above_2_5` / `share_above_5` (degrees).
pub const THRESHOLDS_DEG: [f64; 2] = [2.5, 5.0];
/// Saccades of at least this amplitude get a landing error (degrees).
pub const MIN_SACCADE_DEG: f64 = 2.5;
/// Tracker history every evaluated frame has (the predictor's warm-up).
const SETTLE_S: f64 = 0.3;
/// Saccades this close to samples without gaze are left out: a closing or opening lid moves the
/// recorded gaze like a saccade.
const BLINK_MARGIN_S: f64 = 0.05;

#[derive(Debug, Clone)]
pub struct EvalSettings {
    pub model: LatencyModel,
    pub display_hz: f64,
    pub mode: PredictMode,
    pub params: PredictorParams,
}

/// A saccade of the recording (detected on all of its samples).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrueSaccade {
    pub onset_s: f64,
    pub end_s: f64,
    pub amplitude_deg: f64,
}

#[derive(Debug, Clone, PartialEq)]
pub struct SaccadeResult {
    pub saccade: TrueSaccade,
    /// Error of the first frame after the landing that could have seen the saccade (displayed at
    /// least latency + two tracker periods after its onset).
    pub landing_error_deg: f64,
    /// Frames from its onset to its end + latency + three tracker periods with error > 2.5°.
    pub frames_above_2_5: usize,
}

#[derive(Debug, Clone, PartialEq)]
pub struct EvalResult {
    /// Frames displayed over the recording, and those evaluated (tracker history, true gaze).
    pub frames: usize,
    pub evaluated: usize,
    pub median_deg: f64,
    pub p95_deg: f64,
    pub p99_deg: f64,
    pub share_above_2_5: f64,
    pub share_above_5: f64,
    /// Frames inside fixations (no saccade or missing gaze from the tracker's samples to the
    /// display time) and their median error.
    pub fixation_frames: usize,
    pub fixation_median_deg: f64,
    pub saccades: Vec<SaccadeResult>,
    /// Saccades of at least [`MIN_SACCADE_DEG`] left out for lying next to a blink.
    pub saccades_near_blinks: usize,
    /// The same statistics for a predictor that knows where the eye is at every display time
    /// except what no tracker sample can have shown yet: a saccade before the first sample 1° on
    /// its way (plus the latency), the eye during samples without gaze. What latency alone costs.
    pub floor: FloorResult,
    /// Frames whose gaze was held over missing samples / the view centre.
    pub held_frames: usize,
    pub centre_frames: usize,
    /// Frames whose gaze lay outside the left eye's image (foveated at its centre instead).
    pub outside_view_frames: usize,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FloorResult {
    pub median_deg: f64,
    pub p95_deg: f64,
    pub p99_deg: f64,
    pub share_above_2_5: f64,
    pub share_above_5: f64,
}

/// A tracker sample must lie this far (degrees) along a saccade to show it (noise of 0.05–0.5°).
const FLOOR_DETECT_DEG: f64 = 1.0;

/// Angles (degrees) of a direction, as the predictor uses them.
fn angles(d: Vec3) -> DVec2 {
    let forward = (-d.z as f64).max(1e-9);
    DVec2::new(
        (d.x as f64).atan2(forward).to_degrees(),
        (d.y as f64).atan2(forward).to_degrees(),
    )
}

/// The `q` quantile (0..=1) of sorted values, linearly interpolated.
pub fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let x = q.clamp(0.0, 1.0) * (sorted.len() - 1) as f64;
    let (i, f) = (x.floor() as usize, x.fract());
    let next = sorted[(i + 1).min(sorted.len() - 1)];
    sorted[i] + (next - sorted[i]) * f
}

/// Saccades in `samples` (times from the first sample): velocity of the positions smoothed over
/// ±4 ms above a threshold set by the recording's own noise (at least 30 °/s, peak at least
/// 75 °/s), amplitude between the 10 ms before and after. Returns them and whether each lies
/// next to missing gaze.
pub fn detect_saccades(samples: &[GazeSample]) -> Vec<(TrueSaccade, bool)> {
    let n = samples.len();
    if n < 5 {
        return Vec::new();
    }
    let t0 = samples[0].time;
    let time = |i: usize| (samples[i].time - t0) as f64 * 1e-9;
    let pos: Vec<Option<DVec2>> = samples
        .iter()
        .map(|s| s.valid.then(|| angles(s.gaze.direction)))
        .collect();
    let mut dts: Vec<f64> = (1..n).map(|i| time(i) - time(i - 1)).collect();
    dts.sort_by(f64::total_cmp);
    let period = dts[dts.len() / 2].max(1e-4);
    let w = ((0.004 / period).round() as usize).max(1);
    let smooth: Vec<Option<DVec2>> = (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(w), (i + w + 1).min(n));
            let window = &pos[a..b];
            if pos[i].is_none() || window.iter().any(Option::is_none) {
                return None;
            }
            Some(window.iter().flatten().sum::<DVec2>() / window.len() as f64)
        })
        .collect();
    let speed: Vec<Option<f64>> = (0..n)
        .map(|i| {
            let (a, b) = (i.checked_sub(1)?, i + 1);
            let (pa, pb) = (smooth[a]?, (*smooth.get(b)?)?);
            Some((pb - pa).length() / (time(b) - time(a)))
        })
        .collect();
    let mut speeds: Vec<f64> = speed.iter().flatten().copied().collect();
    speeds.sort_by(f64::total_cmp);
    let typical = quantile(&speeds, 0.5);
    let (on, peak) = ((3.0 * typical).max(30.0), (6.0 * typical).max(75.0));
    let invalid_near = |a: f64, b: f64| {
        (0..n).any(|i| {
            !samples[i].valid && time(i) >= a - BLINK_MARGIN_S && time(i) <= b + BLINK_MARGIN_S
        })
    };
    let mean_over = |a: f64, b: f64| {
        let v: Vec<DVec2> = (0..n)
            .filter(|&i| time(i) >= a && time(i) <= b)
            .filter_map(|i| pos[i])
            .collect();
        (!v.is_empty()).then(|| v.iter().sum::<DVec2>() / v.len() as f64)
    };
    let mut out = Vec::new();
    let mut i = 0;
    while i < n {
        if speed[i].is_none_or(|v| v < on) {
            i += 1;
            continue;
        }
        let start = i;
        let mut top = 0.0f64;
        while i < n && speed[i].is_some_and(|v| v >= on) {
            top = top.max(speed[i].unwrap_or(0.0));
            i += 1;
        }
        let (onset, end) = (time(start), time(i.min(n - 1)));
        if top < peak {
            continue;
        }
        let (Some(before), Some(after)) =
            (mean_over(onset - 0.010, onset), mean_over(end, end + 0.010))
        else {
            continue;
        };
        let saccade = TrueSaccade {
            onset_s: onset,
            end_s: end,
            amplitude_deg: (after - before).length(),
        };
        out.push((saccade, invalid_near(onset, end)));
    }
    out
}

/// Whether `d` shows on the left eye's image (one pixel of slack, as the renderer allows).
fn on_view(hmd: &HmdDescription, d: Vec3) -> bool {
    let eye = hmd.eye(Eye::Left);
    let (w, h) = (eye.recommended_width as f32, eye.recommended_height as f32);
    eye.direction_to_pixel(d)
        .is_some_and(|p| (-1.0..=w + 1.0).contains(&p.x) && (-1.0..=h + 1.0).contains(&p.y))
}

/// Plays `trace` through the latency model and predictor of `settings` on `hmd`'s view.
pub fn evaluate(
    trace: &Trace,
    hmd: &HmdDescription,
    settings: &EvalSettings,
) -> Result<EvalResult, HalError> {
    let first = trace.samples[0].time;
    let duration_s = (trace.samples[trace.samples.len() - 1].time - first) as f64 * 1e-9;
    let mut source = Playback::new(trace.clone(), hmd.clone()).with_time_offset(-first);
    let mut truth_source = Playback::new(trace.clone(), hmd.clone()).with_time_offset(-first);
    let mut truth_at = |t_s: f64| {
        let s = truth_source.sample_at((t_s * 1e9).round() as XrTime);
        s.valid.then_some(s.gaze.direction.normalize())
    };
    let predictor = Predictor::with_params(settings.mode, hmd, settings.params);
    let mut delayed = DelayedGaze::with_predictor(settings.model.clone(), predictor);
    let latency_s = settings.model.total_ms() * 1e-3;
    let period_s = 1.0 / settings.model.tracker_hz;
    let frames = (duration_s * settings.display_hz).floor() as usize + 1;
    let all_saccades = detect_saccades(&trace.samples);
    // Per saccade: where it left from and until when no frame can know of it.
    let unknowable: Vec<(f64, f64, Vec3)> = all_saccades
        .iter()
        .filter_map(|(s, _)| {
            let from = truth_at(s.onset_s)?;
            let mut k = (s.onset_s / period_s).ceil();
            while k * period_s <= s.end_s + period_s {
                let shown = truth_at(k * period_s)
                    .is_some_and(|d| angle_between_deg(d, from) as f64 >= FLOOR_DETECT_DEG);
                if shown {
                    break;
                }
                k += 1.0;
            }
            Some((s.onset_s, k * period_s + latency_s, from))
        })
        .collect();
    let mut floor_errors = Vec::new();
    let invalid_times: Vec<f64> = trace
        .samples
        .iter()
        .filter(|s| !s.valid)
        .map(|s| (s.time - first) as f64 * 1e-9)
        .collect();
    // (display time, error) of evaluated frames.
    let mut errors: Vec<(f64, f64)> = Vec::new();
    let mut fixation = Vec::new();
    let (mut held, mut centre, mut outside) = (0, 0, 0);
    for i in 0..frames {
        let t_s = i as f64 / settings.display_hz;
        let t: XrTime = (t_s * 1e9).round() as XrTime;
        let frame = delayed.frame(&mut source, t)?;
        if t_s < latency_s + SETTLE_S || !frame.truth.valid {
            continue;
        }
        let mut used = frame.resolved.direction;
        if !on_view(hmd, used) {
            // The renderer foveates at the centre then (`project_gaze`).
            outside += 1;
            used = Vec3::NEG_Z;
        }
        match frame.resolved.source {
            GazeOrigin::Held => held += 1,
            GazeOrigin::Centre => centre += 1,
            GazeOrigin::Live => {}
        }
        let truth = frame.truth.gaze.direction.normalize();
        let error = angle_between_deg(used, truth) as f64;
        errors.push((t_s, error));
        // The floor: the newest tick's gaze if it had none (a blink), else the eye itself unless
        // a saccade cannot have been seen yet.
        let newest = settings.model.tick_time(settings.model.newest_tick(t)) as f64 * 1e-9;
        let floor_gaze = match truth_at(newest) {
            None => {
                let mut k = newest;
                let mut last = None;
                while k > newest - 1.0 && last.is_none() {
                    k -= period_s;
                    last = truth_at(k);
                }
                last.unwrap_or(Vec3::NEG_Z)
            }
            Some(_) => unknowable
                .iter()
                .find(|u| u.0 <= t_s && t_s < u.1)
                .map_or(truth, |u| u.2),
        };
        floor_errors.push(angle_between_deg(floor_gaze, truth) as f64);
        let window = (t_s - latency_s - 2.0 * period_s - 0.03, t_s);
        let disturbed = all_saccades
            .iter()
            .any(|(s, _)| s.onset_s <= window.1 && s.end_s >= window.0)
            || invalid_times
                .iter()
                .any(|&v| v >= window.0 && v <= window.1);
        if !disturbed {
            fixation.push(error);
        }
    }
    let mut sorted: Vec<f64> = errors.iter().map(|e| e.1).collect();
    sorted.sort_by(f64::total_cmp);
    fixation.sort_by(f64::total_cmp);
    floor_errors.sort_by(f64::total_cmp);
    let floor_share = |limit: f64| {
        floor_errors.iter().filter(|&&e| e > limit).count() as f64
            / floor_errors.len().max(1) as f64
    };
    let floor = FloorResult {
        median_deg: quantile(&floor_errors, 0.5),
        p95_deg: quantile(&floor_errors, 0.95),
        p99_deg: quantile(&floor_errors, 0.99),
        share_above_2_5: floor_share(THRESHOLDS_DEG[0]),
        share_above_5: floor_share(THRESHOLDS_DEG[1]),
    };
    let share = |limit: f64| {
        sorted.iter().filter(|&&e| e > limit).count() as f64 / sorted.len().max(1) as f64
    };
    let mut saccades = Vec::new();
    let mut near_blinks = 0;
    for &(s, blink) in &all_saccades {
        if s.amplitude_deg < MIN_SACCADE_DEG || s.onset_s < latency_s + SETTLE_S {
            continue;
        }
        if blink {
            near_blinks += 1;
            continue;
        }
        let informed = s.end_s.max(s.onset_s + latency_s + 2.0 * period_s);
        let Some(&(_, landing)) = errors.iter().find(|e| e.0 >= informed) else {
            continue;
        };
        let until = s.end_s + latency_s + 3.0 * period_s;
        let above = errors
            .iter()
            .filter(|e| e.0 >= s.onset_s && e.0 <= until && e.1 > THRESHOLDS_DEG[0])
            .count();
        saccades.push(SaccadeResult {
            saccade: s,
            landing_error_deg: landing,
            frames_above_2_5: above,
        });
    }
    Ok(EvalResult {
        frames,
        evaluated: sorted.len(),
        median_deg: quantile(&sorted, 0.5),
        p95_deg: quantile(&sorted, 0.95),
        p99_deg: quantile(&sorted, 0.99),
        share_above_2_5: share(THRESHOLDS_DEG[0]),
        share_above_5: share(THRESHOLDS_DEG[1]),
        fixation_frames: fixation.len(),
        fixation_median_deg: quantile(&fixation, 0.5),
        saccades,
        saccades_near_blinks: near_blinks,
        floor,
        held_frames: held,
        centre_frames: centre,
        outside_view_frames: outside,
    })
}
