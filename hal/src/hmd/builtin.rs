//! Built-in headset profiles: the files in `config/headsets/` compiled into the binary, so tools work
//! from any directory. A file on disk with the same name wins, so users can edit profiles.

use super::HmdDescription;
use crate::error::HalError;
use std::path::{Path, PathBuf};

/// Directory (relative to the working directory) searched before the compiled-in copies.
pub const BUILTIN_DIR: &str = "config/headsets";

pub const DEFAULT_HEADSET: &str = "fove0";

const BUILTIN: &[(&str, &str)] = &[
    ("fove0", include_str!("../../../config/headsets/fove0.toml")),
    (
        "vive_pro_eye",
        include_str!("../../../config/headsets/vive_pro_eye.toml"),
    ),
    (
        "varjo_aero",
        include_str!("../../../config/headsets/varjo_aero.toml"),
    ),
    (
        "quest_pro",
        include_str!("../../../config/headsets/quest_pro.toml"),
    ),
    ("psvr2", include_str!("../../../config/headsets/psvr2.toml")),
    (
        "pimax_crystal",
        include_str!("../../../config/headsets/pimax_crystal.toml"),
    ),
    (
        "varjo_xr4",
        include_str!("../../../config/headsets/varjo_xr4.toml"),
    ),
];

/// Names of the compiled-in profiles, default (`fove0`) first.
pub fn builtin_names() -> Vec<&'static str> {
    BUILTIN.iter().map(|(n, _)| *n).collect()
}

impl HmdDescription {
    /// The compiled-in profile `name` (ignores files on disk).
    pub fn builtin(name: &str) -> Result<HmdDescription, HalError> {
        let (n, text) = BUILTIN
            .iter()
            .find(|(n, _)| *n == name)
            .ok_or_else(|| unknown(name))?;
        HmdDescription::parse(text, &PathBuf::from(format!("<builtin:{n}>")))
    }

    /// The default device: the simulated FOVE 0.
    pub fn fove0() -> HmdDescription {
        // Covered by tests: the built-in profile always parses.
        HmdDescription::builtin(DEFAULT_HEADSET).expect("built-in fove0 profile is valid")
    }

    /// All compiled-in profiles, parsed, default first (for `fovea headsets`).
    pub fn list_builtin() -> Vec<HmdDescription> {
        BUILTIN
            .iter()
            .filter_map(|(n, _)| HmdDescription::builtin(n).ok())
            .collect()
    }

    /// Resolve a `--headset <name|path>` argument:
    /// 1. an existing file path (or anything ending in `.toml`) is loaded;
    /// 2. `config/headsets/<name>.toml` under the working directory, if present;
    /// 3. the compiled-in profile `<name>`.
    pub fn resolve(spec: &str) -> Result<HmdDescription, HalError> {
        let as_path = Path::new(spec);
        if as_path.is_file() || spec.ends_with(".toml") {
            return HmdDescription::load(as_path);
        }
        let on_disk = Path::new(BUILTIN_DIR).join(format!("{spec}.toml"));
        if on_disk.is_file() {
            return HmdDescription::load(&on_disk);
        }
        HmdDescription::builtin(spec)
    }
}

fn unknown(name: &str) -> HalError {
    HalError::UnknownHeadset {
        name: name.to_string(),
        available: builtin_names().join(", "),
    }
}
