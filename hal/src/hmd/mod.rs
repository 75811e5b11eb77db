//! Headset descriptions loaded from strict TOML (`config/headsets/*.toml`).
//!
//! TOML stores FOV in degrees (what spec sheets quote); the loaded description holds radians in the
//! OpenXR `XrFovf` convention (left/down negative) so a runtime's values drop in unchanged.

mod builtin;
mod projection;

pub use builtin::{builtin_names, BUILTIN_DIR};
pub use projection::angle_between_deg;

use crate::error::HalError;
use crate::sample::Eye;
use glam::Vec3;
use serde::Deserialize;
use std::path::Path;

/// Per-eye field of view, radians, OpenXR `XrFovf` convention (left and down are negative).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fov {
    pub angle_left: f32,
    pub angle_right: f32,
    pub angle_down: f32,
    pub angle_up: f32,
}

impl Fov {
    pub fn from_degrees(left: f32, right: f32, down: f32, up: f32) -> Self {
        Fov {
            angle_left: left.to_radians(),
            angle_right: right.to_radians(),
            angle_down: down.to_radians(),
            angle_up: up.to_radians(),
        }
    }

    pub fn horizontal_deg(&self) -> f32 {
        (self.angle_right - self.angle_left).to_degrees()
    }

    pub fn vertical_deg(&self) -> f32 {
        (self.angle_up - self.angle_down).to_degrees()
    }
}

/// One eye's render view: recommended image size, FOV, and position relative to the view origin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EyeView {
    pub recommended_width: u32,
    pub recommended_height: u32,
    pub fov: Fov,
    /// Eye position in view space, metres (x = ∓IPD/2).
    pub offset: Vec3,
}

/// The eye tracker's nominal figures (the simulator uses them; other backends report them).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackerSpec {
    pub rate_hz: f32,
    /// Measurement → available to the application.
    pub latency_ms: f32,
    /// Mean angular error (systematic, slowly varying).
    pub accuracy_deg: f32,
    /// Per-sample noise, standard deviation per axis.
    pub precision_deg: f32,
}

/// What follows the tracker on the way from a gaze sample to the photons that show a frame
/// foveated with it (`[latency]` of a profile; `crate::latency::LatencyModel` adds the tracker's
/// own delay).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PipelineLatency {
    /// The application reads the gaze → the frame is finished (CPU, GPU, compositor).
    pub render_ms: f32,
    /// The finished frame → its photons (scan-out to mid-panel, panel response).
    pub display_ms: f32,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Capabilities {
    /// A combined gaze ray (XR_EXT_eye_gaze_interaction or vendor SDK).
    #[serde(default)]
    pub eye_gaze: bool,
    #[serde(default)]
    pub per_eye_gaze: bool,
    #[serde(default)]
    pub eye_openness: bool,
    #[serde(default)]
    pub confidence: bool,
    #[serde(default)]
    pub convergence_distance: bool,
}

#[derive(Debug, Clone, PartialEq)]
pub struct HmdDescription {
    pub id: String,
    pub display_name: String,
    /// Indexed by [`Eye::index`].
    pub eyes: [EyeView; 2],
    pub refresh_hz: f32,
    pub tracker: TrackerSpec,
    /// `[latency]`: render and display latency; `None` in a profile without the section.
    pub latency: Option<PipelineLatency>,
    pub capabilities: Capabilities,
}

