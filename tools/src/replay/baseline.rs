//! Replay baselines: under the `--baseline` folder, one folder per trace, named by the trace's
//! identity (its file stem and the first 16 hex digits of a SHA-256 of what it is: a trace
//! file's bytes, a gaze source's canonical spec), holding the frames as displayed
//! (`frame_NNNN.png`), the converged reference (`reference.exr`) and `baseline.json`: what made
//! it, per frame the gaze and its error against the reference per ring, and a manifest of every
//! file with its size and SHA-256.
//!
//! A baseline is one unit. It is written into a fresh hidden folder beside its place
//! (`.<name>.staging-<pid>-<n>`), `baseline.json` last, every file synced, and then swapped into
//! place with one rename (an atomic exchange with the old folder where the file system allows),
//! so a full disk, a signal or a crash leaves the old baseline whole or the new one whole, never
//! a mix. Writers hold an exclusive lock on the `--baseline` folder's `.fovea.lock`, readers a
//! shared one, so two updates cannot interleave and a replay never reads a half-swapped folder.
//! Nothing is written or read through a symbolic link.
//!
//! Reading checks `baseline.json` first (format, the trace's full SHA-256, bounded counts,
//! finite figures, the manifest naming exactly the frames and the reference), then every file it
//! names (a regular file, not a link, of the size and SHA-256 recorded, an image of the recorded
//! size decoded within that size, finite non-negative reference values) before anything renders.
//! Any mismatch is an error naming the file and the field.

use crate::output::LOCK_FILE;
use anyhow::{anyhow, bail, Context, Result};
use fovea_stage::decode;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::fs::{File, OpenOptions};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

pub const FORMAT: &str = "fovea-replay-baseline 2";
/// The most frames a baseline holds (and `--frames` of a new one): 1000 is 14 s at 70 Hz; a
/// replay renders every one of them.
pub const MAX_FRAMES: u32 = 1000;
/// The largest frame a baseline holds: 2048 × 2048 pixels (replays render small: 64 × 72 by default).
pub const MAX_PIXELS: u64 = 1 << 22;
/// Rings per frame and reference samples per pixel (`--rings`, `--reference-spp`).
pub const MAX_RINGS: usize = 64;
pub const MAX_REFERENCE_SPP: u32 = 1 << 16;
/// `baseline.json` is at most this long (1000 frames of 64 rings take about 2 MiB).
const MAX_MANIFEST_BYTES: u64 = 16 << 20;
const MANIFEST: &str = "baseline.json";
const REFERENCE: &str = "reference.exr";

/// The settings a baseline was made with (a replay with other settings is compared all the same:
/// that is how a changed parameter is judged; the report lists the differences).
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Params {
    pub scene: String,
    pub method: String,
    pub denoiser: String,
    pub taa: String,
    pub headset: String,
    pub width: u32,
    pub height: u32,
    pub frames: u32,
    pub seed: u32,
    pub max_depth: u32,
    pub blur_sigma_at_30: f32,
    pub reference_spp: u32,
    pub rings: usize,
    /// The camera and environment flags as given.
    pub camera: String,
    pub environment: String,
    /// The latency model's flags (`--latency-ms`, `--tracker-hz`, `--gaze-predict`); empty
    /// without one.
    pub gaze_timing: String,
}

#[derive(Serialize, Deserialize, Clone, Debug)]
#[serde(deny_unknown_fields)]
pub struct FrameRecord {
    pub frame: u32,
    /// Gaze pixel (left eye's render pixels) and where it came from (live, held, centre).
    pub gaze: [f32; 2],
    pub origin: String,
    /// Mean FLIP against the reference (tonemapped like the frame), per ring of distance from
    /// the gaze (inner first).
    pub quality_flip: Vec<Option<f64>>,
}

/// A file of the baseline: its name in the folder, size and SHA-256 (lower-case hex).
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct FileEntry {
    pub name: String,
    pub bytes: u64,
    pub sha256: String,
}

