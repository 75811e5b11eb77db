//! `DIR/frames.jsonl`: one JSON object per frame of the OpenXR frame loop. A rendered frame's
//! GPU times are known only when its slot in the frame ring comes round again, so rows wait here
//! until then and are written in frame order. The file appears under its name at the end (a
//! temporary until then).

use crate::output::AtomicWriter;
use anyhow::{Context, Result};
use fovea_hal::openxr::xr;
use serde::Serialize;
use std::collections::VecDeque;
use std::io::Write;
use std::path::Path;

#[derive(Serialize, Clone, Copy, Debug)]
pub struct FovTangents {
    pub left: f32,
    pub right: f32,
    pub down: f32,
    pub up: f32,
}

#[derive(Serialize, Clone, Copy, Debug)]
pub struct Pose {
    /// Metres in the LOCAL reference space.
    pub position: [f32; 3],
    /// Quaternion x, y, z, w.
    pub orientation: [f32; 4],
}

#[derive(Serialize, Clone, Debug)]
pub struct ViewRow {
    pub eye: &'static str,
    pub fov: FovTangents,
    pub pose: Pose,
}

impl ViewRow {
    pub fn new(eye: &'static str, view: &xr::View) -> ViewRow {
        let (p, o, f) = (view.pose.position, view.pose.orientation, view.fov);
        ViewRow {
            eye,
            fov: FovTangents {
                left: f.angle_left.tan(),
                right: f.angle_right.tan(),
                down: f.angle_down.tan(),
                up: f.angle_up.tan(),
            },
            pose: Pose {
                position: [p.x, p.y, p.z],
                orientation: [o.x, o.y, o.z, o.w],
            },
        }
    }
}

#[derive(Serialize, Clone, Debug)]
pub struct GazeRow {
    /// When the sample was measured (runtime clock for `--gaze openxr`); null when unknown.
    pub sample_time_ns: Option<i64>,
    /// Unit vector in VIEW space: +X right, +Y up, −Z forward.
    pub direction: [f32; 3],
    /// live | held | centre.
    pub origin: &'static str,
    /// Predicted display time − sample time.
    pub age_ns: i64,
    /// The gaze pixel in each eye's render image (left, right).
    pub pixels: [[f32; 2]; 2],
    /// Why the centre is used although a gaze was available.
    pub reason: Option<&'static str>,
    /// Latency accounting of the gaze.
    pub latency: LatencyRow,
}

/// Which sample a frame's gaze rests on, what the predictor made of it, and the parts of the
/// sample-to-photon latency that the runtime and the headset profile give.
#[derive(Serialize, Clone, Copy, Debug, PartialEq)]
pub struct LatencyRow {
    /// `--gaze-predict`: off | hold | linear | saccade.
    pub gaze_predict: &'static str,
    /// What the predictor took the eye to be doing (fixation, pursuit, saccade, blink, newest);
    /// null without a predictor.
    pub motion: Option<&'static str>,
    /// The predicted gaze (VIEW space, before the invalid-gaze policy and the projection); null
    /// without a predictor or while it has none (a blink).
    pub predicted: Option<[f32; 3]>,
    /// Display time − the time of the newest sample behind the gaze (ms): how far ahead the
    /// prediction reaches; null when the sample time is unknown.
    pub horizon_ms: Option<f64>,
    /// From the runtime: predicted display time − the sample's time as it returned it (ms; null
    /// when it cannot say).
    pub runtime_sample_age_ms: Option<f64>,
    /// From the headset profile: the tracker's delay, render and display latency (ms; the last
    /// two null for a profile without [latency]).
    pub profile_tracker_ms: f32,
    pub profile_render_ms: Option<f32>,
    pub profile_display_ms: Option<f32>,
    /// The latency model's total (ms) when recorded or simulated gaze runs through it.
    pub model_total_ms: Option<f64>,
}

#[derive(Serialize, Clone, Debug)]
pub struct FrameRow {
    pub frame: u64,
    pub predicted_display_time_ns: i64,
    /// xrWaitFrame's predicted display period (the runtime's frame interval).
    pub predicted_display_period_ns: i64,
    pub should_render: bool,
    /// Both eyes rendered and submitted in a projection layer (false: ended without layers —
    /// shouldRender false, views not located, or the session stopping).
    pub rendered: bool,
    pub views: Vec<ViewRow>,
    pub gaze: Option<GazeRow>,
    /// GPU milliseconds per eye (left, right), from the frame's timestamp queries.
    pub gpu_ms: Option<[f64; 2]>,
    /// Host milliseconds from xrWaitFrame's return to xrEndFrame's (recording, submitting, the
    /// runtime's calls; not the wait for the display).
    pub cpu_ms: f64,
}

impl FrameRow {
    /// A frame ended without layers (`frame` and `cpu_ms` are filled in by the loop).
    pub fn not_rendered(predicted_display_time_ns: i64, should_render: bool) -> FrameRow {
        FrameRow {
            frame: 0,
            predicted_display_time_ns,
            predicted_display_period_ns: 0,
            should_render,
            rendered: false,
            views: Vec::new(),
            gaze: None,
            gpu_ms: None,
            cpu_ms: 0.0,
        }
    }
}

pub struct FrameLog {
    out: AtomicWriter,
    /// Rows not yet written, each with the engine frame whose GPU times it waits for.
    pending: VecDeque<(FrameRow, Option<u64>)>,
    pub written: u64,
}

impl FrameLog {
    pub fn create(path: &Path) -> Result<FrameLog> {
        Ok(FrameLog {
            out: AtomicWriter::create(path)?,
            pending: VecDeque::new(),
            written: 0,
        })
    }

    /// Queues a row; `engine_frame`: the renderer's frame id whose GPU times fill `gpu_ms`.
    pub fn push(&mut self, row: FrameRow, engine_frame: Option<u64>) -> Result<()> {
        self.pending.push_back((row, engine_frame));
        self.flush_ready()
    }

    /// Fills the GPU times of engine frame `frame` (read when its slot retired).
    pub fn complete(&mut self, frame: u64, gpu_ms: [f64; 2]) -> Result<()> {
        for (row, waits) in self.pending.iter_mut() {
            if *waits == Some(frame) {
                row.gpu_ms = Some(gpu_ms);
                *waits = None;
            }
        }
        self.flush_ready()
    }

    fn flush_ready(&mut self) -> Result<()> {
        while self
            .pending
            .front()
            .is_some_and(|(_, waits)| waits.is_none())
        {
            let (row, _) = self.pending.pop_front().expect("front checked");
            let line = serde_json::to_string(&row)?;
            writeln!(self.out.writer(), "{line}")
                .with_context(|| format!("writing {}", self.out.path().display()))?;
            self.written += 1;
        }
        Ok(())
    }

    /// Writes what is left (rows still waiting keep `gpu_ms` null) and moves the file into place.
    pub fn commit(mut self) -> Result<u64> {
        for (_, waits) in self.pending.iter_mut() {
            *waits = None;
        }
        self.flush_ready()?;
        self.out.commit()?;
        Ok(self.written)
    }
}
