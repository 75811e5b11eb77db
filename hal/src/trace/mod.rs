//! The gaze trace format (text, CSV with a metadata header; see hal/README.md), its writer,
//! dataset importers, [`Playback`] and [`Recorder`].

pub mod import;
mod parse;
mod playback;
mod recorder;

pub use playback::Playback;
pub use recorder::{Recorder, TraceWriter};

use crate::error::HalError;
use crate::sample::{GazeRay, GazeSample};
use std::io::Write;
use std::path::Path;

pub const FORMAT_MAGIC: &str = "fovea-gaze-trace";
pub const FORMAT_VERSION: u32 = 1;
/// The only coordinate convention stored: OpenXR view space (+X right, +Y up, −Z forward).
/// Importers convert other conventions before writing.
pub const COORDINATES: &str = "openxr-view";
/// Valid directions must have |length − 1| ≤ this; they are kept as written (not renormalised) so
/// a recording replays bit-exactly. Anything further off is rejected as a convention mix-up.
pub const UNIT_TOLERANCE: f32 = 1e-3;

/// Every column the format knows, in the order the writer emits them.
pub const COLUMNS: &[&str] = &[
    "time_ns",
    "time_kind",
    "seq",
    "valid",
    "tracked",
    "origin_x",
    "origin_y",
    "origin_z",
    "dir_x",
    "dir_y",
    "dir_z",
    "left_state",
    "right_state",
    "confidence",
    "convergence_m",
    "left_origin_x",
    "left_origin_y",
    "left_origin_z",
    "left_dir_x",
    "left_dir_y",
    "left_dir_z",
    "right_origin_x",
    "right_origin_y",
    "right_origin_z",
    "right_dir_x",
    "right_dir_y",
    "right_dir_z",
];
pub const REQUIRED_COLUMNS: &[&str] = &["time_ns", "valid", "dir_x", "dir_y", "dir_z"];

#[derive(Debug, Clone, PartialEq)]
pub struct TraceHeader {
    /// Headset profile id (or dataset device name) the trace was recorded with.
    pub device: String,
    /// Nominal tracker rate; gaps longer than 1.5 periods are never interpolated across.
    pub rate_hz: f32,
    /// Left-eye FOV (l, r, d, u degrees) of the recording device, when known.
    pub fov_deg: Option<[f32; 4]>,
    /// Free-text provenance.
    pub source: Option<String>,
    pub notes: Vec<String>,
}

impl TraceHeader {
    pub fn new(device: impl Into<String>, rate_hz: f32) -> Self {
        TraceHeader {
            device: device.into(),
            rate_hz,
            fov_deg: None,
            source: None,
            notes: Vec::new(),
        }
    }

    pub fn period_ns(&self) -> i64 {
        (1e9 / self.rate_hz as f64).round() as i64
    }

    pub fn write(&self, w: &mut impl Write) -> std::io::Result<()> {
        writeln!(w, "# {FORMAT_MAGIC} {FORMAT_VERSION}")?;
        writeln!(w, "# device: {}", one_line(&self.device))?;
        writeln!(w, "# rate_hz: {}", self.rate_hz)?;
        writeln!(w, "# coordinates: {COORDINATES}")?;
        if let Some([l, r, d, u]) = self.fov_deg {
            writeln!(w, "# fov_deg: {l},{r},{d},{u}")?;
        }
        if let Some(s) = &self.source {
            writeln!(w, "# source: {}", one_line(s))?;
        }
        for n in &self.notes {
            writeln!(w, "# note: {}", one_line(n))?;
        }
        writeln!(w, "{}", COLUMNS.join(","))
    }
}

fn one_line(s: &str) -> String {
    s.replace(['\n', '\r'], " ")
}

/// Writes one row with every column of [`COLUMNS`]. Floats use Rust's shortest round-trip
/// formatting, which is what makes record → playback bit-exact.
pub fn write_row(w: &mut impl Write, s: &GazeSample) -> std::io::Result<()> {
    let opt = |v: Option<f32>| v.map_or(String::new(), |v| v.to_string());
    let ray = |r: &GazeRay| {
        let (o, d) = (r.origin, r.direction);
        format!("{},{},{},{},{},{}", o.x, o.y, o.z, d.x, d.y, d.z)
    };
    let eyes = match &s.eyes {
        Some([l, r]) => format!("{},{}", ray(l), ray(r)),
        None => ",,,,,,,,,,,".to_string(),
    };
    writeln!(
        w,
        "{},{},{},{},{},{},{},{},{},{},{}",
        s.time,
        s.time_kind.as_str(),
        s.sequence,
        u8::from(s.valid),
        u8::from(s.tracked),
        ray(&s.gaze),
        s.eye_state[0].as_str(),
        s.eye_state[1].as_str(),
        opt(s.confidence),
        opt(s.convergence_distance),
        eyes
    )
}

/// A whole trace in memory: header plus samples in strictly increasing time order.
#[derive(Debug, Clone, PartialEq)]
pub struct Trace {
    pub header: TraceHeader,
    pub samples: Vec<GazeSample>,
}

impl Trace {
    pub fn load(path: &Path) -> Result<Trace, HalError> {
        let text = crate::file::read_text(path, crate::file::MAX_TRACE_BYTES, "a gaze trace")?;
        Trace::parse(&text, path)
    }

    /// Parse trace text (a leading UTF-8 byte-order mark is skipped); `file` labels errors.
    pub fn parse(text: &str, file: &Path) -> Result<Trace, HalError> {
        parse::parse_trace(text, file)
    }

    pub fn write(&self, w: &mut impl Write) -> std::io::Result<()> {
        self.header.write(w)?;
        self.samples.iter().try_for_each(|s| write_row(w, s))
    }

    pub fn to_text(&self) -> String {
        let mut out = Vec::new();
        // Writing into a Vec cannot fail.
        let _ = self.write(&mut out);
        String::from_utf8_lossy(&out).into_owned()
    }

    /// Write to `path` through a temporary file + rename; refuses to replace an existing file
    /// unless `overwrite`.
    pub fn save(&self, path: &Path, overwrite: bool) -> Result<(), HalError> {
        let mut file = recorder::AtomicFile::create(path, overwrite)?;
        self.write(file.writer())
            .map_err(|e| HalError::io(file.temp_path(), e))?;
        file.commit()
    }
}
