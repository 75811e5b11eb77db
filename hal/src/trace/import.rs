//! Importers for public dataset layouts, producing a native [`Trace`].
//!
//! - GazeBase / GazeBaseVR: CSV with a header row; `n` = time in ms, `x`,`y` = gaze in degrees of
//!   visual angle (+x right, +y up), optional `val` (non-zero = invalid), optional binocular
//!   `lx,ly,rx,ry`. Other columns (targets etc.) are ignored: they belong to the dataset.
//! - Normalised screen coordinates (EHTask style): time in ms plus x, y in 0..1 of the recording
//!   device's image; needs that device's FOV to become directions.
//!
//! - Degrees from the view centre (`t_s,x_deg,y_deg,valid`, the format of fovea's shared real
//!   recordings): seconds, degrees (+x right, +y up), `valid` 0/1; placed on a headset eye's view
//!   ([`import_degrees`]).
//!
//! Degrees become directions per axis through the tangent plane: dir ∝ (tan x, tan y, −1).

use super::{Trace, TraceHeader};
use crate::error::HalError;
use crate::hmd::Fov;
use crate::sample::{EyeState, GazeRay, GazeSample, SampleTimeKind};
use glam::Vec3;
use std::path::Path;

#[derive(Debug, Clone)]
pub struct DegreesImport {
    pub device: String,
    /// Nominal rate; `None` → the median sample interval.
    pub rate_hz: Option<f32>,
    /// Set when the dataset's +y points down.
    pub y_down: bool,
}

impl Default for DegreesImport {
    fn default() -> Self {
        DegreesImport {
            device: "gazebase".into(),
            rate_hz: None,
            y_down: false,
        }
    }
}

#[derive(Debug, Clone)]
pub struct NormalizedImport {
    pub device: String,
    pub fov: Fov,
    pub rate_hz: Option<f32>,
    /// EHTask puts (0,0) at the bottom-left; image conventions put it top-left.
    pub origin_bottom_left: bool,
    pub time_column: String,
    pub x_column: String,
    pub y_column: String,
}

impl NormalizedImport {
    pub fn new(device: impl Into<String>, fov: Fov) -> Self {
        NormalizedImport {
            device: device.into(),
            fov,
            rate_hz: None,
            origin_bottom_left: true,
            time_column: "time_ms".into(),
            x_column: "x".into(),
            y_column: "y".into(),
        }
    }
}

/// A CSV with a header row, read leniently about extra columns but strictly about the ones used.
struct Csv<'a> {
    file: &'a Path,
    names: Vec<String>,
    rows: Vec<(usize, Vec<&'a str>)>,
}

impl<'a> Csv<'a> {
    fn parse(text: &'a str, file: &'a Path) -> Result<Csv<'a>, HalError> {
        let text = crate::file::strip_bom(text);
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l))
            .filter(|(_, l)| !l.trim().is_empty());
        let (_, header) = lines
            .next()
            .ok_or_else(|| HalError::trace(file, 1, "empty file; expected a header row"))?;
        let names: Vec<String> = header.split(',').map(|s| s.trim().to_string()).collect();
        let mut rows = Vec::new();
        for (n, line) in lines {
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            if fields.len() != names.len() {
                let reason = format!("expected {} fields, found {}", names.len(), fields.len());
                return Err(HalError::trace(file, n, reason));
            }
            rows.push((n, fields));
        }
        if rows.is_empty() {
            return Err(HalError::trace(file, 1, "no data rows"));
        }
        Ok(Csv { file, names, rows })
    }

    fn column(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    fn require(&self, name: &str) -> Result<usize, HalError> {
        self.column(name).ok_or_else(|| {
            HalError::trace(self.file, 1, format!("required column `{name}` is missing"))
        })
    }

    /// A number; NaN is returned as is (datasets use it for lost samples), infinities are errors.
    fn number(&self, line: usize, fields: &[&str], col: usize) -> Result<f64, HalError> {
        let v: f64 = fields[col].parse().map_err(|_| {
            HalError::trace(
                self.file,
                line,
                format!("{} `{}` is not a number", self.names[col], fields[col]),
            )
        })?;
        if v.is_infinite() {
            return Err(HalError::trace(
                self.file,
                line,
                format!("{} is infinite", self.names[col]),
            ));
        }
        Ok(v)
    }
}

fn time_ns(file: &Path, line: usize, ms: f64) -> Result<i64, HalError> {
    if !ms.is_finite() || ms.abs() > 9.0e12 {
        return Err(HalError::trace(
            file,
            line,
            format!("time {ms} ms is not a usable time stamp"),
        ));
    }
    Ok((ms * 1e6).round() as i64)
}

fn tangent_direction(tx: f64, ty: f64) -> Vec3 {
    Vec3::new(tx as f32, ty as f32, -1.0).normalize()
}

fn degrees_direction(x: f64, y: f64, y_down: bool) -> Option<Vec3> {
    let ok = x.is_finite() && y.is_finite() && x.abs() < 89.0 && y.abs() < 89.0;
    let y = if y_down { -y } else { y };
    ok.then(|| tangent_direction(x.to_radians().tan(), y.to_radians().tan()))
}