#[derive(Serialize, Deserialize, Clone, Debug)]
#[serde(deny_unknown_fields)]
pub struct Baseline {
    pub format: String,
    /// The trace (or gaze source) as given on the command line.
    pub trace: String,
    /// SHA-256 of the trace's identity ([`TraceId`]).
    pub trace_sha256: String,
    pub commit: String,
    pub device: String,
    pub params: Params,
    pub frames: Vec<FrameRecord>,
    /// Mean GPU ms per pass of the run.
    pub passes: BTreeMap<String, f64>,
    /// Every file of the baseline but this one: the frames in order, then the reference.
    pub files: Vec<FileEntry>,
}

/// What a trace is, for naming its baseline: a trace file by its bytes (the same recording
/// anywhere shares a baseline; an edited one gets a new one), a gaze source by its parsed spec.
#[derive(Clone, Debug, PartialEq)]
pub struct TraceId {
    /// The baseline folder's name: `<stem>-<16 hex digits>`.
    pub key: String,
    pub sha256: String,
}

impl TraceId {
    pub fn of(trace: &str) -> Result<TraceId> {
        use fovea_hal::GazeSpec;
        let spec: GazeSpec = trace.parse()?;
        let mut hash = Sha256::new();
        let stem = match &spec {
            GazeSpec::Trace(path) | GazeSpec::GazeBase(path) | GazeSpec::Degrees(path) => {
                let kind = match spec {
                    GazeSpec::Trace(_) => "trace",
                    GazeSpec::GazeBase(_) => "gazebase",
                    _ => "degrees",
                };
                let bytes = fovea_hal::file::read_text(
                    path,
                    fovea_hal::file::MAX_TRACE_BYTES,
                    "a gaze trace",
                )?;
                hash.update(format!("{kind}\0").as_bytes());
                hash.update(bytes.as_bytes());
                path.file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default()
            }
            GazeSpec::Center => {
                hash.update(b"source\0center");
                "center".into()
            }
            GazeSpec::Fixed { x, y } => {
                hash.update(format!(
                    "source\0fixed {:08x} {:08x}",
                    x.to_bits(),
                    y.to_bits()
                ));
                "fixed".into()
            }
            GazeSpec::Simulated { seed } => {
                hash.update(format!("source\0sim {seed}"));
                format!("sim-{seed}")
            }
        };
        let sha256 = hex(&hash.finalize());
        let readable: String = stem
            .chars()
            .take(48)
            .map(|c| match c {
                'a'..='z' | 'A'..='Z' | '0'..='9' | '_' | '-' => c,
                _ => '-',
            })
            .collect();
        Ok(TraceId {
            key: format!("{readable}-{}", &sha256[..16]),
            sha256,
        })
    }
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

pub fn sha256_hex(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

pub fn frame_name(frame: u32) -> String {
    format!("frame_{frame:04}.png")
}

/// The `--baseline` folder, locked: shared to read, exclusive to update.
pub struct Store {
    root: PathBuf,
    _lock: Option<File>,
}

impl Store {
    /// For reading. A folder where the lock file cannot be made (read-only) is read unlocked:
    /// no fovea run can update it either.
    pub fn open_read(root: &Path) -> Result<Store> {
        let meta = std::fs::metadata(root).with_context(|| {
            format!(
                "no baseline folder {} (make one with --update-baseline)",
                root.display()
            )
        })?;
        if !meta.is_dir() {
            bail!("--baseline {} is not a folder", root.display());
        }
        let path = root.join(LOCK_FILE);
        refuse_link(&path)?;
        let lock = match OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
        {
            Ok(file) => Some(file),
            Err(_) => OpenOptions::new().read(true).open(&path).ok(),
        };
        if let Some(file) = &lock {
            match file.try_lock_shared() {
                Ok(()) => {}
                Err(std::fs::TryLockError::WouldBlock) => bail!(
                    "baseline folder {} is being updated by another fovea run (it holds {LOCK_FILE}); replay when it has finished",
                    root.display()
                ),
                Err(std::fs::TryLockError::Error(e)) => {
                    return Err(e).with_context(|| format!("locking {}", path.display()))
                }
            }
        }
        Ok(Store {
            root: root.to_path_buf(),
            _lock: lock,
        })
    }

    /// For `--update-baseline`: the folder is created if missing, must not be a symbolic link,
    /// and is locked exclusively; staging folders a killed update left are removed.
    pub fn open_update(root: &Path) -> Result<Store> {
        refuse_link(root)?;
        std::fs::create_dir_all(root).with_context(|| format!("creating {}", root.display()))?;
        let path = root.join(LOCK_FILE);
        refuse_link(&path)?;
        let file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .with_context(|| format!("opening {}", path.display()))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => bail!(
                "baseline folder {} is in use by another fovea run (it holds {LOCK_FILE}); wait for it to finish",
                root.display()
            ),
            Err(std::fs::TryLockError::Error(e)) => {
                return Err(e).with_context(|| format!("locking {}", path.display()))
            }
        }
        // Under the lock no other update runs: hidden staging folders are a dead run's.
        for entry in
            std::fs::read_dir(root).with_context(|| format!("reading {}", root.display()))?
        {
            let entry = entry?;
            let name = entry.file_name().to_string_lossy().into_owned();
            let is_dir = entry.file_type().is_ok_and(|t| t.is_dir());
            if is_dir && name.starts_with('.') && name.contains(".staging-") {
                let _ = std::fs::remove_dir_all(entry.path());
            }
        }
        Ok(Store {
            root: root.to_path_buf(),
            _lock: Some(file),
        })
    }

    pub fn folder(&self, id: &TraceId) -> PathBuf {
        self.root.join(&id.key)
    }

    /// The baseline of `id`, every file checked (see the module documentation).
    pub fn load(&self, id: &TraceId) -> Result<Loaded> {
        let dir = self.folder(id);
        match std::fs::symlink_metadata(&dir) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => bail!(
                "no baseline at {} (make one with --update-baseline)",
                dir.display()
            ),
            Err(e) => return Err(e).with_context(|| format!("reading {}", dir.display())),
            Ok(m) if !m.is_dir() => bail!(
                "baseline {} is {}, not a folder; fovea reads no baseline through a link",
                dir.display(),
                fovea_hal::file::file_kind(&m.file_type())
            ),
            Ok(_) => {}
        }
        let manifest = dir.join(MANIFEST);
        refuse_link(&manifest)?;
        let bytes = decode::read_bounded(&manifest, MAX_MANIFEST_BYTES, "replay baseline")?;
        let baseline = parse_manifest(&bytes, &manifest.display().to_string(), id)?;
        let loaded = Loaded {
            dir,
            reference: Vec::new(),
            baseline,
        };
        let (w, h) = (loaded.baseline.params.width, loaded.baseline.params.height);
        for k in 0..loaded.baseline.params.frames {
            loaded.frame(k)?;
        }
        let reference_entry = loaded.entry(REFERENCE)?;
        let bytes = loaded.read_entry(reference_entry)?;
        let name = loaded.dir.join(REFERENCE).display().to_string();
        let (_, _, reference) = decode::decode_exr(&bytes, &name, MAX_PIXELS, Some((w, h)))?;
        if let Some(i) = reference
            .iter()
            .position(|t| !t[..3].iter().all(|c| c.is_finite() && *c >= 0.0))
        {
            bail!(
                "{name}: pixel ({}, {}) is {:?}; a reference holds finite radiance ≥ 0",
                i as u32 % w,
                i as u32 / w,
                reference[i]
            );
        }
        Ok(Loaded {
            reference,
            ..loaded
        })
    }

