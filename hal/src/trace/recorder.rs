//! Recording any gaze source to the trace format, crash-safely.

use super::{write_row, TraceHeader};
use crate::error::HalError;
use crate::hmd::HmdDescription;
use crate::sample::{GazeSample, XrTime};
use crate::source::GazeSource;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// A file written under a temporary name and moved into place only on `commit`, so a crash never
/// leaves a half-written file under the final name. Dropped without commit → temp file removed.
pub(crate) struct AtomicFile {
    final_path: PathBuf,
    temp_path: PathBuf,
    overwrite: bool,
    writer: Option<BufWriter<File>>,
}

impl AtomicFile {
    pub(crate) fn create(path: &Path, overwrite: bool) -> Result<Self, HalError> {
        if !overwrite && path.exists() {
            return Err(HalError::AlreadyExists {
                file: path.to_path_buf(),
            });
        }
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "trace".into());
        let temp_path = path.with_file_name(format!(".{name}.partial-{}", std::process::id()));
        let file = File::create(&temp_path).map_err(|e| HalError::io(&temp_path, e))?;
        Ok(AtomicFile {
            final_path: path.to_path_buf(),
            temp_path,
            overwrite,
            writer: Some(BufWriter::new(file)),
        })
    }

    pub(crate) fn writer(&mut self) -> &mut BufWriter<File> {
        // Only `commit` takes the writer, and it consumes self.
        self.writer.as_mut().expect("writer present until commit")
    }

    pub(crate) fn temp_path(&self) -> &Path {
        &self.temp_path
    }

    pub(crate) fn commit(mut self) -> Result<(), HalError> {
        let temp = self.temp_path.clone();
        let writer = self.writer.take().expect("writer present until commit");
        let file = writer
            .into_inner()
            .map_err(|e| HalError::io(&temp, e.into_error()))?;
        file.sync_all().map_err(|e| HalError::io(&temp, e))?;
        if self.overwrite {
            std::fs::rename(&temp, &self.final_path)
                .map_err(|e| HalError::io(&self.final_path, e))?;
        } else {
            // hard_link fails if the target appeared meanwhile: no-overwrite holds even in a race.
            std::fs::hard_link(&temp, &self.final_path).map_err(|e| match e.kind() {
                std::io::ErrorKind::AlreadyExists => HalError::AlreadyExists {
                    file: self.final_path.clone(),
                },
                _ => HalError::io(&self.final_path, e),
            })?;
            let _ = std::fs::remove_file(&temp);
        }
        Ok(())
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.writer.is_some() {
            let _ = std::fs::remove_file(&self.temp_path);
        }
    }
}

/// Writes gaze samples to a trace file, crash-safely: rows go to a temporary file that
/// [`TraceWriter::finish`] moves into place. Samples must come in increasing time; one at or
/// before the last written time is skipped (a source asked twice for one measurement).
pub struct TraceWriter {
    file: Option<AtomicFile>,
    last_time: Option<XrTime>,
    written: usize,
    /// A write failed: stop writing (the file is incomplete) and refuse to publish it.
    error: Option<HalError>,
    failed: bool,
}

impl TraceWriter {
    /// A trace for `hmd` (its id, FOV and tracker rate go into the header) at `path`; with
    /// `overwrite` false an existing file is an error, also if it appears before `finish`.
    pub fn create(hmd: &HmdDescription, path: &Path, overwrite: bool) -> Result<Self, HalError> {
        let mut file = AtomicFile::create(path, overwrite)?;
        header_for(hmd)
            .write(file.writer())
            .map_err(|e| HalError::io(file.temp_path(), e))?;
        Ok(TraceWriter {
            file: Some(file),
            last_time: None,
            written: 0,
            error: None,
            failed: false,
        })
    }

    pub fn samples_written(&self) -> usize {
        self.written
    }

    /// Writes `s` unless its time is not after the last one written. A failure is kept and
    /// reported by [`Self::flush`] / [`Self::finish`] (callers that cannot return errors).
    pub fn write(&mut self, s: &GazeSample) {
        if self.failed || self.last_time.is_some_and(|t| s.time <= t) {
            return;
        }
        if let Some(file) = self.file.as_mut() {
            match write_row(file.writer(), s) {
                Ok(()) => {
                    self.last_time = Some(s.time);
                    self.written += 1;
                }
                Err(e) => {
                    self.failed = true;
                    self.error = Some(HalError::io(file.temp_path(), e));
                }
            }
        }
    }

    /// Pushes buffered rows to the temporary file; reports an earlier write failure once.
    pub fn flush(&mut self) -> Result<(), HalError> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        if let Some(file) = self.file.as_mut() {
            file.writer()
                .flush()
                .map_err(|e| HalError::io(file.temp_path(), e))?;
        }
        Ok(())
    }

    /// Flush, sync and move the trace into place.
    pub fn finish(mut self) -> Result<(), HalError> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        if self.failed {
            let file = self
                .file
                .as_ref()
                .map(|f| f.temp_path().to_path_buf())
                .unwrap_or_default();
            let reason =
                "an earlier write failed; the recording is incomplete and was not published";
            return Err(HalError::io(file, std::io::Error::other(reason)));
        }
        self.file.take().map_or(Ok(()), AtomicFile::commit)
    }
}

/// Wraps a source and writes every distinct sample the application obtains from it (those with a
/// time later than the last one written) while passing it through unchanged. Call
/// [`Recorder::finish`] to publish the file; dropping the recorder discards it.
pub struct Recorder<S: GazeSource> {
    source: S,
    writer: TraceWriter,
}

impl<S: GazeSource> Recorder<S> {
    pub fn create(source: S, path: &Path, overwrite: bool) -> Result<Self, HalError> {
        let writer = TraceWriter::create(source.describe(), path, overwrite)?;
        Ok(Recorder { source, writer })
    }

    pub fn samples_written(&self) -> usize {
        self.writer.samples_written()
    }

    pub fn source(&self) -> &S {
        &self.source
    }

    /// Flush, sync and move the trace into place. Returns the wrapped source.
    pub fn finish(self) -> Result<S, HalError> {
        self.writer.finish()?;
        Ok(self.source)
    }
}

fn header_for(hmd: &HmdDescription) -> TraceHeader {
    let f = hmd.eyes[0].fov;
    let deg = |r: f32| r.to_degrees();
    TraceHeader {
        fov_deg: Some([
            deg(f.angle_left),
            deg(f.angle_right),
            deg(f.angle_down),
            deg(f.angle_up),
        ]),
        source: Some(format!("recorded by fovea-hal from `{}`", hmd.display_name)),
        ..TraceHeader::new(hmd.id.clone(), hmd.tracker.rate_hz)
    }
}

impl<S: GazeSource> GazeSource for Recorder<S> {
    fn describe(&self) -> &HmdDescription {
        self.source.describe()
    }

    /// Also reports a write failure from an earlier `sample_at` (which cannot return errors).
    fn begin_frame(&mut self, t: XrTime) -> Result<(), HalError> {
        self.writer.flush()?;
        self.source.begin_frame(t)
    }

    fn sample_at(&mut self, t: XrTime) -> GazeSample {
        let s = self.source.sample_at(t);
        self.writer.write(&s);
        s
    }

    fn latest(&self) -> GazeSample {
        self.source.latest()
    }
}
