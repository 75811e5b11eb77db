//! Per-frame gaze for the renderer: a hal gaze source (simulated FOVE 0, trace playback, fixed)
//! sampled at each frame's display time, run through the invalid-gaze policy and turned into a
//! pixel of each eye's rendered (possibly scaled) image. This is the only place that glues hal
//! backends to rendering.

use anyhow::{Context, Result};
use fovea_hal::{
    DelayedFrame, DelayedGaze, Eye, EyeView, GazeOrigin, GazeSample, GazeSource, GazeSpec,
    HmdDescription, InvalidGazePolicy, LatencyModel, PredictMode, ResolvedGaze, XrTime,
};
use glam::{Vec2, Vec3};

/// `--latency-ms`, `--tracker-hz` and `--gaze-predict` of the commands that render: with any of
/// them each frame sees the gaze a headset would (hal's latency model; the latency is
/// `--latency-ms` or the headset profile's sum) and is also judged where the eye is when shown.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GazeTiming {
    pub latency_ms: Option<f64>,
    pub tracker_hz: Option<f64>,
    pub predict: Option<PredictMode>,
}

impl GazeTiming {
    pub fn enabled(&self) -> bool {
        self.latency_ms.is_some() || self.tracker_hz.is_some() || self.predict.is_some()
    }

    /// The flags as given (`--gaze-predict` parsed); all absent: no latency model.
    pub fn from_flags(
        latency_ms: Option<f64>,
        tracker_hz: Option<f64>,
        predict: Option<&str>,
    ) -> Result<GazeTiming> {
        Ok(GazeTiming {
            latency_ms,
            tracker_hz,
            predict: predict.map(PredictMode::parse).transpose()?,
        })
    }

    /// The model for `hmd`, when on.
    pub fn model(&self, hmd: &HmdDescription) -> Result<Option<LatencyModel>> {
        if !self.enabled() {
            return Ok(None);
        }
        Ok(Some(LatencyModel::for_headset(
            hmd,
            self.latency_ms,
            self.tracker_hz,
        )?))
    }

    pub fn mode(&self) -> PredictMode {
        self.predict.unwrap_or(PredictMode::DEFAULT)
    }
}

pub struct GazeDriver {
    source: Box<dyn GazeSource>,
    policy: InvalidGazePolicy,
    /// With a latency model: the source seen through it (and the predictor).
    delayed: Option<DelayedGaze>,
    last_delayed: Option<DelayedFrame>,
    hmd: HmdDescription,
    /// Render pixels per headset pixel.
    scale: Vec2,
    frame_period_ns: f64,
    /// One eye's render size in pixels.
    size: Vec2,
}

/// The gaze used for one frame.
#[derive(Clone, Copy, Debug)]
pub struct FrameGaze {
    /// Gaze point in the left eye's render pixels (x right, y down).
    pub pixel: Vec2,
    /// The same gaze direction in each eye's render pixels (indexed by `Eye::index`).
    pub pixels: [Vec2; 2],
    pub origin: GazeOrigin,
    pub time_ns: XrTime,
    /// Why the centre is used although the source gave a gaze (`origin` is then `Centre`): it
    /// lies behind or outside a rendered eye's view (`project_gaze`).
    pub reason: Option<&'static str>,
    /// With a latency model: where the eye is at the display time (the source's own gaze), in
    /// each eye's render pixels; `None` without a model, when the source has no gaze then, or
    /// where it lies off that eye's image.
    pub true_pixels: [Option<Vec2>; 2],
    /// With a latency model: what the predictor did for this frame.
    pub latency: Option<FrameLatency>,
}

/// One frame's latency accounting.
#[derive(Clone, Copy, Debug)]
pub struct FrameLatency {
    /// When the newest tracker sample behind the gaze was taken (0: none yet).
    pub sample_time_ns: XrTime,
    pub mode: PredictMode,
    /// fixation, pursuit, saccade, blink or newest (`fovea_hal::EyeMotion`).
    pub motion: &'static str,
}

