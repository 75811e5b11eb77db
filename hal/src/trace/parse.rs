//! Strict trace parser. Every error names the file, the 1-based line, and the reason; nothing here
//! panics on any input (a proptest suite checks that).

use super::{
    Trace, TraceHeader, COLUMNS, COORDINATES, FORMAT_MAGIC, FORMAT_VERSION, REQUIRED_COLUMNS,
    UNIT_TOLERANCE,
};
use crate::error::HalError;
use crate::sample::{EyeState, GazeRay, GazeSample, SampleTimeKind};
use glam::Vec3;
use std::path::Path;

type Res<T> = Result<T, String>;

pub(super) fn parse_trace(text: &str, file: &Path) -> Result<Trace, HalError> {
    let text = crate::file::strip_bom(text);
    let err = |line: usize, reason: String| HalError::trace(file, line, reason);
    let mut lines = text
        .split('\n')
        .enumerate()
        .map(|(i, l)| (i + 1, l.strip_suffix('\r').unwrap_or(l)));
    let (_, first) = lines.next().unwrap_or((1, ""));
    parse_magic(first).map_err(|r| err(1, r))?;

    let mut meta = Meta::default();
    let (column_line, columns) = loop {
        let Some((n, line)) = lines.next() else {
            return Err(err(
                text.split('\n').count(),
                "missing column header line after the metadata".into(),
            ));
        };
        if let Some(rest) = line.strip_prefix('#') {
            meta.add(rest).map_err(|r| err(n, r))?;
        } else if !line.trim().is_empty() {
            break (n, Columns::parse(line).map_err(|r| err(n, r))?);
        }
    };
    let header = meta.finish().map_err(|r| err(column_line, r))?;

    let ends_with_newline = text.ends_with('\n');
    let total_lines = text.split('\n').count();
    let mut samples: Vec<GazeSample> = Vec::new();
    let mut previous_line = 0;
    for (n, line) in lines {
        if line.trim().is_empty() || line.starts_with('#') {
            continue;
        }
        // A crash mid-write can cut a number short and still leave a parseable row, so a data
        // line without its newline is rejected even when it parses (the writer always ends rows).
        if n == total_lines && !ends_with_newline {
            return Err(err(
                n,
                "truncated last line: no trailing newline (the file was cut short?)".into(),
            ));
        }
        let sample = columns
            .parse_row(line, samples.len() as u64)
            .map_err(|r| err(n, r))?;
        if let Some(prev) = samples.last() {
            if sample.time == prev.time {
                return Err(err(
                    n,
                    format!(
                        "duplicate time stamp {} (also on line {previous_line})",
                        sample.time
                    ),
                ));
            }
            if sample.time < prev.time {
                return Err(err(n, format!(
                    "time stamp {} is earlier than {} on line {previous_line}; rows must be in time order",
                    sample.time, prev.time
                )));
            }
        }
        previous_line = n;
        samples.push(sample);
    }
    if samples.is_empty() {
        return Err(err(column_line, "the trace has no sample rows".into()));
    }
    Ok(Trace { header, samples })
}

fn parse_magic(first: &str) -> Res<()> {
    if first.trim().is_empty() {
        return Err(format!(
            "empty file or empty first line; expected `# {FORMAT_MAGIC} {FORMAT_VERSION}`"
        ));
    }
    let rest = first.strip_prefix('#').map(str::trim).unwrap_or("");
    let Some(version) = rest.strip_prefix(FORMAT_MAGIC) else {
        return Err(format!(
            "not a fovea gaze trace: the first line must be `# {FORMAT_MAGIC} {FORMAT_VERSION}`"
        ));
    };
    match version.trim().parse::<u32>() {
        Ok(FORMAT_VERSION) => Ok(()),
        Ok(v) => Err(format!(
            "unsupported trace format version {v}; this build reads version {FORMAT_VERSION}"
        )),
        Err(_) => Err(format!(
            "missing or malformed format version after `{FORMAT_MAGIC}`"
        )),
    }
}

#[derive(Default)]
struct Meta {
    device: Option<String>,
    rate_hz: Option<f32>,
    coordinates: bool,
    fov_deg: Option<[f32; 4]>,
    source: Option<String>,
    notes: Vec<String>,
}