    /// A new baseline of `id`, written into a staging folder until [`Staging::commit`].
    pub fn begin(&self, id: &TraceId) -> Result<Staging> {
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let dir = self
            .root
            .join(format!(".{}.staging-{}-{n}", id.key, std::process::id()));
        std::fs::create_dir(&dir).with_context(|| format!("creating {}", dir.display()))?;
        Ok(Staging {
            dir,
            target: self.folder(id),
            files: Vec::new(),
            committed: false,
        })
    }
}

fn refuse_link(path: &Path) -> Result<()> {
    if std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink()) {
        bail!(
            "{} is a symbolic link; fovea reads and writes baselines only in place",
            path.display()
        );
    }
    Ok(())
}

/// `baseline.json` checked against itself and the trace, before any file it names is read.
pub fn parse_manifest(bytes: &[u8], name: &str, id: &TraceId) -> Result<Baseline> {
    let text = std::str::from_utf8(bytes).map_err(|e| anyhow!("{name}: not UTF-8 ({e})"))?;
    let format = serde_json::from_str::<serde_json::Value>(text)
        .ok()
        .and_then(|v| v.get("format")?.as_str().map(str::to_string));
    if let Some(format) = format.filter(|f| f != FORMAT) {
        bail!("{name}: format '{format}', expected '{FORMAT}' (remake the baseline with --update-baseline)");
    }
    let b: Baseline =
        serde_path_to_error::deserialize(&mut serde_json::Deserializer::from_str(text))
            .map_err(|e| anyhow!("{name}: not a replay baseline: {}: {}", e.path(), e.inner()))?;
    if b.trace_sha256 != id.sha256 {
        bail!(
            "{name}: trace_sha256 {} is not this trace's {} (the folder belongs to another trace)",
            b.trace_sha256,
            id.sha256
        );
    }
    let p = &b.params;
    let field = |f: &str, rule: String| -> Result<()> { bail!("{name}: params.{f} {rule}") };
    if !(1..=MAX_FRAMES).contains(&p.frames) {
        field(
            "frames",
            format!("= {} must be in 1..={MAX_FRAMES}", p.frames),
        )?;
    }
    if p.width == 0 || p.height == 0 || p.width as u64 * p.height as u64 > MAX_PIXELS {
        field(
            "width/height",
            format!(
                "= {}×{} must be at least 1×1 and at most {MAX_PIXELS} pixels",
                p.width, p.height
            ),
        )?;
    }
    if !(1..=MAX_RINGS).contains(&p.rings) {
        field("rings", format!("= {} must be in 1..={MAX_RINGS}", p.rings))?;
    }
    if !(1..=MAX_REFERENCE_SPP).contains(&p.reference_spp) {
        field(
            "reference_spp",
            format!("= {} must be in 1..={MAX_REFERENCE_SPP}", p.reference_spp),
        )?;
    }
    if b.frames.len() != p.frames as usize {
        bail!(
            "{name}: frames holds {} records, params.frames says {}",
            b.frames.len(),
            p.frames
        );
    }
    for (i, f) in b.frames.iter().enumerate() {
        if f.frame != i as u32 || f.quality_flip.len() != p.rings {
            bail!(
                "{name}: frames[{i}] is frame {} with {} rings; expected frame {i} with {} rings",
                f.frame,
                f.quality_flip.len(),
                p.rings
            );
        }
        if !f.gaze.iter().all(|c| c.is_finite()) {
            bail!("{name}: frames[{i}].gaze {:?} is not finite", f.gaze);
        }
        if !matches!(f.origin.as_str(), "live" | "held" | "centre") {
            bail!(
                "{name}: frames[{i}].origin '{}' is not live, held or centre",
                f.origin
            );
        }
        if let Some(q) = f
            .quality_flip
            .iter()
            .flatten()
            .find(|q| !(0.0..=1.0).contains(*q))
        {
            bail!("{name}: frames[{i}].quality_flip holds {q}; FLIP lies in [0, 1]");
        }
    }
    if let Some((pass, ms)) = b
        .passes
        .iter()
        .find(|(_, ms)| !(ms.is_finite() && **ms >= 0.0))
    {
        bail!("{name}: passes.{pass} = {ms} must be finite milliseconds ≥ 0");
    }
    let expected: Vec<String> = (0..p.frames)
        .map(frame_name)
        .chain([REFERENCE.to_string()])
        .collect();
    let listed: Vec<&str> = b.files.iter().map(|f| f.name.as_str()).collect();
    if listed != expected {
        bail!(
            "{name}: files lists {} entries ({}…); expected frame_0000.png to {} and {REFERENCE}",
            listed.len(),
            listed
                .iter()
                .take(3)
                .copied()
                .collect::<Vec<_>>()
                .join(", "),
            frame_name(p.frames - 1)
        );
    }
    let pixels = p.width as u64 * p.height as u64;
    for f in &b.files {
        // Stored PNG at worst a little over the raw RGBA; EXR: 32-bit RGBA uncompressed.
        let limit = if f.name == REFERENCE {
            pixels * 16
        } else {
            pixels * 4
        } + pixels / 8
            + (1 << 20);
        if f.bytes > limit {
            bail!(
                "{name}: files[{}].bytes = {} is more than a {}×{} image takes ({limit})",
                f.name,
                f.bytes,
                p.width,
                p.height
            );
        }
        if f.sha256.len() != 64 || !f.sha256.bytes().all(|c| c.is_ascii_hexdigit()) {
            bail!("{name}: files[{}].sha256 is not 64 hex digits", f.name);
        }
    }
    Ok(b)
}