/// The flags of `timing` as one line (empty without a latency model): what a replay baseline
/// records of them.
pub fn describe_timing(timing: &GazeTiming) -> String {
    if !timing.enabled() {
        return String::new();
    }
    let part = |name: &str, v: Option<f64>| v.map(|v| format!("{name} {v}"));
    [
        part("--latency-ms", timing.latency_ms),
        part("--tracker-hz", timing.tracker_hz),
        Some(format!("--gaze-predict {}", timing.mode().name())),
    ]
    .into_iter()
    .flatten()
    .collect::<Vec<_>>()
    .join(" ")
}

/// A run's latency accounting for report.json (`fovea render`; `quality` and `replay` read it).
#[derive(Clone, Debug, serde::Serialize)]
pub struct LatencyLog {
    /// Sample-to-photon latency and how it is made up.
    pub latency_ms: f64,
    pub latency: String,
    pub tracker_hz: f64,
    pub gaze_predict: &'static str,
    /// Per frame: when the newest tracker sample behind its gaze was taken (ns; 0: none yet)
    /// and what the predictor took the eye to be doing.
    pub sample_time_ns: Vec<XrTime>,
    pub motion: Vec<&'static str>,
    /// Per frame: where the eye is at the display time (left eye's render pixels; null where
    /// the source has no gaze then or it lies off the image).
    #[serde(skip)]
    pub true_pixels: Vec<Option<[f32; 2]>>,
}

impl LatencyLog {
    /// For a driver with a latency model; `None` without one.
    pub fn for_driver(driver: &GazeDriver) -> Option<LatencyLog> {
        let model = driver.latency_model()?;
        Some(LatencyLog {
            latency_ms: model.total_ms(),
            latency: model.describe(),
            tracker_hz: model.tracker_hz,
            gaze_predict: driver.delayed.as_ref()?.mode().name(),
            sample_time_ns: Vec::new(),
            motion: Vec::new(),
            true_pixels: Vec::new(),
        })
    }

    pub fn push(&mut self, gaze: &FrameGaze) {
        let l = gaze.latency;
        self.sample_time_ns.push(l.map_or(0, |l| l.sample_time_ns));
        self.motion.push(l.map_or("", |l| l.motion));
        self.true_pixels
            .push(gaze.true_pixels[0].map(|p| p.to_array()));
    }
}

/// `project_gaze`'s reasons (report.json counts them as `gaze_outside_view`, xr's frames.jsonl
/// writes them as `reason`).
pub const GAZE_BEHIND: &str = "the gaze lies behind the eye";
pub const GAZE_OUTSIDE: &str = "the gaze lies outside the eye's view";

/// The one rule of `fovea render`/`view` and `fovea xr` for where a gaze lands: `direction` (in
/// the eye's own frame) through `eye`'s projection, times `scale` (render pixels per `eye`
/// pixel), must lie on the `size` render image with one pixel of slack (the edges `--gaze X,Y`
/// accepts, and rounding). Anywhere else the foveation would be centred off the image (or, behind
/// the eye, nowhere), so the caller uses the centre and says why.
pub fn project_gaze(
    eye: &EyeView,
    direction: Vec3,
    scale: Vec2,
    size: Vec2,
) -> Result<Vec2, &'static str> {
    let p = eye.direction_to_pixel(direction).ok_or(GAZE_BEHIND)? * scale;
    let on = |v: f32, n: f32| (-1.0..=n + 1.0).contains(&v);
    if on(p.x, size.x) && on(p.y, size.y) {
        Ok(p)
    } else {
        Err(GAZE_OUTSIDE)
    }
}

/// `index` refresh periods after the start: when `fovea render` shows frame `index` (and the time
/// `fovea xr --record` gives that frame's gaze, so a replay samples exactly it).
pub fn frame_time(frame_period_ns: f64, index: u32) -> XrTime {
    (index as f64 * frame_period_ns) as XrTime
}

/// Render pixels per headset pixel (the left eye's; both eyes share one render size).
fn render_scale(hmd: &HmdDescription, render_width: u32, render_height: u32) -> Vec2 {
    let eye = hmd.eye(Eye::Left);
    Vec2::new(
        render_width as f32 / eye.recommended_width as f32,
        render_height as f32 / eye.recommended_height as f32,
    )
}

