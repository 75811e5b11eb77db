//! Reading the text files hal is given (gaze traces, dataset CSVs, headset and simulator TOML)
//! safely: only regular files are opened, non-blocking, so `--gaze /dev/zero` or a FIFO is
//! refused at once instead of reading without end or waiting for a writer; the size is checked
//! against a documented limit before anything is allocated, and the read itself is bounded.

use crate::error::HalError;
use std::io::Read;
use std::path::Path;

/// Largest gaze trace or dataset CSV read (256 MiB): about a million rows of the full trace format
/// (~250 bytes each), i.e. over two hours at 120 Hz. Longer recordings: split them.
pub const MAX_TRACE_BYTES: u64 = 256 << 20;
/// Largest headset or simulator TOML profile read (1 MiB; real ones are a few KiB).
pub const MAX_PROFILE_BYTES: u64 = 1 << 20;

fn refuse(path: &Path, reason: String) -> HalError {
    HalError::io(path, std::io::Error::other(reason))
}

/// Reads `path` as UTF-8 text of at most `limit` bytes; `what` names it in the size error.
/// Public so the tools read their own TOML profiles the same way.
pub fn read_text(path: &Path, limit: u64, what: &str) -> Result<String, HalError> {
    let file = open_nonblocking(path).map_err(|e| HalError::io(path, e))?;
    let meta = file.metadata().map_err(|e| HalError::io(path, e))?;
    if !meta.is_file() {
        return Err(refuse(
            path,
            format!("it is {}, not a regular file", file_kind(&meta.file_type())),
        ));
    }
    if meta.len() > limit {
        return Err(refuse(
            path,
            format!(
                "{} bytes is more than the {limit}-byte limit for {what}",
                meta.len()
            ),
        ));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    // One byte past the limit tells a file that grew while being read from one that fits.
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| HalError::io(path, e))?;
    if bytes.len() as u64 > limit {
        return Err(refuse(
            path,
            format!("it grew past the {limit}-byte limit for {what} while being read"),
        ));
    }
    String::from_utf8(bytes).map_err(|e| {
        refuse(
            path,
            format!(
                "not UTF-8 text (invalid byte at offset {})",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

/// The first line of `path` (at most `limit` bytes of it), with the same refusals as
/// [`read_text`]: to tell file formats apart without reading a whole file.
pub fn read_first_line(path: &Path, limit: u64) -> Result<String, HalError> {
    let file = open_nonblocking(path).map_err(|e| HalError::io(path, e))?;
    let meta = file.metadata().map_err(|e| HalError::io(path, e))?;
    if !meta.is_file() {
        return Err(refuse(
            path,
            format!("it is {}, not a regular file", file_kind(&meta.file_type())),
        ));
    }
    let mut bytes = Vec::new();
    file.take(limit)
        .read_to_end(&mut bytes)
        .map_err(|e| HalError::io(path, e))?;
    let text = String::from_utf8_lossy(&bytes);
    Ok(strip_bom(text.lines().next().unwrap_or("")).to_string())
}

#[cfg(unix)]
fn open_nonblocking(path: &Path) -> std::io::Result<std::fs::File> {
    use std::os::unix::fs::OpenOptionsExt;
    std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK | libc::O_CLOEXEC)
        .open(path)
}

#[cfg(not(unix))]
fn open_nonblocking(path: &Path) -> std::io::Result<std::fs::File> {
    std::fs::File::open(path)
}

/// What kind of thing a file type is, for messages ("a FIFO (named pipe)", "a symbolic link",
/// ...). Public so the tools word their output checks the same way.
pub fn file_kind(t: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_symlink() {
        "a symbolic link"
    } else if t.is_dir() {
        "a folder"
    } else if t.is_file() {
        "a regular file"
    } else {
        "not a file"
    }
}

/// Text without a leading UTF-8 byte-order mark (editors on Windows add one; it is not content).
pub(crate) fn strip_bom(text: &str) -> &str {
    text.strip_prefix('\u{FEFF}').unwrap_or(text)
}