// ---- strict TOML schema (degrees, as in spec sheets) ----

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct HmdToml {
    id: String,
    display_name: String,
    refresh_hz: f32,
    left_eye: EyeToml,
    right_eye: EyeToml,
    tracker: TrackerToml,
    #[serde(default)]
    latency: Option<PipelineLatency>,
    #[serde(default)]
    capabilities: Capabilities,
    /// Free text: sources of the numbers. Kept out of the description.
    #[serde(default)]
    #[allow(dead_code)]
    notes: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EyeToml {
    recommended_width: u32,
    recommended_height: u32,
    fov_deg: FovDegToml,
    offset_m: [f32; 3],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FovDegToml {
    left: f32,
    right: f32,
    down: f32,
    up: f32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TrackerToml {
    rate_hz: f32,
    latency_ms: f32,
    accuracy_deg: f32,
    precision_deg: f32,
}

/// Largest render target side we accept; beyond this the value is almost certainly a typo.
const MAX_RESOLUTION: u32 = 16384;

impl HmdDescription {
    /// Load and validate a headset TOML file.
    pub fn load(path: &Path) -> Result<HmdDescription, HalError> {
        let text =
            crate::file::read_text(path, crate::file::MAX_PROFILE_BYTES, "a headset profile")?;
        Self::parse(&text, path)
    }

    /// Parse TOML text; `file` is only used to label errors.
    pub fn parse(text: &str, file: &Path) -> Result<HmdDescription, HalError> {
        let raw: HmdToml = toml::from_str(text).map_err(|e| HalError::Toml {
            file: file.to_path_buf(),
            message: e.to_string().trim_end().to_string(),
        })?;
        validate(raw, file)
    }

    pub fn eye(&self, eye: Eye) -> &EyeView {
        &self.eyes[eye.index()]
    }

    /// Distance between the eye offsets, metres.
    pub fn ipd_m(&self) -> f32 {
        self.eyes[0].offset.distance(self.eyes[1].offset)
    }

    pub fn tracker_period_ns(&self) -> i64 {
        (1e9 / self.tracker.rate_hz as f64).round() as i64
    }
}

fn validate(raw: HmdToml, file: &Path) -> Result<HmdDescription, HalError> {
    let bad = |key: &str, reason: String| Err(HalError::invalid(file, key, reason));
    if raw.id.is_empty()
        || !raw
            .id
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_' || c == '-')
    {
        return bad(
            "id",
            format!(
                "`{}` must be non-empty lowercase ASCII letters, digits, `_` or `-`",
                raw.id
            ),
        );
    }
    // Frame k is shown at k / refresh: below 1 Hz a simulated or recorded gaze is played over
    // years of samples (1e-30 Hz never finished) and a frame is not an image in a headset.
    within(file, "refresh_hz", raw.refresh_hz, MIN_RATE_HZ, 1000.0)?;
    let left = validate_eye(&raw.left_eye, "left_eye", file)?;
    let right = validate_eye(&raw.right_eye, "right_eye", file)?;
    let t = &raw.tracker;
    within(file, "tracker.rate_hz", t.rate_hz, MIN_RATE_HZ, 10_000.0)?;
    non_negative(file, "tracker.latency_ms", t.latency_ms, 1000.0)?;
    non_negative(file, "tracker.accuracy_deg", t.accuracy_deg, 45.0)?;
    non_negative(file, "tracker.precision_deg", t.precision_deg, 45.0)?;
    if let Some(l) = &raw.latency {
        non_negative(file, "latency.render_ms", l.render_ms, 1000.0)?;
        non_negative(file, "latency.display_ms", l.display_ms, 1000.0)?;
    }
    Ok(HmdDescription {
        id: raw.id,
        display_name: raw.display_name,
        eyes: [left, right],
        refresh_hz: raw.refresh_hz,
        tracker: TrackerSpec {
            rate_hz: t.rate_hz,
            latency_ms: t.latency_ms,
            accuracy_deg: t.accuracy_deg,
            precision_deg: t.precision_deg,
        },
        latency: raw.latency,
        capabilities: raw.capabilities,
    })
}

fn validate_eye(e: &EyeToml, name: &str, file: &Path) -> Result<EyeView, HalError> {
    for (key, v) in [
        ("recommended_width", e.recommended_width),
        ("recommended_height", e.recommended_height),
    ] {
        if v == 0 || v > MAX_RESOLUTION {
            return Err(HalError::invalid(
                file,
                format!("{name}.{key}"),
                format!("{v} is out of range 1..={MAX_RESOLUTION} pixels"),
            ));
        }
    }
    let f = &e.fov_deg;
    for (key, v) in [
        ("left", f.left),
        ("right", f.right),
        ("down", f.down),
        ("up", f.up),
    ] {
        if !v.is_finite() || v <= -90.0 || v >= 90.0 {
            return Err(HalError::invalid(
                file,
                format!("{name}.fov_deg.{key}"),
                format!("{v}° must lie strictly between -90° and 90° (a rectilinear view cannot reach 180°)"),
            ));
        }
    }
    let pairs = [
        ("right", f.left, f.right, "left"),
        ("up", f.down, f.up, "down"),
    ];
    for (key, lo, hi, lo_name) in pairs {
        if hi <= lo {
            return Err(HalError::invalid(
                file,
                format!("{name}.fov_deg.{key}"),
                format!(
                    "{hi}° must be greater than {lo_name} ({lo}°); left/down are negative (XrFovf)"
                ),
            ));
        }
    }
    if let Some(i) = e
        .offset_m
        .iter()
        .position(|v| !v.is_finite() || v.abs() > 0.2)
    {
        return Err(HalError::invalid(
            file,
            format!("{name}.offset_m[{i}]"),
            format!(
                "{} m: eye offsets must be finite and within ±0.2 m of the view origin",
                e.offset_m[i]
            ),
        ));
    }
    Ok(EyeView {
        recommended_width: e.recommended_width,
        recommended_height: e.recommended_height,
        fov: Fov::from_degrees(f.left, f.right, f.down, f.up),
        offset: Vec3::from_array(e.offset_m),
    })
}

/// The lowest display refresh and tracker rate a profile may give (Hz).
pub const MIN_RATE_HZ: f32 = 1.0;

fn within(file: &Path, key: &str, v: f32, min: f32, max: f32) -> Result<(), HalError> {
    if !(v.is_finite() && (min..=max).contains(&v)) {
        return Err(HalError::invalid(
            file,
            key,
            format!("{v} must be in [{min}, {max}] Hz"),
        ));
    }
    Ok(())
}

fn non_negative(file: &Path, key: &str, v: f32, max: f32) -> Result<(), HalError> {
    if !v.is_finite() || v < 0.0 || v > max {
        return Err(HalError::invalid(
            file,
            key,
            format!("{v} must be >= 0 and <= {max}"),
        ));
    }
    Ok(())
}