impl GazeDriver {
    /// `spec`: center | X,Y (render pixels, inside the render image) | sim[:seed] | trace path.
    pub fn open(
        spec: &str,
        hmd: &HmdDescription,
        render_width: u32,
        render_height: u32,
    ) -> Result<GazeDriver> {
        GazeDriver::open_timed(
            spec,
            hmd,
            render_width,
            render_height,
            &GazeTiming::default(),
        )
    }

    /// As [`GazeDriver::open`], through the latency model when `timing` asks for it.
    pub fn open_timed(
        spec: &str,
        hmd: &HmdDescription,
        render_width: u32,
        render_height: u32,
        timing: &GazeTiming,
    ) -> Result<GazeDriver> {
        let scale = render_scale(hmd, render_width, render_height);
        let mut parsed: GazeSpec = spec.parse().with_context(|| format!("--gaze {spec}"))?;
        if let GazeSpec::Fixed { x, y } = &mut parsed {
            // Checked here in render pixels, the units the user wrote.
            if !((0.0..=render_width as f32).contains(x)
                && (0.0..=render_height as f32).contains(y))
            {
                anyhow::bail!("--gaze {spec}: ({x:?}, {y:?}) lies outside the {render_width}×{render_height} render image");
            }
            *x /= scale.x;
            *y /= scale.y;
        }
        let model = timing.model(hmd)?;
        let mut source_hmd = hmd.clone();
        if model.is_some() {
            // The simulated eye stands for the eye itself: the model adds the tracker's delay.
            source_hmd.tracker.latency_ms = 0.0;
        }
        let source = parsed
            .open(source_hmd)
            .with_context(|| format!("opening gaze source '{spec}'"))?;
        let mut driver = GazeDriver::from_source(source, hmd, render_width, render_height);
        driver.delayed = model.map(|m| DelayedGaze::new(m, timing.mode(), hmd));
        Ok(driver)
    }

    /// The latency model in use, if any.
    pub fn latency_model(&self) -> Option<&LatencyModel> {
        self.delayed.as_ref().and_then(DelayedGaze::model)
    }

    /// Prediction on a live source (`fovea xr --gaze-predict` with the runtime's eye tracker):
    /// each new sample feeds `mode`'s predictor, which predicts to the display time.
    pub fn with_live_prediction(mut self, mode: PredictMode) -> GazeDriver {
        self.delayed = Some(DelayedGaze::live(mode, &self.hmd));
        self
    }

    /// The predictor in use (`off` without one).
    pub fn predict_mode(&self) -> PredictMode {
        self.delayed
            .as_ref()
            .map_or(PredictMode::Off, DelayedGaze::mode)
    }

    /// The last frame through the latency model (`resolve_at` with one).
    pub fn last_delayed(&self) -> Option<&DelayedFrame> {
        self.last_delayed.as_ref()
    }

    /// A driver over a source opened elsewhere (`fovea xr`'s OpenXR eye tracker).
    pub fn from_source(
        source: Box<dyn GazeSource>,
        hmd: &HmdDescription,
        render_width: u32,
        render_height: u32,
    ) -> GazeDriver {
        let scale = render_scale(hmd, render_width, render_height);
        GazeDriver {
            source,
            policy: InvalidGazePolicy::default(),
            delayed: None,
            last_delayed: None,
            hmd: hmd.clone(),
            scale,
            frame_period_ns: 1e9 / hmd.refresh_hz as f64,
            size: Vec2::new(render_width as f32, render_height as f32),
        }
    }

    /// The display time of frame `index` in the timebase of simulated and recorded sources.
    pub fn frame_time(&self, index: u32) -> XrTime {
        frame_time(self.frame_period_ns, index)
    }

