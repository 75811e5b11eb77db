//! The gaze-to-photon latency model: a frame displayed at time T was foveated with the tracker
//! samples measured up to T − L, where L is the tracker's delay plus render and display latency
//! (the headset profile's `[tracker] latency_ms` and `[latency]`, or `--latency-ms` for the whole
//! sum), and the tracker samples the eye at its own rate. [`DelayedGaze`] runs a gaze source
//! through the model, a [`Predictor`] and the invalid-gaze policy, so offline runs (`fovea
//! render`, `replay`, `quality`, `gaze-eval`) see what a headset would, and keeps the source's
//! own gaze at the display time as the truth the frame is judged against.

use crate::error::HalError;
use crate::hmd::HmdDescription;
use crate::predict::{PredictMode, Prediction, Predictor};
use crate::sample::{GazeSample, SampleTimeKind, XrTime, NANOS_PER_MILLI};
use crate::source::{GazeSource, InvalidGazePolicy, ResolvedGaze};

/// Largest latency accepted (ms): a second is far beyond any headset (45–81 ms measured).
pub const MAX_LATENCY_MS: f64 = 1000.0;
/// Tracker rates accepted (Hz).
pub const MAX_TRACKER_HZ: f64 = 10_000.0;
/// How much tracker history a [`DelayedGaze`] feeds its predictor before the first frame (ms).
const WARM_UP_MS: f64 = 300.0;

#[derive(Debug, Clone, PartialEq)]
pub struct LatencyModel {
    pub tracker_hz: f64,
    /// Measurement → available to the application (`[tracker] latency_ms`).
    pub tracker_ms: f64,
    /// Available → frame finished (`[latency] render_ms`).
    pub render_ms: f64,
    /// Frame finished → photons (`[latency] display_ms`).
    pub display_ms: f64,
    /// `--latency-ms`: the whole sample-to-photon latency instead of the sum.
    pub total_override_ms: Option<f64>,
}

impl LatencyModel {
    /// The model of `hmd`'s profile; `total_ms` (`--latency-ms`) replaces the sum and
    /// `tracker_hz` (`--tracker-hz`) the profile's rate. A profile without `[latency]` needs
    /// `total_ms`.
    pub fn for_headset(
        hmd: &HmdDescription,
        total_ms: Option<f64>,
        tracker_hz: Option<f64>,
    ) -> Result<LatencyModel, HalError> {
        let flag = |flag: &'static str, reason: String| HalError::Flag { flag, reason };
        if let Some(l) = total_ms {
            if !(0.0..=MAX_LATENCY_MS).contains(&l) {
                return Err(flag(
                    "--latency-ms",
                    format!("{l} must be a number of milliseconds in 0..={MAX_LATENCY_MS}"),
                ));
            }
        }
        if let Some(r) = tracker_hz {
            // Below 1 Hz the model replays years of tracker samples per second shown.
            if !(r >= crate::hmd::MIN_RATE_HZ as f64 && r <= MAX_TRACKER_HZ) {
                return Err(flag(
                    "--tracker-hz",
                    format!("{r} must be a rate in Hz, >= 1 and <= {MAX_TRACKER_HZ}"),
                ));
            }
        }
        let pipeline = match (hmd.latency, total_ms) {
            (Some(p), _) => p,
            (None, Some(_)) => crate::hmd::PipelineLatency {
                render_ms: 0.0,
                display_ms: 0.0,
            },
            (None, None) => {
                return Err(flag(
                    "--latency-ms",
                    format!(
                        "headset `{}` has no [latency] section (render_ms, display_ms): add one \
                         to its profile or give the total latency",
                        hmd.id
                    ),
                ))
            }
        };
        // The profile's decimal figures as written (14.3, not 14.300000190734863).
        let decimal = |v: f32| v.to_string().parse::<f64>().unwrap_or(v as f64);
        Ok(LatencyModel {
            tracker_hz: tracker_hz.unwrap_or(decimal(hmd.tracker.rate_hz)),
            tracker_ms: decimal(hmd.tracker.latency_ms),
            render_ms: decimal(pipeline.render_ms),
            display_ms: decimal(pipeline.display_ms),
            total_override_ms: total_ms,
        })
    }

    /// Sample-to-photon latency in milliseconds.
    pub fn total_ms(&self) -> f64 {
        self.total_override_ms
            .unwrap_or(self.tracker_ms + self.render_ms + self.display_ms)
    }

    pub fn total_ns(&self) -> i64 {
        (self.total_ms() * NANOS_PER_MILLI).round() as i64
    }

    pub fn tracker_period_ns(&self) -> f64 {
        1e9 / self.tracker_hz
    }

    /// When the tracker takes sample `k` (k · period from the source's time 0).
    pub fn tick_time(&self, k: i64) -> XrTime {
        (k as f64 * self.tracker_period_ns()).round() as XrTime
    }

    /// The newest tracker sample a frame displayed at `display_time` can have used.
    pub fn newest_tick(&self, display_time: XrTime) -> i64 {
        let available = display_time - self.total_ns();
        let mut k = (available as f64 / self.tracker_period_ns()).floor() as i64;
        // Rounding of tick times: the tick must not lie after `available`.
        while self.tick_time(k) > available {
            k -= 1;
        }
        while self.tick_time(k + 1) <= available {
            k += 1;
        }
        k
    }