pub fn import_gazebase(path: &Path, opts: &DegreesImport) -> Result<Trace, HalError> {
    let text = crate::file::read_text(path, crate::file::MAX_TRACE_BYTES, "a dataset CSV")?;
    import_gazebase_text(&text, path, opts)
}

pub fn import_gazebase_text(
    text: &str,
    file: &Path,
    opts: &DegreesImport,
) -> Result<Trace, HalError> {
    let csv = Csv::parse(text, file)?;
    let (n, x, y) = (csv.require("n")?, csv.require("x")?, csv.require("y")?);
    let val = csv.column("val");
    let binocular = match ["lx", "ly", "rx", "ry"].map(|c| csv.column(c)) {
        [Some(a), Some(b), Some(c), Some(d)] => Some([a, b, c, d]),
        _ => None,
    };
    let mut samples = Vec::with_capacity(csv.rows.len());
    for (line, fields) in &csv.rows {
        let time = time_ns(file, *line, csv.number(*line, fields, n)?)?;
        let flagged_invalid = match val {
            Some(c) => csv.number(*line, fields, c)? != 0.0,
            None => false,
        };
        let dir = degrees_direction(
            csv.number(*line, fields, x)?,
            csv.number(*line, fields, y)?,
            opts.y_down,
        );
        let mut s = match dir {
            Some(d) if !flagged_invalid => GazeSample::looking(time, samples.len() as u64, d),
            _ => GazeSample {
                time_kind: SampleTimeKind::Measured,
                ..GazeSample::no_gaze(time, samples.len() as u64)
            },
        };
        if let Some([lx, ly, rx, ry]) = binocular {
            let eye = |a, b| -> Result<Option<Vec3>, HalError> {
                Ok(degrees_direction(
                    csv.number(*line, fields, a)?,
                    csv.number(*line, fields, b)?,
                    opts.y_down,
                ))
            };
            let (l, r) = (eye(lx, ly)?, eye(rx, ry)?);
            let state = |d: Option<Vec3>| {
                if d.is_some() {
                    EyeState::Open
                } else {
                    EyeState::NotDetected
                }
            };
            s.eye_state = [state(l), state(r)];
            if let (Some(l), Some(r), true) = (l, r, s.valid) {
                s.eyes = Some([
                    GazeRay {
                        origin: Vec3::ZERO,
                        direction: l,
                    },
                    GazeRay {
                        origin: Vec3::ZERO,
                        direction: r,
                    },
                ]);
            }
        }
        samples.push(s);
    }
    finish(file, samples, &csv, opts.rate_hz, opts.device.clone(), None)
}

pub fn import_normalized(path: &Path, opts: &NormalizedImport) -> Result<Trace, HalError> {
    let text = crate::file::read_text(path, crate::file::MAX_TRACE_BYTES, "a dataset CSV")?;
    import_normalized_text(&text, path, opts)
}

pub fn import_normalized_text(
    text: &str,
    file: &Path,
    opts: &NormalizedImport,
) -> Result<Trace, HalError> {
    let csv = Csv::parse(text, file)?;
    let (tc, xc, yc) = (
        csv.require(&opts.time_column)?,
        csv.require(&opts.x_column)?,
        csv.require(&opts.y_column)?,
    );
    let f = &opts.fov;
    let (l, r, d, u) = (
        f.angle_left.tan() as f64,
        f.angle_right.tan() as f64,
        f.angle_down.tan() as f64,
        f.angle_up.tan() as f64,
    );
    let mut samples = Vec::with_capacity(csv.rows.len());
    for (line, fields) in &csv.rows {
        let time = time_ns(file, *line, csv.number(*line, fields, tc)?)?;
        let (x, y) = (
            csv.number(*line, fields, xc)?,
            csv.number(*line, fields, yc)?,
        );
        let seq = samples.len() as u64;
        samples.push(if x.is_finite() && y.is_finite() {
            let ty = if opts.origin_bottom_left {
                d + y * (u - d)
            } else {
                u - y * (u - d)
            };
            GazeSample::looking(time, seq, tangent_direction(l + x * (r - l), ty))
        } else {
            GazeSample {
                time_kind: SampleTimeKind::Measured,
                ..GazeSample::no_gaze(time, seq)
            }
        });
    }
    let deg = |v: f32| v.to_degrees();
    let fov = Some([
        deg(f.angle_left),
        deg(f.angle_right),
        deg(f.angle_down),
        deg(f.angle_up),
    ]);
    finish(file, samples, &csv, opts.rate_hz, opts.device.clone(), fov)
}

/// The one header of a degrees recording, in this order.
pub const DEGREES_COLUMNS: [&str; 4] = ["t_s", "x_deg", "y_deg", "valid"];

/// Largest gaze angle a degrees recording may hold: a rectilinear view never reaches 90°, and a
/// desktop or headset recording stays far inside it.
pub const MAX_DEGREES: f64 = 80.0;