    /// The source's sample for display time `t` and the invalid-gaze policy's decision on it;
    /// with a latency model the prediction from the tracker samples taken up to t − latency
    /// (the sample's time is the newest one's, its kind `predicted`).
    pub fn resolve_at(&mut self, t: XrTime) -> Result<(GazeSample, ResolvedGaze)> {
        if let Some(delayed) = &mut self.delayed {
            let frame = delayed.frame(self.source.as_mut(), t)?;
            self.last_delayed = Some(frame);
            let p = &frame.prediction;
            let sample = match p.direction {
                Some(d) => GazeSample {
                    time_kind: fovea_hal::SampleTimeKind::Predicted,
                    ..GazeSample::looking(p.sample_time, 0, d)
                },
                None => GazeSample::no_gaze(t, 0),
            };
            return Ok((sample, frame.resolved));
        }
        self.source.begin_frame(t)?;
        let sample = self.source.sample_at(t);
        let resolved = self.policy.resolve(&sample, t);
        Ok((sample, resolved))
    }

    /// Gaze for frame `index`, displayed at `index` refresh periods after the start. A gaze
    /// behind or outside one of `eyes` (the rendered ones) makes the frame foveate at each eye's
    /// image centre with origin `Centre` and the reason, as `fovea xr` does.
    pub fn frame(&mut self, index: u32, eyes: &[Eye]) -> Result<FrameGaze> {
        let t = self.frame_time(index);
        let (_, resolved) = self.resolve_at(t)?;
        let centre = self.size * 0.5;
        let projected = [Eye::Left, Eye::Right]
            .map(|eye| project_gaze(self.hmd.eye(eye), resolved.direction, self.scale, self.size));
        let reason = match resolved.source {
            GazeOrigin::Centre => None,
            _ => eyes.iter().find_map(|eye| projected[eye.index()].err()),
        };
        let (origin, pixels) = match reason {
            Some(_) => (GazeOrigin::Centre, [centre; 2]),
            None => (resolved.source, projected.map(|p| p.unwrap_or(centre))),
        };
        let live = self.latency_model().is_none();
        let (true_pixels, latency) = match (&self.delayed, self.last_delayed) {
            (Some(delayed), Some(frame)) if !live => {
                let truth = frame.truth;
                let true_pixels = [Eye::Left, Eye::Right].map(|eye| {
                    let d = truth.gaze.direction;
                    let on = project_gaze(self.hmd.eye(eye), d, self.scale, self.size).ok();
                    on.filter(|_| truth.valid)
                });
                let latency = FrameLatency {
                    sample_time_ns: frame.prediction.sample_time,
                    mode: delayed.mode(),
                    motion: frame.prediction.motion.name(),
                };
                (true_pixels, Some(latency))
            }
            _ => ([None; 2], None),
        };
        Ok(FrameGaze {
            pixel: pixels[0],
            pixels,
            origin,
            time_ns: t,
            reason,
            true_pixels,
            latency,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fovea_hal::FixedGaze;

    fn driver(direction: Vec3) -> GazeDriver {
        let hmd = HmdDescription::resolve("fove0").unwrap();
        GazeDriver::from_source(
            Box::new(FixedGaze::new(hmd.clone(), direction)),
            &hmd,
            40,
            36,
        )
    }

    #[test]
    fn a_gaze_behind_or_outside_the_view_is_the_centre_with_a_reason() {
        // FOVE 0: ±45° horizontally, so (-3, 0, -1) (71.6° left) is off the image.
        for (direction, reason) in [
            (Vec3::Z, GAZE_BEHIND),
            (Vec3::new(1.0, 0.0, 0.0), GAZE_BEHIND),
            (Vec3::new(-3.0, 0.0, -1.0), GAZE_OUTSIDE),
        ] {
            let g = driver(direction).frame(0, &[Eye::Left]).unwrap();
            assert_eq!(
                (g.origin, g.reason),
                (GazeOrigin::Centre, Some(reason)),
                "{direction}"
            );
            assert_eq!(g.pixels, [Vec2::new(20.0, 18.0); 2]);
        }
        let g = driver(Vec3::NEG_Z)
            .frame(0, &[Eye::Left, Eye::Right])
            .unwrap();
        assert_eq!((g.origin, g.reason), (GazeOrigin::Live, None));
        // Straight ahead is the FOVE's image centre (pixel index 639.5 of 1280, scaled by 1/32).
        assert!(
            (g.pixel - Vec2::new(20.0, 18.0)).length() < 0.05,
            "{}",
            g.pixel
        );
    }

    /// With a latency model a frame shows the gaze of the tracker samples taken a latency before
    /// its display time, and reports where the eye is when it is shown.
    #[test]
    fn the_latency_model_delays_the_gaze_and_keeps_the_truth() {
        let dir = std::env::temp_dir().join(format!("fovea-gaze-latency-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("step.csv");
        // 0° until 0.5 s, then 10° right (1 kHz).
        let mut text = String::from("t_s,x_deg,y_deg,valid\n");
        for i in 0..1000 {
            let x = if i < 500 { 0 } else { 10 };
            text += &format!("{:.3},{x},0,1\n", i as f64 * 1e-3);
        }
        std::fs::write(&file, text).unwrap();
        let hmd = HmdDescription::resolve("fove0").unwrap();
        let timing = GazeTiming::from_flags(Some(100.0), Some(120.0), Some("off")).unwrap();
        let spec = format!("degrees:{}", file.display());
        let mut d = GazeDriver::open_timed(&spec, &hmd, 40, 36, &timing).unwrap();
        assert_eq!(d.latency_model().unwrap().total_ms(), 100.0);
        let mut plain = GazeDriver::open(&spec, &hmd, 40, 36).unwrap();
        // FOVE 0 frames at 70 Hz: frame 42 is shown at 0.6 s, 100 ms after the step.
        let (mut first_true, mut first_shown) = (None, None);
        for k in 0..60 {
            let g = d.frame(k, &[Eye::Left]).unwrap();
            let p = plain.frame(k, &[Eye::Left]).unwrap();
            assert_eq!(
                g.true_pixels[0],
                Some(p.pixel),
                "frame {k}: the truth is the source"
            );
            // 10° right on a 40-pixel, 90° wide image: pixel 23.0 (the centre 19.5).
            let right = |px: Vec2| px.x > 21.0;
            if first_true.is_none() && right(p.pixel) {
                first_true = Some(k);
            }
            if first_shown.is_none() && right(g.pixel) {
                first_shown = Some(k);
            }
            let l = g.latency.unwrap();
            assert_eq!(l.mode, PredictMode::Off);
            assert!(l.sample_time_ns <= g.time_ns - 100_000_000);
        }
        // 0.5 s is frame 35; a tick (120 Hz) at or after it plus 100 ms: frame 42.
        assert_eq!((first_true, first_shown), (Some(35), Some(42)));
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Only the rendered eyes decide; `--gaze X,Y` on the image's edges and corners stays live.
    #[test]
    fn only_rendered_eyes_decide_and_edges_are_on_the_image() {
        let mut hmd = HmdDescription::resolve("fove0").unwrap();
        for spec in ["0,0", "40,36", "0,36", "40,0", "20,18"] {
            let g = GazeDriver::open(spec, &hmd, 40, 36)
                .unwrap()
                .frame(0, &[Eye::Left])
                .unwrap();
            assert_eq!(
                (g.origin, g.reason),
                (GazeOrigin::Live, None),
                "--gaze {spec}"
            );
        }
        // 30° left: inside the left eye (45°), outside a right eye that sees only 10° left.
        hmd.eyes[Eye::Right.index()].fov.angle_left = -10f32.to_radians();
        let dir = Vec3::new(-30f32.to_radians().tan(), 0.0, -1.0);
        let mut d =
            GazeDriver::from_source(Box::new(FixedGaze::new(hmd.clone(), dir)), &hmd, 40, 36);
        let g = d.frame(0, &[Eye::Left]).unwrap();
        assert_eq!((g.origin, g.reason), (GazeOrigin::Live, None));
        let g = d.frame(1, &[Eye::Left, Eye::Right]).unwrap();
        assert_eq!(
            (g.origin, g.reason),
            (GazeOrigin::Centre, Some(GAZE_OUTSIDE))
        );
    }
}