impl Meta {
    fn add(&mut self, rest: &str) -> Res<()> {
        let rest = rest.trim();
        if rest.is_empty() {
            return Ok(());
        }
        let Some((key, value)) = rest.split_once(':') else {
            return Err(format!("metadata line `# {rest}` must be `# key: value`"));
        };
        let (key, value) = (key.trim(), value.trim());
        let dup = |set: bool| {
            if set {
                Err(format!("metadata key `{key}` given twice"))
            } else {
                Ok(())
            }
        };
        match key {
            "device" => {
                dup(self.device.is_some())?;
                self.device = Some(value.to_string());
            }
            "rate_hz" => {
                dup(self.rate_hz.is_some())?;
                let r: f32 = value.parse().map_err(|_| format!("rate_hz `{value}` is not a number"))?;
                if !(r.is_finite() && r > 0.0) {
                    return Err(format!("rate_hz {value} must be > 0"));
                }
                self.rate_hz = Some(r);
            }
            "coordinates" => {
                dup(self.coordinates)?;
                if value != COORDINATES {
                    return Err(format!(
                        "coordinates `{value}` not supported; traces store `{COORDINATES}` directions (import other conventions)"
                    ));
                }
                self.coordinates = true;
            }
            "fov_deg" => {
                dup(self.fov_deg.is_some())?;
                self.fov_deg = Some(parse_fov(value)?);
            }
            "source" => {
                dup(self.source.is_some())?;
                self.source = Some(value.to_string());
            }
            "note" => self.notes.push(value.to_string()),
            _ => return Err(format!("unknown metadata key `{key}` (known: device, rate_hz, coordinates, fov_deg, source, note)")),
        }
        Ok(())
    }

    fn finish(self) -> Res<TraceHeader> {
        let device = self.device.ok_or("metadata `# device: ...` is missing")?;
        let rate_hz = self.rate_hz.ok_or("metadata `# rate_hz: ...` is missing")?;
        if !self.coordinates {
            return Err(format!(
                "metadata `# coordinates: {COORDINATES}` is missing"
            ));
        }
        Ok(TraceHeader {
            device,
            rate_hz,
            fov_deg: self.fov_deg,
            source: self.source,
            notes: self.notes,
        })
    }
}

fn parse_fov(value: &str) -> Res<[f32; 4]> {
    let parts: Vec<f32> = value
        .split(',')
        .map(|v| v.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("fov_deg `{value}` must be four numbers: left,right,down,up"))?;
    let [l, r, d, u] = parts[..] else {
        return Err(format!(
            "fov_deg `{value}` must be four numbers: left,right,down,up"
        ));
    };
    let in_range = [l, r, d, u].iter().all(|v| v.is_finite() && v.abs() < 90.0);
    if !in_range || l >= r || d >= u {
        return Err(format!(
            "fov_deg `{value}`: each angle within (-90, 90), left < right, down < up"
        ));
    }
    Ok([l, r, d, u])
}

/// Column name → position in a row, resolved once from the header line.
struct Columns {
    count: usize,
    index: Vec<Option<usize>>,
}

impl Columns {
    fn parse(line: &str) -> Res<Columns> {
        let names: Vec<&str> = line.split(',').map(str::trim).collect();
        let mut index = vec![None; COLUMNS.len()];
        for (pos, name) in names.iter().enumerate() {
            let Some(k) = COLUMNS.iter().position(|c| c == name) else {
                return Err(format!(
                    "unknown column `{name}` (known: {})",
                    COLUMNS.join(", ")
                ));
            };
            if index[k].is_some() {
                return Err(format!("column `{name}` appears twice"));
            }
            index[k] = Some(pos);
        }
        let cols = Columns {
            count: names.len(),
            index,
        };
        if let Some(missing) = REQUIRED_COLUMNS.iter().find(|c| cols.pos(c).is_none()) {
            return Err(format!("required column `{missing}` is missing"));
        }
        for group in [
            "origin_",
            "left_origin_",
            "left_dir_",
            "right_origin_",
            "right_dir_",
        ] {
            let present = ["x", "y", "z"]
                .iter()
                .filter(|a| cols.pos(&format!("{group}{a}")).is_some())
                .count();
            if present != 0 && present != 3 {
                return Err(format!("columns {group}x/y/z must appear together"));
            }
        }
        let left = cols.pos("left_dir_x").is_some() || cols.pos("left_origin_x").is_some();
        let right = cols.pos("right_dir_x").is_some() || cols.pos("right_origin_x").is_some();
        if left != right
            || (left && (cols.pos("left_dir_x").is_none() || cols.pos("right_dir_x").is_none()))
        {
            return Err("per-eye columns need left_dir_* and right_dir_* together".into());
        }
        Ok(cols)
    }

    fn pos(&self, name: &str) -> Option<usize> {
        COLUMNS
            .iter()
            .position(|c| *c == name)
            .and_then(|k| self.index[k])
    }

