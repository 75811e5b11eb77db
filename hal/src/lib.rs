//! Gaze and headset abstraction for fovea (no Vulkan).
//!
//! - [`sample`]: OpenXR-shaped gaze samples ([`GazeSample`], [`XrTime`]).
//! - [`hmd`]: headset profiles from strict TOML ([`HmdDescription`]) and pixel ↔ direction ↔
//!   eccentricity conversions.
//! - [`source`]: the [`GazeSource`] trait, [`InvalidGazePolicy`], [`FixedGaze`].
//! - [`sim`]: simulated FOVE 0 ([`SimulatedFove`]).
//! - [`trace`]: the gaze trace format, importers, [`Playback`] and [`Recorder`].
//! - [`latency`]: the gaze-to-photon latency model ([`LatencyModel`], [`DelayedGaze`]).
//! - [`predict`]: gaze prediction at the display time ([`Predictor`], [`PredictMode`]).
//! - [`spec`]: parsing of the CLI's `--gaze` argument ([`GazeSpec`]).
//! - `openxr` (cargo feature `openxr`): a real runtime through `XR_EXT_eye_gaze_interaction`.

pub mod error;
pub mod file;
pub mod gaze_eval;
pub mod hmd;
pub mod latency;
pub mod predict;
pub mod sample;
pub mod sim;
pub mod source;
pub mod spec;
pub mod trace;

#[cfg(feature = "openxr")]
pub mod openxr;

pub use error::HalError;
pub use hmd::{
    builtin_names, Capabilities, EyeView, Fov, HmdDescription, PipelineLatency, TrackerSpec,
};
pub use latency::{DelayedFrame, DelayedGaze, LatencyModel};
pub use predict::{EyeMotion, PredictMode, Prediction, Predictor};
pub use sample::{Eye, EyeState, GazeRay, GazeSample, SampleTimeKind, XrTime};
pub use sim::{SimConfig, SimulatedFove};
pub use source::{FixedGaze, GazeOrigin, GazeSource, InvalidGazePolicy, ResolvedGaze};
pub use spec::GazeSpec;
pub use trace::{Playback, Recorder, Trace, TraceHeader, TraceWriter};