/// A baseline whose `baseline.json` and files were checked.
pub struct Loaded {
    pub dir: PathBuf,
    pub baseline: Baseline,
    /// The converged reference, linear RGBA.
    pub reference: Vec<[f32; 4]>,
}

impl Loaded {
    fn entry(&self, name: &str) -> Result<&FileEntry> {
        self.baseline
            .files
            .iter()
            .find(|f| f.name == name)
            .ok_or_else(|| {
                anyhow!(
                    "{}: files has no entry {name}",
                    self.dir.join(MANIFEST).display()
                )
            })
    }

    /// The bytes of a listed file: a regular file (never through a link), of the recorded size
    /// and SHA-256.
    fn read_entry(&self, entry: &FileEntry) -> Result<Vec<u8>> {
        let path = self.dir.join(&entry.name);
        refuse_link(&path)?;
        let bytes = decode::read_bounded(&path, entry.bytes, "baseline file")?;
        if bytes.len() as u64 != entry.bytes {
            bail!(
                "{}: {} bytes, baseline.json files[{}].bytes says {}",
                path.display(),
                bytes.len(),
                entry.name,
                entry.bytes
            );
        }
        let sha = sha256_hex(&bytes);
        if sha != entry.sha256 {
            bail!(
                "{}: SHA-256 {sha} differs from baseline.json files[{}].sha256 {} (the file changed after the baseline was made)",
                path.display(),
                entry.name,
                entry.sha256
            );
        }
        Ok(bytes)
    }

