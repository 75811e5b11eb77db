//! The gaze of each `fovea xr` frame: taken at the frame's predicted display time from the
//! runtime's eye tracker (`--gaze openxr`), or from any other `--gaze` source on a timebase that
//! starts at the first rendered frame; run through the invalid-gaze policy; projected into each
//! eye with that frame's located views; optionally recorded (`--record`) so `fovea render --gaze
//! TRACE.csv` replays the session.

use super::frame_log::LatencyRow;
use anyhow::{Context, Result};
use fovea_hal::openxr::xr;
use fovea_hal::{
    EyeView, Fov, GazeOrigin, GazeSample, HmdDescription, SampleTimeKind, TraceWriter, XrTime,
};
use fovea_stage::gaze::{project_gaze, GazeDriver};
use glam::{Quat, Vec2, Vec3};
use std::path::Path;

/// Where display times come from for the source.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Timebase {
    /// The runtime's clock (the OpenXR eye tracker).
    Runtime,
    /// Nanoseconds since the first rendered frame's display time (simulated, trace, fixed).
    FromFirstFrame,
}

/// The gaze used for one frame, as the per-frame log reports it.
#[derive(Clone, Copy, Debug)]
pub struct XrFrameGaze {
    /// Unit vector in VIEW space (the head): +X right, +Y up, −Z forward.
    pub direction: Vec3,
    pub origin: GazeOrigin,
    /// When the sample used was measured, in the source's timebase; `None` when unknown or for
    /// the centre fallback.
    pub sample_time_ns: Option<XrTime>,
    /// Display time − sample time (0 for the centre fallback).
    pub age_ns: i64,
    /// Per eye (left, right): the gaze pixel in that eye's render image.
    pub pixels: [Vec2; 2],
    /// Why the centre is used although a gaze was available (behind or outside an eye's view).
    pub reason: Option<&'static str>,
    pub latency: LatencyRow,
}

pub struct XrGaze {
    driver: GazeDriver,
    /// The `--headset` TOML: the latency figures the runtime does not give.
    profile: HmdDescription,
    /// The `--headset` TOML's refresh period: the recording's frame timebase.
    record_period_ns: f64,
    timebase: Timebase,
    first_display_time: Option<XrTime>,
    recorder: Option<TraceWriter>,
}

impl XrGaze {
    /// `record`: a new trace file (an existing one is refused) written in `base`'s frame timebase
    /// (`index × 1 / base.refresh_hz`), which is what `fovea render --headset <the same> --gaze
    /// TRACE.csv` samples.
    pub fn new(
        driver: GazeDriver,
        timebase: Timebase,
        base: &HmdDescription,
        record: Option<&Path>,
    ) -> Result<XrGaze> {
        let recorder = match record {
            Some(path) => Some(
                TraceWriter::create(base, path, false)
                    .with_context(|| format!("--record {}", path.display()))?,
            ),
            None => None,
        };
        Ok(XrGaze {
            driver,
            profile: base.clone(),
            record_period_ns: 1e9 / base.refresh_hz as f64,
            timebase,
            first_display_time: None,
            recorder,
        })
    }

    /// The gaze for the rendered frame `render_index` displayed at `display_time`; `eyes_in_head`:
    /// the two views located in VIEW space; `size`: one eye's render size.
    pub fn frame(
        &mut self,
        display_time: XrTime,
        render_index: u32,
        eyes_in_head: &[xr::View],
        size: (u32, u32),
    ) -> Result<XrFrameGaze> {
        let first = *self.first_display_time.get_or_insert(display_time);
        let t = match self.timebase {
            Timebase::Runtime => display_time,
            Timebase::FromFirstFrame => display_time - first,
        };
        let (sample, resolved) = self.driver.resolve_at(t)?;
        let latency = self.latency_row(t, &sample);
        // A live predictor's sample carries the runtime's time only when the runtime gave one.
        let unknown = match (self.driver.latency_model(), self.driver.last_delayed()) {
            (None, Some(frame)) => frame.truth.time_kind == SampleTimeKind::Unknown,
            _ => sample.time_kind == SampleTimeKind::Unknown,
        };
        let mut gaze = XrFrameGaze {
            direction: resolved.direction,
            origin: resolved.source,
            sample_time_ns: None,
            age_ns: resolved.age_ns,
            pixels: [Vec2::new(size.0 as f32, size.1 as f32) * 0.5; 2],
            reason: None,
            latency,
        };
        gaze.sample_time_ns = match resolved.source {
            GazeOrigin::Live if unknown => None,
            GazeOrigin::Live | GazeOrigin::Held => Some(t - resolved.age_ns),
            GazeOrigin::Centre => None,
        };
        for (pixel, view) in gaze.pixels.iter_mut().zip(eyes_in_head) {
            match project(resolved.direction, view, size) {
                Ok(p) => *pixel = p,
                Err(why) if resolved.source != GazeOrigin::Centre => {
                    gaze.reason = gaze.reason.or(Some(why));
                }
                Err(_) => {}
            }
        }
        if gaze.reason.is_some() {
            gaze = XrFrameGaze {
                origin: GazeOrigin::Centre,
                age_ns: 0,
                sample_time_ns: None,
                pixels: [Vec2::new(size.0 as f32, size.1 as f32) * 0.5; 2],
                ..gaze
            };
        }
        self.record(render_index, &gaze)?;
        Ok(gaze)
    }

