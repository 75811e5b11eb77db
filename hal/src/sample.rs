//! Gaze sample types, shaped after OpenXR so a runtime backend fills them without translation.

use glam::Vec3;

/// Nanoseconds on one monotonic clock shared with frame timing (OpenXR `XrTime`). 0 = unknown.
pub type XrTime = i64;

pub const NANOS_PER_SECOND: f64 = 1e9;
pub const NANOS_PER_MILLI: f64 = 1e6;

/// How a sample's time relates to a real measurement.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum SampleTimeKind {
    /// The tracker measured the eye at exactly `time`.
    Measured,
    /// Blended from measurements either side of `time`.
    Interpolated,
    /// Extrapolated past the newest measurement.
    Predicted,
    /// The source cannot say (e.g. a runtime without `XrEyeGazeSampleTimeEXT`).
    #[default]
    Unknown,
}

impl SampleTimeKind {
    pub fn as_str(self) -> &'static str {
        match self {
            SampleTimeKind::Measured => "measured",
            SampleTimeKind::Interpolated => "interpolated",
            SampleTimeKind::Predicted => "predicted",
            SampleTimeKind::Unknown => "unknown",
        }
    }

    pub fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "measured" => SampleTimeKind::Measured,
            "interpolated" => SampleTimeKind::Interpolated,
            "predicted" => SampleTimeKind::Predicted,
            "unknown" => SampleTimeKind::Unknown,
            _ => return None,
        })
    }
}

/// Per-eye lid / detection state (FOVE SDK and XR_FB_eye_tracking_social both report this).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum EyeState {
    Open,
    Closed,
    #[default]
    NotDetected,
}

impl EyeState {
    pub fn as_str(self) -> &'static str {
        match self {
            EyeState::Open => "open",
            EyeState::Closed => "closed",
            EyeState::NotDetected => "not_detected",
        }
    }

    pub fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "open" => EyeState::Open,
            "closed" => EyeState::Closed,
            "not_detected" => EyeState::NotDetected,
            _ => return None,
        })
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Eye {
    Left,
    Right,
}

impl Eye {
    pub const BOTH: [Eye; 2] = [Eye::Left, Eye::Right];

    pub fn index(self) -> usize {
        match self {
            Eye::Left => 0,
            Eye::Right => 1,
        }
    }
}

/// A ray in OpenXR view space: +X right, +Y up, −Z forward; metres; `direction` is unit length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GazeRay {
    pub origin: Vec3,
    pub direction: Vec3,
}

impl GazeRay {
    pub const FORWARD: GazeRay = GazeRay {
        origin: Vec3::ZERO,
        direction: Vec3::NEG_Z,
    };
}

impl Default for GazeRay {
    fn default() -> Self {
        GazeRay::FORWARD
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GazeSample {
    /// The real time the eye was measured (or the query time for synthetic no-gaze samples).
    pub time: XrTime,
    pub time_kind: SampleTimeKind,
    /// Increments once per tracker measurement; repeats when the same measurement is returned.
    pub sequence: u64,
    /// Combined (cyclopean) gaze.
    pub gaze: GazeRay,
    /// Per-eye rays when the device reports them.
    pub eyes: Option<[GazeRay; 2]>,
    /// OpenXR "orientation valid": the direction can be used at all.
    pub valid: bool,
    /// OpenXR "orientation tracked": valid and currently measured (not degraded / held by the runtime).
    pub tracked: bool,
    /// Indexed by [`Eye::index`].
    pub eye_state: [EyeState; 2],
    /// 0..=1 when the device reports it.
    pub confidence: Option<f32>,
    /// Distance (m) along the combined ray where the eyes converge, when reported.
    pub convergence_distance: Option<f32>,
}

impl GazeSample {
    /// "No gaze" at time `t` (blink, lost tracking, no permission): invalid, never an error.
    pub fn no_gaze(t: XrTime, sequence: u64) -> Self {
        GazeSample {
            time: t,
            time_kind: SampleTimeKind::Unknown,
            sequence,
            gaze: GazeRay::FORWARD,
            eyes: None,
            valid: false,
            tracked: false,
            eye_state: [EyeState::NotDetected; 2],
            confidence: None,
            convergence_distance: None,
        }
    }

    /// A valid, tracked, measured sample looking along `direction` (normalised here).
    pub fn looking(t: XrTime, sequence: u64, direction: Vec3) -> Self {
        GazeSample {
            time: t,
            time_kind: SampleTimeKind::Measured,
            sequence,
            gaze: GazeRay {
                origin: Vec3::ZERO,
                direction: direction.normalize_or(Vec3::NEG_Z),
            },
            eyes: None,
            valid: true,
            tracked: true,
            eye_state: [EyeState::Open; 2],
            confidence: None,
            convergence_distance: None,
        }
    }

    /// Bitwise equality (NaN-safe, distinguishes −0.0): what "record → play back identical" means.
    pub fn bit_eq(&self, other: &GazeSample) -> bool {
        fn ray_bits(r: &GazeRay) -> [u32; 6] {
            let (o, d) = (r.origin, r.direction);
            [o.x, o.y, o.z, d.x, d.y, d.z].map(f32::to_bits)
        }
        let opt = |v: Option<f32>| v.map(f32::to_bits);
        self.time == other.time
            && self.time_kind == other.time_kind
            && self.sequence == other.sequence
            && ray_bits(&self.gaze) == ray_bits(&other.gaze)
            && self.eyes.map(|e| e.map(|r| ray_bits(&r)))
                == other.eyes.map(|e| e.map(|r| ray_bits(&r)))
            && self.valid == other.valid
            && self.tracked == other.tracked
            && self.eye_state == other.eye_state
            && opt(self.confidence) == opt(other.confidence)
            && opt(self.convergence_distance) == opt(other.convergence_distance)
    }
}
