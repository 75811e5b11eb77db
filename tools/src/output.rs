//! Writes what a run produces: PNG and linear EXR images, JSON and text reports — every one
//! through [`write_atomic`]: the bytes go to a temporary file in the target's folder, are synced,
//! and the temporary is renamed over the target, so a failed or killed write leaves the old file
//! (or none) and never a half-written one. Only regular files are replaced: a symbolic link,
//! device or FIFO at the target is refused.
//!
//! Output folders ([`prepare_output_dir`]) must hold only files fovea writes, no symbolic links,
//! and are locked (`.fovea.lock`, an advisory `flock`) while a run writes into them, so two runs
//! cannot interleave their frames.

use anyhow::{bail, Context, Result};
use fovea_renderer::passes::tonemap::ToneCurve;
pub use fovea_stage::files::{
    check_regular_input, write_atomic, write_text, AtomicWriter, TEMP_SUFFIX,
};
use fovea_stage::files::{check_replaceable, kind_of};
use std::ffi::OsString;
use std::fs::{File, OpenOptions};

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Name of the lock file inside an output folder.
pub const LOCK_FILE: &str = ".fovea.lock";
/// A run's outputs are written into `.fovea-run.<pid>.<n>` inside its output folder
/// ([`OutputDir::stage`]) and moved out when the run is complete.
const STAGING_PREFIX: &str = ".fovea-run.";
/// The file whose presence says an output folder holds a complete run (written last).
pub const REPORT_FILE: &str = "report.json";
/// Pretty JSON with a trailing newline, written atomically.
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> Result<()> {
    write_text(path, &(serde_json::to_string_pretty(value)? + "\n"))
}

/// An 8-bit image (`color`: Rgb8 or Rgba8) as PNG, written atomically.
pub fn write_image(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[u8],
    color: image::ExtendedColorType,
) -> Result<()> {
    write_atomic(path, |w| {
        Ok(image::write_buffer_with_format(
            w,
            pixels,
            width,
            height,
            color,
            image::ImageFormat::Png,
        )?)
    })
}

pub fn write_png(path: &Path, width: u32, height: u32, rgba8: &[u8]) -> Result<()> {
    write_image(path, width, height, rgba8, image::ExtendedColorType::Rgba8)
}

/// Linear float RGB(A) EXR, written atomically.
pub fn write_exr(path: &Path, width: u32, height: u32, texels: &[[f32; 4]]) -> Result<()> {
    use exr::prelude::*;
    let w = width as usize;
    if texels.len() != w * height as usize {
        bail!(
            "{}: {} texels do not make a {width}×{height} image",
            path.display(),
            texels.len()
        );
    }
    let channels = SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
        let t = texels[y * w + x];
        (t[0], t[1], t[2], 1.0f32)
    });
    // Tiles in increasing order: the parallel compressor otherwise writes them as they finish,
    // and the same pixels would give different bytes from run to run (`fovea sweep merge`
    // promises one process's files byte for byte).
    let encoding = Encoding {
        line_order: LineOrder::Increasing,
        ..Encoding::FAST_LOSSLESS
    };
    write_atomic(path, |out| {
        Ok(
            Image::from_encoded_channels((w, height as usize), encoding, channels)
                .write()
                .to_buffered(out)?,
        )
    })
}

/// Reads a linear EXR's RGB channels (references for `fovea eval` and tests): a regular file of
/// at most [`fovea_stage::decode::MAX_IMAGE_FILE_BYTES`], declaring at most
/// [`fovea_stage::decode::MAX_IMAGE_PIXELS`] (checked from its headers before pixels are allocated).
pub fn read_exr(path: &Path) -> Result<(u32, u32, Vec<[f32; 4]>)> {
    fovea_stage::decode::read_exr(path, fovea_stage::decode::MAX_IMAGE_PIXELS, None)
}

/// Refuses to replace an existing file unless `force` is set, and refuses any target that is not a
/// regular file even with `force`. Nothing is deleted here: the new file replaces the old one
/// only once it is complete ([`write_atomic`]).
pub fn check_new_file(path: &Path, force: bool) -> Result<()> {
    check_replaceable(path)?;
    if path.exists() && !force {
        bail!(
            "{} already exists; pass --force to replace it",
            path.display()
        );
    }
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("creating {}", parent.display()))?;
    }
    Ok(())
}

/// Names fovea writes into an output folder.
fn is_fovea_file(name: &str) -> bool {
    matches!(
        name,
        "report.json"
            | "eval.json"
            | "eval.png"
            | "quality.json"
            | "quality.md"
            | "frames.jsonl"
            | "replay.json"
            | "replay.md"
            | "overview.png"
            | "perceptual.json"
            | "perceptual.md"
    ) || (name.starts_with("reference_") && (name.ends_with(".exr") || name.ends_with(".png")))
        || (name.starts_with("frame_") && (name.ends_with(".png") || name.ends_with(".exr")))
        || (name.starts_with("debug_")
            && [".png", ".exr", ".json"].iter().any(|e| name.ends_with(e)))
        || (name.starts_with("rays_") && name.ends_with(".bin"))
        || (name.starts_with("jod_") && name.ends_with(".png"))
}