    /// The frame's latency accounting; `t` in the source's timebase, `sample` what the driver
    /// gave the invalid-gaze policy.
    fn latency_row(&self, t: XrTime, sample: &GazeSample) -> LatencyRow {
        let hmd = &self.profile;
        let ms = |ns: i64| ns as f64 * 1e-6;
        let frame = self.driver.last_delayed();
        // The runtime's own sample: the live predictor's input, or what the driver gave.
        let runtime = match (self.timebase, self.driver.latency_model(), frame) {
            (Timebase::Runtime, None, Some(f)) => Some(f.truth),
            (Timebase::Runtime, _, None) => Some(*sample),
            _ => None,
        };
        let known = |s: &GazeSample| s.time != 0 && s.time_kind != SampleTimeKind::Unknown;
        LatencyRow {
            gaze_predict: self.driver.predict_mode().name(),
            motion: frame.map(|f| f.prediction.motion.name()),
            predicted: frame.and_then(|f| f.prediction.direction.map(|d| d.to_array())),
            horizon_ms: match frame {
                Some(f) if f.prediction.sample_time != 0 => Some(ms(f.prediction.horizon_ns)),
                Some(_) => None,
                None => known(sample).then(|| ms(t - sample.time)),
            },
            runtime_sample_age_ms: runtime
                .filter(|s| s.valid && known(s))
                .map(|s| ms(t - s.time)),
            profile_tracker_ms: hmd.tracker.latency_ms,
            profile_render_ms: hmd.latency.map(|l| l.render_ms),
            profile_display_ms: hmd.latency.map(|l| l.display_ms),
            model_total_ms: self.driver.latency_model().map(|m| m.total_ms()),
        }
    }

    fn record(&mut self, render_index: u32, gaze: &XrFrameGaze) -> Result<()> {
        let Some(recorder) = self.recorder.as_mut() else {
            return Ok(());
        };
        let t = fovea_stage::gaze::frame_time(self.record_period_ns, render_index);
        // Held gaze is written as the direction it held, so the replay shows the same pixels; no
        // gaze stays no gaze (the replay's invalid-gaze policy decides again, on its frame times).
        let sample = match gaze.origin {
            GazeOrigin::Centre => GazeSample::no_gaze(t, render_index as u64),
            _ => GazeSample::looking(t, render_index as u64, gaze.direction),
        };
        recorder.write(&sample);
        recorder.flush().context("--record")?;
        Ok(())
    }

    /// Publishes the recording (if any); returns how many samples it holds.
    pub fn finish(self) -> Result<Option<usize>> {
        let Some(recorder) = self.recorder else {
            return Ok(None);
        };
        let written = recorder.samples_written();
        recorder.finish().context("--record")?;
        Ok(Some(written))
    }
}

/// `direction` (VIEW space) as a pixel of the eye located at `eye_in_head` with `size`, or why it
/// has none (`project_gaze`: the same rule as `fovea render`'s).
pub fn project(
    direction: Vec3,
    eye_in_head: &xr::View,
    size: (u32, u32),
) -> Result<Vec2, &'static str> {
    let o = eye_in_head.pose.orientation;
    let in_eye = Quat::from_xyzw(o.x, o.y, o.z, o.w).normalize().inverse() * direction;
    let f = eye_in_head.fov;
    let view = EyeView {
        recommended_width: size.0,
        recommended_height: size.1,
        fov: Fov {
            angle_left: f.angle_left,
            angle_right: f.angle_right,
            angle_down: f.angle_down,
            angle_up: f.angle_up,
        },
        offset: Vec3::ZERO,
    };
    project_gaze(
        &view,
        in_eye,
        Vec2::ONE,
        Vec2::new(size.0 as f32, size.1 as f32),
    )
}
