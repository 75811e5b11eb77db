//! Per-frame gaze for the renderer: a hal gaze source (simulated FOVE 0, trace playback, fixed)
//! sampled at each frame's display time, run through the invalid-gaze policy and turned into a
//! pixel of each eye's rendered (possibly scaled) image. This is the only place that glues hal
//! backends to rendering.

use anyhow::{Context, Result};
use fovea_hal::{
    Eye, EyeView, GazeOrigin, GazeSample, GazeSource, GazeSpec, HmdDescription, InvalidGazePolicy,
    ResolvedGaze, XrTime,
};
use glam::{Vec2, Vec3};

pub struct GazeDriver {
    source: Box<dyn GazeSource>,
    policy: InvalidGazePolicy,
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
        let source = parsed
            .open(hmd.clone())
            .with_context(|| format!("opening gaze source '{spec}'"))?;
        Ok(GazeDriver::from_source(
            source,
            hmd,
            render_width,
            render_height,
        ))
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

    /// The source's sample for display time `t` and the invalid-gaze policy's decision on it.
    pub fn resolve_at(&mut self, t: XrTime) -> Result<(GazeSample, ResolvedGaze)> {
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
        Ok(FrameGaze {
            pixel: pixels[0],
            pixels,
            origin,
            time_ns: t,
            reason,
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