/// A temporary of [`write_atomic`] (left behind only by a killed process).
fn is_fovea_temp(name: &str) -> bool {
    name.starts_with('.') && name.ends_with(TEMP_SUFFIX)
}

/// Identity of a file version: a rename over it makes a new inode with a new change time.
type Version = (u64, i64, i64);

#[cfg(unix)]
fn identity(meta: &std::fs::Metadata) -> Version {
    use std::os::unix::fs::MetadataExt;
    (meta.ino(), meta.ctime(), meta.ctime_nsec())
}

#[cfg(not(unix))]
fn identity(meta: &std::fs::Metadata) -> Version {
    let t = meta
        .modified()
        .ok()
        .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
        .unwrap_or_default();
    (meta.len(), t.as_secs() as i64, t.subsec_nanos() as i64)
}

/// An output folder held by this run: locked until dropped, with the fovea files an earlier run
/// left in it.
#[derive(Debug)]
#[must_use = "the output folder is locked only while this value lives"]
pub struct OutputDir {
    path: PathBuf,
    _lock: File,
    previous: Vec<(OsString, Version)>,
}

/// Creates `dir` or accepts an existing one holding only files fovea writes (frames, reports,
/// debug views, `fovea quality`'s `run_*` folders); anything else in it, a symbolic link
/// included, means the user chose the wrong folder and nothing is touched. Then locks it against
/// a second concurrent run.
pub fn prepare_output_dir(dir: &Path) -> Result<OutputDir> {
    if dir.exists() && !dir.is_dir() {
        bail!("output {} exists and is not a folder", dir.display());
    }
    if dir.exists() {
        scan(dir, false)?; // refuse before creating the lock file in a user's folder
    }
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let lock = lock_folder(dir)?;
    // Under the lock no other run writes here, so leftover temporaries are a dead run's.
    let previous = scan(dir, true)?;
    Ok(OutputDir {
        path: dir.to_path_buf(),
        _lock: lock,
        previous,
    })
}

fn lock_folder(dir: &Path) -> Result<File> {
    let path = dir.join(LOCK_FILE);
    check_replaceable(&path)?;
    let file = OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(&path)
        .with_context(|| format!("opening {}", path.display()))?;
    match file.try_lock() {
        Ok(()) => Ok(file),
        Err(std::fs::TryLockError::WouldBlock) => bail!(
            "output folder {} is in use by another fovea run (it holds {LOCK_FILE}); wait for it to finish or choose another folder",
            dir.display()
        ),
        Err(std::fs::TryLockError::Error(e)) => Err(e).with_context(|| format!("locking {}", path.display())),
    }
}

/// Checks every entry; returns the fovea files found (name and version). With `clean`, removes
/// leftover temporaries.
fn scan(dir: &Path, clean: bool) -> Result<Vec<(OsString, Version)>> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))? {
        let entry = entry?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let meta = match std::fs::symlink_metadata(entry.path()) {
            Ok(meta) => meta,
            // Renamed or removed since read_dir listed it (a run's temporary moving into place).
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => continue,
            Err(e) => {
                return Err(e).with_context(|| format!("inspecting {}", entry.path().display()))
            }
        };
        if meta.file_type().is_symlink() {
            bail!(
                "output folder {} holds a symbolic link '{name}'; fovea does not write through links (remove it or choose another folder)",
                dir.display()
            );
        }
        let regular = meta.file_type().is_file();
        if name == LOCK_FILE && regular {
            continue;
        }
        // `fovea quality` keeps one `fovea render` folder per run (checked when reused).
        if name.starts_with("run_") && meta.is_dir() {
            continue;
        }
        // A run's staging folder: under the lock, one a dead run left.
        if name.starts_with(STAGING_PREFIX) && meta.is_dir() {
            if clean {
                let _ = std::fs::remove_dir_all(entry.path());
            }
            continue;
        }
        if is_fovea_temp(&name) && regular {
            if clean {
                let _ = std::fs::remove_file(entry.path());
            }
            continue;
        }
        if !is_fovea_file(&name) {
            bail!("output folder {} holds '{name}', which fovea did not write; choose an empty or new folder", dir.display());
        }
        if !regular {
            bail!(
                "output folder {} holds '{name}', which is {}; fovea writes only regular files",
                dir.display(),
                kind_of(&meta)
            );
        }
        found.push((entry.file_name(), identity(&meta)));
    }
    Ok(found)
}

