//! Trace playback as a [`GazeSource`], with OpenXR-style clamp / interpolate semantics.

use super::Trace;
use crate::error::HalError;
use crate::hmd::HmdDescription;
use crate::sample::{GazeRay, GazeSample, SampleTimeKind, XrTime};
use crate::source::GazeSource;
use std::path::Path;

pub struct Playback {
    hmd: HmdDescription,
    trace: Trace,
    /// Sample times alone: a compact array keeps the binary search in cache.
    times: Vec<XrTime>,
    /// Index found by the previous query; frame-by-frame queries hit it or its neighbour.
    cursor: usize,
    /// Added to trace times to map them onto the session clock.
    time_offset: i64,
    align_on_first_frame: bool,
    /// Neighbours further apart than this are a tracking gap: never interpolated across.
    max_gap_ns: i64,
    now: Option<XrTime>,
}

impl Playback {
    pub fn new(trace: Trace, hmd: HmdDescription) -> Self {
        let max_gap_ns = trace.header.period_ns().saturating_mul(3) / 2;
        let times = trace.samples.iter().map(|s| s.time).collect();
        Playback {
            hmd,
            trace,
            times,
            cursor: 0,
            time_offset: 0,
            align_on_first_frame: false,
            max_gap_ns,
            now: None,
        }
    }

    pub fn open(path: &Path, hmd: HmdDescription) -> Result<Self, HalError> {
        Ok(Playback::new(Trace::load(path)?, hmd))
    }

    pub fn trace(&self) -> &Trace {
        &self.trace
    }

    /// Shift trace times by `offset` ns (returned samples carry shifted times).
    pub fn with_time_offset(mut self, offset: i64) -> Self {
        self.time_offset = offset;
        self
    }

    /// Make the first `begin_frame` time correspond to the trace's first sample.
    pub fn aligned_to_first_frame(mut self) -> Self {
        self.align_on_first_frame = true;
        self
    }

    pub fn max_gap_ns(&self) -> i64 {
        self.max_gap_ns
    }

    fn shifted(&self, s: &GazeSample) -> GazeSample {
        GazeSample {
            time: s.time.saturating_add(self.time_offset),
            ..*s
        }
    }

    /// Trace semantics in trace time (no offset): exact hit → that sample; before/after the
    /// recording → first/last (clamped, real time kept); between two valid samples no further
    /// apart than 1.5 tracker periods → interpolated at `t`; next to an invalid sample → the
    /// earlier sample as is (never interpolate across invalid data); inside a longer gap → the
    /// earlier sample for up to 1.5 periods, then "no gaze".
    fn lookup(&mut self, t: XrTime) -> GazeSample {
        let i = self.partition(t);
        let s = &self.trace.samples;
        if i == 0 {
            return s[0];
        }
        let a = &s[i - 1];
        if a.time == t || i == s.len() {
            return *a;
        }
        let b = &s[i];
        if b.time - a.time > self.max_gap_ns {
            return if t - a.time <= self.max_gap_ns {
                *a
            } else {
                GazeSample::no_gaze(t, a.sequence)
            };
        }
        if !(a.valid && b.valid) {
            return *a;
        }
        interpolate(a, b, t)
    }

    /// Number of samples with time ≤ t, trying the previous answer first.
    fn partition(&mut self, t: XrTime) -> usize {
        let times = &self.times;
        let c = self.cursor;
        let fits = |i: usize| (i == 0 || times[i - 1] <= t) && (i == times.len() || times[i] > t);
        let i = if fits(c) {
            c
        } else if c < times.len() && fits(c + 1) {
            c + 1
        } else {
            times.partition_point(|&x| x <= t)
        };
        self.cursor = i;
        i
    }
}

fn interpolate(a: &GazeSample, b: &GazeSample, t: XrTime) -> GazeSample {
    let w = (t - a.time) as f64 / (b.time - a.time) as f64;
    let wf = w as f32;
    let ray = |ra: &GazeRay, rb: &GazeRay| GazeRay {
        origin: ra.origin.lerp(rb.origin, wf),
        direction: ra
            .direction
            .lerp(rb.direction, wf)
            .normalize_or(ra.direction),
    };
    let lerp_opt = |x: Option<f32>, y: Option<f32>| match (x, y) {
        (Some(x), Some(y)) => Some(x + (y - x) * wf),
        _ => None,
    };
    let nearer = if w < 0.5 { a } else { b };
    GazeSample {
        time: t,
        time_kind: SampleTimeKind::Interpolated,
        sequence: a.sequence,
        gaze: ray(&a.gaze, &b.gaze),
        eyes: match (&a.eyes, &b.eyes) {
            (Some([al, ar]), Some([bl, br])) => Some([ray(al, bl), ray(ar, br)]),
            _ => None,
        },
        valid: true,
        tracked: a.tracked && b.tracked,
        eye_state: nearer.eye_state,
        confidence: lerp_opt(a.confidence, b.confidence),
        convergence_distance: lerp_opt(a.convergence_distance, b.convergence_distance),
    }
}

impl GazeSource for Playback {
    fn describe(&self) -> &HmdDescription {
        &self.hmd
    }

    fn begin_frame(&mut self, predicted_display_time: XrTime) -> Result<(), HalError> {
        if self.align_on_first_frame && self.now.is_none() {
            self.time_offset = predicted_display_time - self.trace.samples[0].time;
        }
        self.now = Some(predicted_display_time);
        Ok(())
    }

    fn sample_at(&mut self, t: XrTime) -> GazeSample {
        let s = self.lookup(t.saturating_sub(self.time_offset));
        self.shifted(&s)
    }

    /// The newest recorded sample at or before the current frame time (never interpolated).
    fn latest(&self) -> GazeSample {
        let samples = &self.trace.samples;
        let t = self
            .now
            .map_or(samples[0].time, |n| n.saturating_sub(self.time_offset));
        let i = self.times.partition_point(|&x| x <= t).saturating_sub(1);
        self.shifted(&samples[i])
    }
}