    /// Frame `k` as displayed (RGBA8, params.width × params.height), checked.
    pub fn frame(&self, k: u32) -> Result<Vec<u8>> {
        let p = &self.baseline.params;
        let entry = self.entry(&frame_name(k))?;
        let bytes = self.read_entry(entry)?;
        let name = self.dir.join(&entry.name).display().to_string();
        Ok(decode::decode_rgba8(&bytes, &name, MAX_PIXELS, Some((p.width, p.height)))?.2)
    }
}

/// A baseline being written; removed unless committed.
pub struct Staging {
    dir: PathBuf,
    target: PathBuf,
    files: Vec<FileEntry>,
    committed: bool,
}

impl Drop for Staging {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.dir);
        }
    }
}

impl Staging {
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Records a file written into the staging folder (read back: the manifest holds what is on
    /// disk).
    fn add(&mut self, name: &str) -> Result<()> {
        let path = self.dir.join(name);
        let bytes =
            std::fs::read(&path).with_context(|| format!("reading back {}", path.display()))?;
        self.files.push(FileEntry {
            name: name.to_string(),
            bytes: bytes.len() as u64,
            sha256: sha256_hex(&bytes),
        });
        Ok(())
    }

    /// Frame `k` (frames in order from 0).
    pub fn write_frame(&mut self, k: u32, width: u32, height: u32, rgba8: &[u8]) -> Result<()> {
        if self.files.len() != k as usize {
            bail!(
                "baseline frames are written in order (frame {k} after {} files)",
                self.files.len()
            );
        }
        let name = frame_name(k);
        crate::output::write_png(&self.dir.join(&name), width, height, rgba8)?;
        self.add(&name)
    }

    /// The reference, after the frames; then `baseline.json` (its `files` filled in here) and
    /// the swap into place.
    pub fn commit(
        mut self,
        mut baseline: Baseline,
        width: u32,
        height: u32,
        reference: &[[f32; 4]],
    ) -> Result<()> {
        crate::output::write_exr(&self.dir.join(REFERENCE), width, height, reference)?;
        self.add(REFERENCE)?;
        baseline.files = std::mem::take(&mut self.files);
        crate::output::write_json(&self.dir.join(MANIFEST), &baseline)?;
        sync_dir(&self.dir)?;
        let parent = self.target.parent().unwrap_or(Path::new("."));
        match std::fs::symlink_metadata(&self.target) {
            Ok(m) if !m.is_dir() => bail!(
                "{} is {}; fovea replaces only a baseline folder, never through a link",
                self.target.display(),
                fovea_hal::file::file_kind(&m.file_type())
            ),
            Ok(_) => {
                exchange(&self.dir, &self.target)?;
                // After the exchange the staging name holds the old baseline.
                self.committed = true;
                sync_dir(parent)?;
                std::fs::remove_dir_all(&self.dir).with_context(|| {
                    format!(
                        "removing the old baseline (moved to {})",
                        self.dir.display()
                    )
                })?;
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                std::fs::rename(&self.dir, &self.target).with_context(|| {
                    format!("moving the new baseline to {}", self.target.display())
                })?;
                self.committed = true;
                sync_dir(parent)?;
            }
            Err(e) => {
                return Err(e).with_context(|| format!("inspecting {}", self.target.display()))
            }
        }
        Ok(())
    }
}

fn sync_dir(dir: &Path) -> Result<()> {
    File::open(dir)
        .and_then(|d| d.sync_all())
        .with_context(|| format!("syncing {}", dir.display()))
}

/// Swaps two folders' names in one step (`renameat2(RENAME_EXCHANGE)`); where the file system
/// cannot, the old folder is first moved aside (`a` ends up holding the old one either way).
fn exchange(a: &Path, b: &Path) -> Result<()> {
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::ffi::OsStrExt;
        let ca = std::ffi::CString::new(a.as_os_str().as_bytes())?;
        let cb = std::ffi::CString::new(b.as_os_str().as_bytes())?;
        // SAFETY: two valid NUL-terminated paths; AT_FDCWD resolves them like rename(2).
        let r = unsafe {
            libc::renameat2(
                libc::AT_FDCWD,
                ca.as_ptr(),
                libc::AT_FDCWD,
                cb.as_ptr(),
                libc::RENAME_EXCHANGE,
            )
        };
        if r == 0 {
            return Ok(());
        }
        let e = std::io::Error::last_os_error();
        if !matches!(
            e.raw_os_error(),
            Some(libc::EINVAL) | Some(libc::ENOSYS) | Some(libc::EOPNOTSUPP)
        ) {
            return Err(e).with_context(|| format!("moving the new baseline to {}", b.display()));
        }
    }
    let mut aside = a.as_os_str().to_owned();
    aside.push("-old"); // still a staging name: removed by the next update if this one dies
    let aside = PathBuf::from(aside);
    std::fs::rename(b, &aside)
        .with_context(|| format!("moving the old baseline {} aside", b.display()))?;
    std::fs::rename(a, b).with_context(|| format!("moving the new baseline to {}", b.display()))?;
    std::fs::rename(&aside, a)
        .with_context(|| format!("moving the old baseline to {}", a.display()))?;
    Ok(())
}

/// The commit of the working tree the tool runs in, if it is a git checkout.
pub fn current_commit() -> String {
    std::process::Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "unknown".into())
}

#[cfg(test)]
#[path = "baseline_tests.rs"]
mod tests;