impl OutputDir {
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// A hidden folder inside this one that a run writes all its files into; [`Staged::commit`]
    /// moves them out (renames only: no space needed), so a run that fails for any reason (a full
    /// disk, an error) leaves the earlier run's files exactly as they were.
    pub fn stage(&self) -> Result<Staged> {
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let dir = self
            .path
            .join(format!("{STAGING_PREFIX}{}.{n}", std::process::id()));
        std::fs::create_dir(&dir).with_context(|| format!("creating {}", dir.display()))?;
        Ok(Staged {
            dir,
            committed: false,
        })
    }

    /// Removes the fovea files an earlier run left that this run did not rewrite (frames beyond
    /// this run's count, EXR or debug files it did not produce), so the folder holds exactly this
    /// run's outputs. Returns how many were removed.
    pub fn remove_stale(&self) -> Result<usize> {
        let mut removed = 0;
        for (name, version) in &self.previous {
            let path = self.path.join(name);
            let unchanged = std::fs::symlink_metadata(&path)
                .is_ok_and(|m| m.file_type().is_file() && identity(&m) == *version);
            if unchanged {
                std::fs::remove_file(&path)
                    .with_context(|| format!("removing the stale {}", path.display()))?;
                removed += 1;
            }
        }
        Ok(removed)
    }
}

/// A run's files while it writes them: removed with everything in them unless committed.
#[must_use = "the staged files are removed unless committed"]
pub struct Staged {
    dir: PathBuf,
    committed: bool,
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.dir);
        }
    }
}

impl Staged {
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// Moves the staged files into `out` as one run: the earlier run's [`REPORT_FILE`] is removed
    /// first and the new one moved in last, so the folder holds a report only beside the files of
    /// its run (a process killed while moving leaves no report: an incomplete folder); then the
    /// earlier run's files that this one did not rewrite are removed ([`OutputDir::remove_stale`]).
    pub fn commit(mut self, out: &OutputDir) -> Result<usize> {
        let report = out.path.join(REPORT_FILE);
        match std::fs::remove_file(&report) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                return Err(e).with_context(|| format!("removing the earlier {}", report.display()))
            }
            _ => {}
        }
        let mut names: Vec<OsString> = std::fs::read_dir(&self.dir)
            .with_context(|| format!("reading {}", self.dir.display()))?
            .map(|e| e.map(|e| e.file_name()))
            .collect::<std::io::Result<_>>()?;
        names.sort_by_key(|n| n == REPORT_FILE);
        for name in names {
            let (from, to) = (self.dir.join(&name), out.path.join(&name));
            check_replaceable(&to)?;
            std::fs::rename(&from, &to)
                .with_context(|| format!("moving {} into place", to.display()))?;
        }
        self.committed = true;
        let _ = std::fs::remove_dir(&self.dir);
        out.remove_stale()
    }
}

/// Linear radiance → sRGB RGBA8 through `curve` at `exposure`, as the tonemap pass displays it
/// (`shaders/common/tone.glsl`; previews and references).
pub fn tonemap_preview(texels: &[[f32; 4]], exposure: f32, curve: ToneCurve) -> Vec<u8> {
    let srgb = |c: f32| {
        if c <= 0.0031308 {
            c * 12.92
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        }
    };
    texels
        .iter()
        .flat_map(|t| {
            let c = tone_curve(curve, [t[0], t[1], t[2]].map(|c| (c * exposure).max(0.0)));
            let px = |c: f32| (srgb(c.clamp(0.0, 1.0)) * 255.0 + 0.5) as u8;
            [px(c[0]), px(c[1]), px(c[2]), 255]
        })
        .collect()
}

/// The display transforms of `shaders/common/tone.glsl` on the host.
pub fn tone_curve(curve: ToneCurve, c: [f32; 3]) -> [f32; 3] {
    match curve {
        ToneCurve::Clamp => c,
        ToneCurve::Aces => {
            c.map(|x| ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0))
        }
        ToneCurve::Neutral => {
            const START: f32 = 0.8 - 0.04;
            const DESATURATION: f32 = 0.15;
            let x = c[0].min(c[1]).min(c[2]);
            let offset = if x < 0.08 { x - 6.25 * x * x } else { 0.04 };
            let c = c.map(|v| v - offset);
            let peak = c[0].max(c[1]).max(c[2]);
            if peak < START {
                return c;
            }
            let d = 1.0 - START;
            let new_peak = 1.0 - d * d / (peak + d - START);
            let g = 1.0 - 1.0 / (DESATURATION * (peak - new_peak) + 1.0);
            c.map(|v| v * new_peak / peak * (1.0 - g) + new_peak * g)
        }
    }
}

#[cfg(test)]
#[path = "output_tests.rs"]
mod tests;
