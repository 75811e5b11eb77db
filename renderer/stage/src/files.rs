//! Files written whole or not at all ([`write_atomic`]): the bytes go to a temporary file in
//! the target's folder, are synced, and the temporary is renamed over the target, so a failed or
//! killed write leaves the old file (or none) and never a half-written one. Only regular files
//! are replaced: a symbolic link, device or FIFO at the target is refused. Inputs are read only
//! from regular files ([`check_regular_input`]).

use anyhow::{anyhow, bail, Context, Result};
use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Temporary files are `.<name>.<pid>.<n>.tmp` next to their target.
pub const TEMP_SUFFIX: &str = ".tmp";

/// What kind of thing a path is, for messages ("a symbolic link", "a FIFO", ...).
pub fn kind_of(meta: &std::fs::Metadata) -> &'static str {
    fovea_hal::file::file_kind(&meta.file_type())
}

/// Refuses a target that exists and is not a regular file (a link could redirect the write, a
/// device or FIFO is not an output).
pub fn check_replaceable(path: &Path) -> Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(meta) if !meta.file_type().is_file() => {
            bail!(
                "{} is {}; fovea only writes or replaces regular files",
                path.display(),
                kind_of(&meta)
            )
        }
        Ok(_) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e).with_context(|| format!("inspecting {}", path.display())),
    }
}

/// A temporary file removed on drop unless it was renamed into place.
struct TempFile {
    path: PathBuf,
    committed: bool,
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

fn temp_path_for(path: &Path) -> Result<PathBuf> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path
        .file_name()
        .ok_or_else(|| anyhow!("{} has no file name", path.display()))?
        .to_string_lossy();
    // A bounded prefix keeps the temporary's name legal even for a target name near NAME_MAX.
    let short: String = name.chars().take(64).collect();
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    Ok(path.with_file_name(format!(".{short}.{}.{n}{TEMP_SUFFIX}", std::process::id())))
}

/// A file written over time (a per-frame log) that appears under its name only when
/// [`AtomicWriter::commit`] renames it into place; dropped uncommitted, the temporary is removed
/// and an existing file at the path stays as it was.
pub struct AtomicWriter {
    path: PathBuf,
    temp: TempFile,
    writer: BufWriter<File>,
}

impl AtomicWriter {
    pub fn create(path: &Path) -> Result<AtomicWriter> {
        check_replaceable(path)?;
        let temp = TempFile {
            path: temp_path_for(path)?,
            committed: false,
        };
        // create_new: never opens something already there (a planted link at the temporary's name).
        let file = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&temp.path)
            .with_context(|| format!("writing {}", path.display()))?;
        Ok(AtomicWriter {
            path: path.to_path_buf(),
            temp,
            writer: BufWriter::new(file),
        })
    }

    pub fn writer(&mut self) -> &mut BufWriter<File> {
        &mut self.writer
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Syncs the temporary and renames it over the target.
    pub fn commit(self) -> Result<()> {
        let AtomicWriter {
            path,
            mut temp,
            writer,
        } = self;
        let file = writer
            .into_inner()
            .map_err(|e| e.into_error())
            .with_context(|| format!("writing {}", path.display()))?;
        // On disk before the rename, so a crash leaves the old file or the complete new one.
        file.sync_data()
            .with_context(|| format!("writing {}", path.display()))?;
        drop(file);
        check_replaceable(&path)?; // a link planted while we wrote is refused, not followed
        std::fs::rename(&temp.path, &path)
            .with_context(|| format!("moving the new {} into place", path.display()))?;
        temp.committed = true;
        Ok(())
    }
}

/// Writes `path` atomically with `write` filling a buffered writer. On any error (or a panic in
/// `write`) the temporary file is removed and an existing `path` is left exactly as it was.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<()>,
) -> Result<()> {
    let mut out = AtomicWriter::create(path)?;
    write(out.writer()).with_context(|| format!("writing {}", path.display()))?;
    out.commit()
}

/// Text (reports, tables) written atomically.
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    write_atomic(path, |w| Ok(w.write_all(text.as_bytes())?))
}

/// Refuses an input image that is not a regular file: a FIFO would block the reader and a device
/// never ends; references and frames are regular files.
pub fn check_regular_input(path: &Path) -> Result<()> {
    let meta = std::fs::metadata(path).with_context(|| format!("reading {}", path.display()))?;
    if !meta.is_file() {
        bail!(
            "reading {}: it is {}, not a regular file",
            path.display(),
            kind_of(&meta)
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use fovea_test_kit::file_names as names;

    #[test]
    fn a_failed_write_keeps_the_old_file_and_leaves_no_temporary() {
        let d = std::env::temp_dir().join(format!("fovea-files-{}-failed", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        let target = d.join("report.json");
        std::fs::write(&target, "old").unwrap();
        let err = write_atomic(&target, |w| {
            w.write_all(b"half of the new")?;
            bail!("disk on fire")
        })
        .unwrap_err();
        assert!(
            format!("{err:#}").contains("report.json")
                && format!("{err:#}").contains("disk on fire"),
            "{err:#}"
        );
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "old");
        assert_eq!(names(&d), vec!["report.json"], "the temporary is removed");
        write_text(&target, "new").unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new");
        assert_eq!(names(&d), vec!["report.json"]);
    }
}