    /// One line for reports: "50.0 ms (tracker 20 + render 14.3 + display 10.7), tracker 120 Hz".
    pub fn describe(&self) -> String {
        let parts = format!(
            "tracker {} + render {} + display {}",
            self.tracker_ms, self.render_ms, self.display_ms
        );
        match self.total_override_ms {
            Some(l) => format!(
                "{l} ms (--latency-ms; the profile's {parts}), tracker {} Hz",
                self.tracker_hz
            ),
            None => format!(
                "{:.1} ms ({parts}), tracker {} Hz",
                self.total_ms(),
                self.tracker_hz
            ),
        }
    }
}

/// One displayed frame under the model.
#[derive(Debug, Clone, Copy)]
pub struct DelayedFrame {
    pub display_time: XrTime,
    /// What the frame uses: the prediction after the invalid-gaze policy.
    pub resolved: ResolvedGaze,
    pub prediction: Prediction,
    /// The source's own gaze at the display time: where the eye is when the frame is seen (a
    /// live source's own sample, which is all there is).
    pub truth: GazeSample,
}

/// A gaze source seen through the latency model: tracker samples at the model's rate, each frame
/// foveated with the prediction from those measured up to its display time − latency. Or, for a
/// live tracker whose latency is real (an OpenXR runtime), [`DelayedGaze::live`]: the predictor
/// takes each new sample the source gives and predicts to the display time.
pub struct DelayedGaze {
    /// `None`: live.
    model: Option<LatencyModel>,
    predictor: Predictor,
    policy: InvalidGazePolicy,
    /// The next tracker tick to feed the predictor.
    next_tick: Option<i64>,
    /// Live: the time of the newest sample fed.
    newest_live: Option<XrTime>,
}

impl DelayedGaze {
    pub fn new(model: LatencyModel, mode: PredictMode, hmd: &HmdDescription) -> DelayedGaze {
        DelayedGaze::with_predictor(model, Predictor::new(mode, hmd))
    }

    pub fn with_predictor(model: LatencyModel, predictor: Predictor) -> DelayedGaze {
        DelayedGaze {
            model: Some(model),
            predictor,
            policy: InvalidGazePolicy::default(),
            next_tick: None,
            newest_live: None,
        }
    }

    /// A live source: no modelled latency, each new sample fed as the source measured it (a
    /// sample of unknown time as taken at the display time it was asked for).
    pub fn live(mode: PredictMode, hmd: &HmdDescription) -> DelayedGaze {
        DelayedGaze {
            model: None,
            ..DelayedGaze::with_predictor(
                LatencyModel::for_headset(hmd, Some(0.0), None).unwrap_or(LatencyModel {
                    tracker_hz: hmd.tracker.rate_hz as f64,
                    tracker_ms: 0.0,
                    render_ms: 0.0,
                    display_ms: 0.0,
                    total_override_ms: Some(0.0),
                }),
                Predictor::new(mode, hmd),
            )
        }
    }

    /// The latency model; `None` for a live source.
    pub fn model(&self) -> Option<&LatencyModel> {
        self.model.as_ref()
    }

    pub fn mode(&self) -> PredictMode {
        self.predictor.mode()
    }

    /// The frame displayed at `display_time` (increasing from call to call). The source's
    /// `begin_frame` sees the display times (a recording aligned to the first frame starts there);
    /// tracker samples before the source's first are its first (clamped), as playback gives them.
    pub fn frame(
        &mut self,
        source: &mut dyn GazeSource,
        display_time: XrTime,
    ) -> Result<DelayedFrame, HalError> {
        source.begin_frame(display_time)?;
        let usable = |s: &GazeSample| {
            let ok = s.valid && s.gaze.direction.is_finite() && s.gaze.direction.length() > 0.0;
            ok.then(|| s.gaze.direction.normalize())
        };
        let mut newest = 0;
        match &self.model {
            Some(model) => {
                newest = model.newest_tick(display_time);
                let warm_up =
                    (WARM_UP_MS * NANOS_PER_MILLI / model.tracker_period_ns()).ceil() as i64;
                let first = self.next_tick.unwrap_or(newest - warm_up);
                for k in first..=newest {
                    let t = model.tick_time(k);
                    let s = source.sample_at(t);
                    self.predictor.push(t, usable(&s));
                }
                self.next_tick = Some(newest.max(first - 1) + 1);
            }
            None => {
                let s = source.sample_at(display_time);
                let known = s.time != 0 && s.time_kind != SampleTimeKind::Unknown;
                let t = if known { s.time } else { display_time };
                if self.newest_live.is_none_or(|n| t > n) {
                    self.predictor.push(t, usable(&s));
                    self.newest_live = Some(t);
                }
            }
        }
        let prediction = self.predictor.predict(display_time);
        let sample = match prediction.direction {
            Some(direction) => GazeSample {
                time: prediction.sample_time,
                time_kind: SampleTimeKind::Predicted,
                ..GazeSample::looking(prediction.sample_time, newest as u64, direction)
            },
            None => {
                // Blink or lost tracking: the policy holds what the predictor would hold (the
                // fixation before it, not the samples of a closing lid), then the centre.
                if let Some(hold) = prediction.hold {
                    self.policy.retarget_hold(hold);
                }
                GazeSample::no_gaze(display_time, newest as u64)
            }
        };
        let resolved = self.policy.resolve(&sample, display_time);
        let truth = source.sample_at(display_time);
        Ok(DelayedFrame {
            display_time,
            resolved,
            prediction,
            truth,
        })
    }
}
