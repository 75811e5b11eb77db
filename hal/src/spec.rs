//! `--gaze center | X,Y | sim[:seed] | gazebase:<file> | degrees:<file> | <trace path>` for the
//! CLI.

use crate::error::HalError;
use crate::hmd::HmdDescription;
use crate::sample::Eye;
use crate::sim::{SimConfig, SimulatedFove};
use crate::source::{FixedGaze, GazeSource};
use crate::trace::import::{self, DEGREES_COLUMNS};
use crate::trace::{Playback, Trace};
use glam::{Vec2, Vec3};
use std::path::{Path, PathBuf};
use std::str::FromStr;

#[derive(Debug, Clone, PartialEq)]
pub enum GazeSpec {
    /// Straight ahead.
    Center,
    /// A fixed pixel position in the left eye's image (x right, y down).
    Fixed {
        x: f32,
        y: f32,
    },
    Simulated {
        seed: u64,
    },
    Trace(PathBuf),
    /// A GazeBase-style dataset CSV (`n` ms, `x`/`y` degrees, optional `val`), imported on open.
    GazeBase(PathBuf),
    /// A recording in degrees from the screen centre (`t_s,x_deg,y_deg,valid`), placed on the
    /// left eye's view (`trace::import::import_degrees`), imported on open.
    Degrees(PathBuf),
}

impl FromStr for GazeSpec {
    type Err = HalError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let err = |reason: &str| HalError::GazeSpec {
            input: s.to_string(),
            reason: reason.to_string(),
        };
        let t = s.trim();
        if t.is_empty() {
            return Err(err(
                "empty; expected center, X,Y, sim[:seed], gazebase:FILE, degrees:FILE or a trace file path",
            ));
        }
        if t.eq_ignore_ascii_case("center") || t.eq_ignore_ascii_case("centre") {
            return Ok(GazeSpec::Center);
        }
        if t == "sim" {
            return Ok(GazeSpec::Simulated {
                seed: SimConfig::default().seed,
            });
        }
        if let Some(seed) = t.strip_prefix("sim:") {
            let seed = seed
                .parse()
                .map_err(|_| err("the seed after `sim:` must be a non-negative integer"))?;
            return Ok(GazeSpec::Simulated { seed });
        }
        if let Some(path) = t.strip_prefix("gazebase:") {
            if path.is_empty() {
                return Err(err("a file must follow `gazebase:`"));
            }
            return Ok(GazeSpec::GazeBase(PathBuf::from(path)));
        }
        if let Some(path) = t.strip_prefix("degrees:") {
            if path.is_empty() {
                return Err(err("a file must follow `degrees:`"));
            }
            return Ok(GazeSpec::Degrees(PathBuf::from(path)));
        }
        // Something that starts like a number, or two things that parse as numbers (`NaN,5`,
        // `inf,0`), with a comma, is meant as pixel coordinates, never as a trace file name.
        if let Some((x, y)) = t.split_once(',') {
            let number = |v: &str| v.trim().parse::<f32>().ok();
            let numeric_start =
                t.starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '+' || c == '.');
            if numeric_start || (number(x).is_some() && number(y).is_some()) {
                return match (number(x), number(y)) {
                    (Some(x), Some(y)) if x.is_finite() && y.is_finite() => {
                        Ok(GazeSpec::Fixed { x, y })
                    }
                    (Some(x), Some(y)) => Err(err(&format!(
                        "X,Y must be finite pixel coordinates; got {x} and {y}"
                    ))),
                    _ => Err(err(
                        "expected X,Y as two finite pixel coordinates, e.g. 640,720",
                    )),
                };
            }
        }
        Ok(GazeSpec::Trace(PathBuf::from(t)))
    }
}

/// Whether `path` starts with the header of a degrees recording (`t_s,x_deg,y_deg,valid`): such
/// a file given as a plain path is imported as `degrees:` would.
fn is_degrees_file(path: &Path) -> Result<bool, HalError> {
    let header = crate::file::read_first_line(path, 256)?;
    Ok(header.split(',').map(str::trim).eq(DEGREES_COLUMNS))
}

impl GazeSpec {
    /// The recorded samples a file spec names (a fovea trace, or a degrees / GazeBase recording
    /// imported for `hmd`'s left eye); other specs have no recording.
    pub fn recording(&self, hmd: &HmdDescription) -> Result<Trace, HalError> {
        match self {
            GazeSpec::Trace(path) if is_degrees_file(path)? => {
                import::import_degrees(path, &hmd.eye(Eye::Left).fov)
            }
            GazeSpec::Trace(path) => Trace::load(path),
            GazeSpec::GazeBase(path) => {
                import::import_gazebase(path, &import::DegreesImport::default())
            }
            GazeSpec::Degrees(path) => import::import_degrees(path, &hmd.eye(Eye::Left).fov),
            other => Err(HalError::GazeSpec {
                input: format!("{other:?}"),
                reason: "not a recording: name a trace file, degrees:FILE or gazebase:FILE".into(),
            }),
        }
    }

    /// Build the gaze source this spec names for a headset.
    pub fn open(&self, hmd: HmdDescription) -> Result<Box<dyn GazeSource>, HalError> {
        Ok(match self {
            GazeSpec::Center => Box::new(FixedGaze::new(hmd, Vec3::NEG_Z)),
            GazeSpec::Fixed { x, y } => {
                // Off the image the pixel → direction mapping has no meaning (1e30 would come back
                // as a silent fallback to the centre).
                let eye = hmd.eye(Eye::Left);
                let (w, h) = (eye.recommended_width as f32, eye.recommended_height as f32);
                // One pixel of slack: callers that scale render pixels to headset pixels round.
                if !((-1.0..=w + 1.0).contains(x) && (-1.0..=h + 1.0).contains(y)) {
                    return Err(HalError::GazeSpec {
                        input: format!("{x:?},{y:?}"),
                        reason: format!(
                            "outside the {w}×{h} left-eye image of headset `{}`",
                            hmd.id
                        ),
                    });
                }
                let dir = hmd.pixel_to_direction(Eye::Left, Vec2::new(*x, *y));
                Box::new(FixedGaze::new(hmd, dir))
            }
            GazeSpec::Simulated { seed } => {
                Box::new(SimulatedFove::new(hmd, SimConfig::seeded(*seed))?)
            }
            GazeSpec::Trace(_) | GazeSpec::GazeBase(_) | GazeSpec::Degrees(_) => {
                let trace = self.recording(&hmd)?;
                let playback = Playback::new(trace, hmd);
                Box::new(match self {
                    // fovea traces keep their clock (a recording of a session replays on it).
                    GazeSpec::Trace(path) if !is_degrees_file(path)? => playback,
                    // Dataset times start anywhere: frame 0 shows the first sample.
                    _ => playback.aligned_to_first_frame(),
                })
            }
        })
    }
}
