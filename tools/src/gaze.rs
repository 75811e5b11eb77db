//! Per-frame gaze for the renderer: a hal gaze source (simulated FOVE 0, trace playback, fixed)
//! sampled at each frame's display time, run through the invalid-gaze policy and turned into a
//! pixel of each eye's rendered (possibly scaled) image. This is the only place that glues hal
//! backends to rendering.

use anyhow::{Context, Result};
use fovea_hal::{Eye, GazeOrigin, GazeSample, GazeSource, GazeSpec, HmdDescription, InvalidGazePolicy, ResolvedGaze, XrTime};
use glam::Vec2;

pub struct GazeDriver {
    source: Box<dyn GazeSource>,
    policy: InvalidGazePolicy,
    hmd: HmdDescription,
    /// Render pixels per headset pixel.
    scale: Vec2,
    frame_period_ns: f64,
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
}

/// `index` refresh periods after the start: when `fovea render` shows frame `index` (and the time
/// `fovea xr --record` gives that frame's gaze, so a replay samples exactly it).
pub fn frame_time(frame_period_ns: f64, index: u32) -> XrTime {
    (index as f64 * frame_period_ns) as XrTime
}

/// Render pixels per headset pixel (the left eye's; both eyes share one render size).
fn render_scale(hmd: &HmdDescription, render_width: u32, render_height: u32) -> Vec2 {
    let eye = hmd.eye(Eye::Left);
    Vec2::new(render_width as f32 / eye.recommended_width as f32, render_height as f32 / eye.recommended_height as f32)
}

impl GazeDriver {
    /// `spec`: center | X,Y (render pixels, inside the render image) | sim[:seed] | trace path.
    pub fn open(spec: &str, hmd: &HmdDescription, render_width: u32, render_height: u32) -> Result<GazeDriver> {
        let scale = render_scale(hmd, render_width, render_height);
        let mut parsed: GazeSpec = spec.parse().with_context(|| format!("--gaze {spec}"))?;
        if let GazeSpec::Fixed { x, y } = &mut parsed {
            // Checked here in render pixels, the units the user wrote.
            if !((0.0..=render_width as f32).contains(x) && (0.0..=render_height as f32).contains(y)) {
                anyhow::bail!("--gaze {spec}: ({x:?}, {y:?}) lies outside the {render_width}×{render_height} render image");
            }
            *x /= scale.x;
            *y /= scale.y;
        }
        let source = parsed.open(hmd.clone()).with_context(|| format!("opening gaze source '{spec}'"))?;
        Ok(GazeDriver::from_source(source, hmd, render_width, render_height))
    }

    /// A driver over a source opened elsewhere (`fovea xr`'s OpenXR eye tracker).
    pub fn from_source(source: Box<dyn GazeSource>, hmd: &HmdDescription, render_width: u32, render_height: u32) -> GazeDriver {
        let scale = render_scale(hmd, render_width, render_height);
        GazeDriver {
            source,
            policy: InvalidGazePolicy::default(),
            hmd: hmd.clone(),
            scale,
            frame_period_ns: 1e9 / hmd.refresh_hz as f64,
        }
    }

    /// The display time of frame `index` in the timebase of simulated and recorded sources.
    pub fn frame_time(&self, index: u32) -> XrTime {
        frame_time(self.frame_period_ns, index)
    }

    /// The source's sample for display time `t` and the invalid-gaze policy's decision on it.
    pub fn resolve_at(&mut self, t: XrTime) -> Result<(GazeSample, ResolvedGaze)> {
        self.source.begin_frame(t)?;
        let sample = self.source.sample_at(t);
        let resolved = self.policy.resolve(&sample, t);
        Ok((sample, resolved))
    }

    /// Gaze for frame `index`, displayed at `index` refresh periods after the start.
    pub fn frame(&mut self, index: u32) -> Result<FrameGaze> {
        let t = self.frame_time(index);
        let (_, resolved) = self.resolve_at(t)?;
        let pixels = [Eye::Left, Eye::Right].map(|eye| {
            let view = self.hmd.eye(eye);
            let centre = Vec2::new(view.recommended_width as f32, view.recommended_height as f32) * 0.5;
            self.hmd.direction_to_pixel(eye, resolved.direction).unwrap_or(centre) * self.scale
        });
        Ok(FrameGaze { pixel: pixels[0], pixels, origin: resolved.source, time_ns: t })
    }
}
