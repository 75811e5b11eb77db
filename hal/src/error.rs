//! One error type for the crate. Every variant names the file (or "<builtin:NAME>" / "<input>"),
//! where in it (line or key), and why, so a user can fix the input without reading code.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum HalError {
    #[error("{file}: cannot read or write: {source}")]
    Io {
        file: PathBuf,
        #[source]
        source: std::io::Error,
    },

    /// TOML syntax, unknown key, missing key or wrong type (the toml message carries line/column).
    #[error("{file}: {message}")]
    Toml { file: PathBuf, message: String },

    /// A key parsed but its value is out of range or inconsistent.
    #[error("{file}: key `{key}`: {reason}")]
    InvalidValue {
        file: PathBuf,
        key: String,
        reason: String,
    },

    /// A trace or import file problem at a specific line (1-based).
    #[error("{file}:{line}: {reason}")]
    Trace {
        file: PathBuf,
        line: usize,
        reason: String,
    },

    #[error(
        "unknown headset `{name}`: not a file and not a built-in profile (built-in: {available})"
    )]
    UnknownHeadset { name: String, available: String },

    #[error("{file}: already exists; refusing to overwrite (ask for overwrite explicitly)")]
    AlreadyExists { file: PathBuf },

    #[error("invalid --gaze value `{input}`: {reason}")]
    GazeSpec { input: String, reason: String },

    /// A command-line value out of range (`--latency-ms`, `--tracker-hz`, `--gaze-predict`).
    #[error("{flag}: {reason}")]
    Flag { flag: &'static str, reason: String },

    #[error("simulator script: step {index}: {reason}")]
    Script { index: usize, reason: String },

    /// Device backend failures (no runtime, no eye tracker, runtime call failed).
    #[error("{backend}: {reason}")]
    Backend {
        backend: &'static str,
        reason: String,
    },
}

impl HalError {
    pub(crate) fn io(file: impl Into<PathBuf>, source: std::io::Error) -> Self {
        HalError::Io {
            file: file.into(),
            source,
        }
    }

    pub(crate) fn trace(file: impl Into<PathBuf>, line: usize, reason: impl Into<String>) -> Self {
        HalError::Trace {
            file: file.into(),
            line,
            reason: reason.into(),
        }
    }

    pub(crate) fn invalid(
        file: impl Into<PathBuf>,
        key: impl Into<String>,
        reason: impl Into<String>,
    ) -> Self {
        HalError::InvalidValue {
            file: file.into(),
            key: key.into(),
            reason: reason.into(),
        }
    }
}