/// `t_s,x_deg,y_deg,valid` (seconds from the first sample; degrees from the screen centre, +x
/// right, +y up; `valid` 0 where the tracker had no gaze, those rows may hold `nan`) placed on the
/// eye view `fov`: the recording's screen centre goes to the view's centre and its angles through
/// the view's tangent plane, tx = (tan l + tan r)/2 + tan x (likewise y), so a recording made on
/// a flat screen keeps its geometry. Invalid rows become no-gaze samples (the invalid-gaze policy
/// decides what a frame shows), and the rate is the median interval.
pub fn import_degrees(path: &Path, fov: &Fov) -> Result<Trace, HalError> {
    let text = crate::file::read_text(path, crate::file::MAX_TRACE_BYTES, "a degrees recording")?;
    import_degrees_text(&text, path, fov)
}

pub fn import_degrees_text(text: &str, file: &Path, fov: &Fov) -> Result<Trace, HalError> {
    let csv = Csv::parse(text, file)?;
    if csv.names != DEGREES_COLUMNS {
        return Err(HalError::trace(
            file,
            1,
            format!(
                "header `{}`: expected exactly `{}`",
                csv.names.join(","),
                DEGREES_COLUMNS.join(",")
            ),
        ));
    }
    if csv.rows.len() < 2 {
        return Err(HalError::trace(
            file,
            csv.rows[0].0,
            "one data row: a recording needs at least two samples",
        ));
    }
    let centre = (
        (fov.angle_left.tan() as f64 + fov.angle_right.tan() as f64) / 2.0,
        (fov.angle_down.tan() as f64 + fov.angle_up.tan() as f64) / 2.0,
    );
    let mut samples = Vec::with_capacity(csv.rows.len());
    for (line, fields) in &csv.rows {
        let line = *line;
        let seconds = csv.number(line, fields, 0)?;
        if !seconds.is_finite() || seconds.abs() > 9.0e9 {
            let reason = format!("t_s {seconds} is not a usable time in seconds");
            return Err(HalError::trace(file, line, reason));
        }
        let time = (seconds * 1e9).round() as i64;
        let valid = match fields[3] {
            "1" => true,
            "0" => false,
            other => {
                return Err(HalError::trace(
                    file,
                    line,
                    format!("valid `{other}` must be 0 or 1"),
                ))
            }
        };
        let seq = samples.len() as u64;
        if !valid {
            // The angles of an invalid row are not read: trackers write nan, 0 or stale values.
            samples.push(GazeSample {
                time_kind: SampleTimeKind::Measured,
                ..GazeSample::no_gaze(time, seq)
            });
            continue;
        }
        let angle = |col: usize| -> Result<f64, HalError> {
            let v = csv.number(line, fields, col)?;
            if v.is_nan() || v.abs() > MAX_DEGREES {
                let name = &csv.names[col];
                let reason = format!(
                    "{name} {v} on a valid row: expected an angle within ±{MAX_DEGREES}° (rows \
                     without gaze have valid 0)"
                );
                return Err(HalError::trace(file, line, reason));
            }
            Ok(v)
        };
        let (x, y) = (angle(1)?, angle(2)?);
        let direction = tangent_direction(
            centre.0 + x.to_radians().tan(),
            centre.1 + y.to_radians().tan(),
        );
        samples.push(GazeSample::looking(time, seq, direction));
    }
    let mut trace = finish(file, samples, &csv, None, "degrees".into(), None)?;
    trace.header.notes.push(format!(
        "degrees from the view centre of an eye with FOV {:.1},{:.1},{:.1},{:.1}",
        fov.angle_left.to_degrees(),
        fov.angle_right.to_degrees(),
        fov.angle_down.to_degrees(),
        fov.angle_up.to_degrees()
    ));
    Ok(trace)
}

fn finish(
    file: &Path,
    samples: Vec<GazeSample>,
    csv: &Csv,
    rate_hz: Option<f32>,
    device: String,
    fov_deg: Option<[f32; 4]>,
) -> Result<Trace, HalError> {
    for (w, rows) in samples.windows(2).zip(csv.rows.windows(2)) {
        if w[1].time <= w[0].time {
            let what = if w[1].time == w[0].time {
                "duplicate"
            } else {
                "out-of-order"
            };
            let reason = format!("{what} time stamp (previous row is line {})", rows[0].0);
            return Err(HalError::trace(file, rows[1].0, reason));
        }
    }
    let rate_hz = match rate_hz {
        Some(r) => r,
        None => {
            let mut dts: Vec<i64> = samples.windows(2).map(|w| w[1].time - w[0].time).collect();
            dts.sort_unstable();
            let median = dts.get(dts.len() / 2).copied().unwrap_or(1_000_000);
            (1e9 / median as f64) as f32
        }
    };
    let header = TraceHeader {
        fov_deg,
        source: Some(format!("imported from {}", file.display())),
        ..TraceHeader::new(device, rate_hz)
    };
    Ok(Trace { header, samples })
}
