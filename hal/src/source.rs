//! The backend-independent gaze source trait, the invalid-gaze policy, and a fixed-gaze source.

use crate::error::HalError;
use crate::hmd::HmdDescription;
use crate::sample::{GazeSample, XrTime, NANOS_PER_MILLI};
use glam::Vec3;

/// Anything that produces gaze: simulator, trace playback, recorder wrapper, OpenXR runtime.
///
/// Call order per frame: `begin_frame(predicted_display_time)` once (OpenXR syncs actions here,
/// playback moves its clock, the simulator steps), then any number of `sample_at` / `latest`.
/// No-gaze conditions (blink, lost tracking, no permission) are invalid samples, never errors;
/// `begin_frame` errors mean the source itself broke (runtime lost, file write failed).
pub trait GazeSource {
    fn describe(&self) -> &HmdDescription;

    fn begin_frame(&mut self, predicted_display_time: XrTime) -> Result<(), HalError>;

    /// Gaze for time `t` with OpenXR semantics: the source interpolates or clamps to the nearest
    /// available measurement and reports the sample's real time and how it was obtained. `&mut`
    /// because sources advance or cache state while answering (simulator steps, OpenXR locates).
    fn sample_at(&mut self, t: XrTime) -> GazeSample;

    /// The newest sample available as of the last `begin_frame` / `sample_at`.
    fn latest(&self) -> GazeSample;
}

impl<S: GazeSource + ?Sized> GazeSource for Box<S> {
    fn describe(&self) -> &HmdDescription {
        (**self).describe()
    }
    fn begin_frame(&mut self, t: XrTime) -> Result<(), HalError> {
        (**self).begin_frame(t)
    }
    fn sample_at(&mut self, t: XrTime) -> GazeSample {
        (**self).sample_at(t)
    }
    fn latest(&self) -> GazeSample {
        (**self).latest()
    }
}

/// Where a [`ResolvedGaze`] direction came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GazeOrigin {
    /// The sample itself was valid.
    Live,
    /// The sample was invalid; the last valid direction is still recent enough.
    Held,
    /// No valid gaze for longer than the hold time (or ever): the view centre.
    Centre,
}

impl GazeOrigin {
    /// The name in reports and logs: live, held, centre.
    pub fn name(self) -> &'static str {
        match self {
            GazeOrigin::Live => "live",
            GazeOrigin::Held => "held",
            GazeOrigin::Centre => "centre",
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResolvedGaze {
    /// Unit direction in view space.
    pub direction: Vec3,
    pub source: GazeOrigin,
    /// How old the used measurement is at `now` (0 for `Centre`).
    pub age_ns: i64,
}

/// What the renderer uses when gaze is invalid: hold the last valid direction for up to
/// `hold_ms` (blinks last 100–400 ms, so the fovea should not jump during one), then fall back to
/// `centre` (straight ahead by default, which is where the eyes rest — not the image centre of an
/// asymmetric FOV). Valid-but-untracked (degraded) samples count as live: the runtime still
/// vouches for the direction.
#[derive(Debug, Clone)]
pub struct InvalidGazePolicy {
    pub hold_ms: f32,
    pub centre: Vec3,
    last_valid: Option<(XrTime, Vec3)>,
}

impl Default for InvalidGazePolicy {
    fn default() -> Self {
        InvalidGazePolicy::new(250.0)
    }
}

impl InvalidGazePolicy {
    pub fn new(hold_ms: f32) -> Self {
        InvalidGazePolicy {
            hold_ms,
            centre: Vec3::NEG_Z,
            last_valid: None,
        }
    }

    /// Decide the gaze for a frame rendered at `now`. Time is passed explicitly because an invalid
    /// sample's own time may be unknown (0) or stale.
    pub fn resolve(&mut self, sample: &GazeSample, now: XrTime) -> ResolvedGaze {
        let usable = sample.valid
            && sample.gaze.direction.is_finite()
            && sample.gaze.direction.length_squared() > 0.0;
        if usable {
            let dir = sample.gaze.direction.normalize();
            // Samples of unknown time are treated as current so the hold window stays meaningful.
            let t = if sample.time == 0 { now } else { sample.time };
            self.last_valid = Some((t, dir));
            return ResolvedGaze {
                direction: dir,
                source: GazeOrigin::Live,
                age_ns: now.saturating_sub(t).max(0),
            };
        }
        if let Some((t, dir)) = self.last_valid {
            let age = now.saturating_sub(t).max(0);
            if (age as f64) <= self.hold_ms as f64 * NANOS_PER_MILLI {
                return ResolvedGaze {
                    direction: dir,
                    source: GazeOrigin::Held,
                    age_ns: age,
                };
            }
        }
        ResolvedGaze {
            direction: self.centre,
            source: GazeOrigin::Centre,
            age_ns: 0,
        }
    }

    /// Hold `direction` instead of the last valid one (keeping that one's time, so the hold
    /// ends when it would have): a gaze predictor that knows the last samples before a blink
    /// were the lid closing, not the eye moving, says what to hold.
    pub fn retarget_hold(&mut self, direction: Vec3) {
        if let Some((_, held)) = &mut self.last_valid {
            *held = direction.normalize_or(*held);
        }
    }

    pub fn reset(&mut self) {
        self.last_valid = None;
    }
}

/// A source that always looks in one direction (`--gaze center` / `--gaze X,Y`).
pub struct FixedGaze {
    hmd: HmdDescription,
    direction: Vec3,
    now: XrTime,
}

impl FixedGaze {
    pub fn new(hmd: HmdDescription, direction: Vec3) -> Self {
        FixedGaze {
            hmd,
            direction: direction.normalize_or(Vec3::NEG_Z),
            now: 0,
        }
    }
}

impl GazeSource for FixedGaze {
    fn describe(&self) -> &HmdDescription {
        &self.hmd
    }
    fn begin_frame(&mut self, t: XrTime) -> Result<(), HalError> {
        self.now = t;
        Ok(())
    }
    fn sample_at(&mut self, t: XrTime) -> GazeSample {
        GazeSample::looking(t, 0, self.direction)
    }
    fn latest(&self) -> GazeSample {
        GazeSample::looking(self.now, 0, self.direction)
    }
}