    fn parse_row(&self, line: &str, row_index: u64) -> Res<GazeSample> {
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != self.count {
            return Err(format!(
                "expected {} fields, found {}",
                self.count,
                fields.len()
            ));
        }
        let row = Row {
            cols: self,
            fields: &fields,
        };
        let time: i64 = row.parse_req("time_ns")?;
        let valid = row.flag("valid")?.unwrap_or(false);
        let tracked = row.flag("tracked")?.unwrap_or(valid);
        if tracked && !valid {
            return Err("tracked=1 requires valid=1 (OpenXR: tracked implies valid)".into());
        }
        let gaze = GazeRay {
            origin: row.vec3("origin_")?.unwrap_or(Vec3::ZERO),
            direction: row
                .vec3("dir_")?
                .ok_or("dir_x/dir_y/dir_z must not be empty")?,
        };
        let eyes = match (row.ray("left_")?, row.ray("right_")?) {
            (Some(l), Some(r)) => Some([l, r]),
            (None, None) => None,
            _ => {
                return Err(
                    "per-eye rays come in pairs: fill both left_* and right_* or neither".into(),
                )
            }
        };
        if valid {
            check_unit("dir", gaze.direction)?;
            for (eye, r) in ["left_dir", "right_dir"].iter().zip(eyes.iter().flatten()) {
                check_unit(eye, r.direction)?;
            }
        }
        let default_state = if valid {
            EyeState::Open
        } else {
            EyeState::NotDetected
        };
        Ok(GazeSample {
            time,
            time_kind: match row.get("time_kind") {
                None | Some("") => SampleTimeKind::Measured,
                Some(s) => SampleTimeKind::parse(s).ok_or_else(|| {
                    format!("time_kind `{s}` is not measured/interpolated/predicted/unknown")
                })?,
            },
            sequence: row.parse_opt("seq")?.unwrap_or(row_index),
            gaze,
            eyes,
            valid,
            tracked,
            eye_state: [
                row.eye_state("left_state")?.unwrap_or(default_state),
                row.eye_state("right_state")?.unwrap_or(default_state),
            ],
            confidence: row.float("confidence")?,
            convergence_distance: row.float("convergence_m")?,
        })
    }
}

fn check_unit(name: &str, d: Vec3) -> Res<()> {
    let len = d.length();
    if (len - 1.0).abs() > UNIT_TOLERANCE {
        return Err(format!(
            "{name} has length {len}, not unit (±{UNIT_TOLERANCE}); traces store unit view-space directions — \
             degrees or screen positions need an importer"
        ));
    }
    Ok(())
}

struct Row<'a> {
    cols: &'a Columns,
    fields: &'a [&'a str],
}

impl Row<'_> {
    fn get(&self, name: &str) -> Option<&str> {
        self.cols.pos(name).map(|p| self.fields[p])
    }

    fn parse_opt<T: std::str::FromStr>(&self, name: &str) -> Res<Option<T>> {
        match self.get(name) {
            None | Some("") => Ok(None),
            Some(v) => v
                .parse()
                .map(Some)
                .map_err(|_| format!("{name} `{v}` is not a valid {}", std::any::type_name::<T>())),
        }
    }

    fn parse_req<T: std::str::FromStr>(&self, name: &str) -> Res<T> {
        self.parse_opt(name)?
            .ok_or_else(|| format!("{name} must not be empty"))
    }

    fn float(&self, name: &str) -> Res<Option<f32>> {
        match self.parse_opt::<f32>(name)? {
            Some(v) if !v.is_finite() => {
                Err(format!("{name} is {v}; NaN and infinities are not allowed"))
            }
            v => Ok(v),
        }
    }

    fn flag(&self, name: &str) -> Res<Option<bool>> {
        match self.get(name) {
            None | Some("") => Ok(None),
            Some("0") => Ok(Some(false)),
            Some("1") => Ok(Some(true)),
            Some(v) => Err(format!("{name} `{v}` must be 0 or 1")),
        }
    }

    fn eye_state(&self, name: &str) -> Res<Option<EyeState>> {
        match self.get(name) {
            None | Some("") => Ok(None),
            Some(v) => EyeState::parse(v)
                .map(Some)
                .ok_or_else(|| format!("{name} `{v}` must be open, closed or not_detected")),
        }
    }

    /// All three of `{prefix}x/y/z`, or `None` when the columns are absent or all empty.
    fn vec3(&self, prefix: &str) -> Res<Option<Vec3>> {
        let parts = ["x", "y", "z"].map(|a| format!("{prefix}{a}"));
        let values = [
            self.float(&parts[0])?,
            self.float(&parts[1])?,
            self.float(&parts[2])?,
        ];
        match values {
            [Some(x), Some(y), Some(z)] => Ok(Some(Vec3::new(x, y, z))),
            [None, None, None] => Ok(None),
            _ => Err(format!("{prefix}x/y/z must be all filled or all empty")),
        }
    }

    fn ray(&self, eye: &str) -> Res<Option<GazeRay>> {
        let origin = self.vec3(&format!("{eye}origin_"))?;
        let direction = self.vec3(&format!("{eye}dir_"))?;
        match (origin, direction) {
            (o, Some(d)) => Ok(Some(GazeRay {
                origin: o.unwrap_or(Vec3::ZERO),
                direction: d,
            })),
            (None, None) => Ok(None),
            (Some(_), None) => Err(format!("{eye}origin_* given without {eye}dir_*")),
        }
    }
}
