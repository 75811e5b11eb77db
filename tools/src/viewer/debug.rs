//! `fovea view`'s debug views (key v, or `--debug-view`): the sampling grid as traced, the
//! screen-space sample density, eccentricity rings over the image, or (both eyes) the binocular
//! difference as a heat map. They are the same pictures
//! `fovea render --debug-views` writes (the density one byte for byte), made on the CPU from the
//! finished frame and copied into the swapchain image: a debug frame waits for its GPU work.

use crate::eval::binocular::{heat_map, EyeGeometry, Warp};
use crate::eval::density::{box_filter, heatmap_rgba, samples_per_pixel};
use anyhow::{bail, Result};
use fovea_hal::{Eye, HmdDescription};
use fovea_renderer::frame::CameraPose;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::scene::bvh::instanced::SceneBvh;
use glam::{UVec2, Vec2};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DebugView {
    Off,
    /// The sampling grid as traced (before the way back), stretched over the eye.
    Grid,
    /// Samples per screen pixel, log scale, gaze marked.
    Density,
    /// The image with rings at `RINGS_DEG` of true eccentricity from the gaze.
    Rings,
    /// Both eyes: each eye's binocular difference (`crate::eval::binocular`: the other eye warped into
    /// it through the scene's depth) as a heat map, black where only one eye sees the surface.
    StereoDiff,
}

/// What the stereo-diff view needs besides the frame: the scene's CPU BVH and the frame's cameras.
pub struct StereoScene<'a> {
    pub bvh: &'a SceneBvh,
    pub cameras: [CameraPose; 2],
}

/// Ring eccentricities in degrees (through the headset eye's FOV).
pub const RINGS_DEG: [f32; 5] = [5.0, 10.0, 20.0, 30.0, 40.0];

impl DebugView {
    pub const NAMES: &'static [&'static str] = &["off", "grid", "density", "rings", "stereo-diff"];

    pub fn parse(name: &str) -> Result<DebugView> {
        Ok(match name {
            "off" => DebugView::Off,
            "grid" => DebugView::Grid,
            "density" => DebugView::Density,
            "rings" => DebugView::Rings,
            "stereo-diff" => DebugView::StereoDiff,
            _ => bail!(
                "--debug-view {name}: expected one of {}",
                DebugView::NAMES.join(", ")
            ),
        })
    }

    pub fn name(self) -> &'static str {
        DebugView::NAMES[self as usize]
    }

    /// The next view of the key v cycle; `stereo`: both eyes are rendered (only then does the
    /// cycle visit stereo-diff).
    pub fn next(self, stereo: bool) -> DebugView {
        match self {
            DebugView::Off => DebugView::Grid,
            DebugView::Grid => DebugView::Density,
            DebugView::Density => DebugView::Rings,
            DebugView::Rings if stereo => DebugView::StereoDiff,
            DebugView::Rings | DebugView::StereoDiff => DebugView::Off,
        }
    }
}

/// The debug picture of every view of completed frame `frame`, side by side (RGBA8, each view
/// `eye.x` × `eye.y`). `eyes`: which headset eye each view is (for the rings' FOV); `stereo`:
/// the scene and cameras of a two-eye frame (the stereo-diff view needs them).
pub fn compose(
    mode: DebugView,
    renderer: &Renderer,
    frame: u64,
    eye: UVec2,
    hmd: &HmdDescription,
    eyes: &[Eye],
    stereo: Option<&StereoScene>,
) -> Result<Vec<u8>> {
    let (w, h) = (eye.x as usize, eye.y as usize);
    let width = w * eyes.len();
    let mut out = vec![0u8; width * h * 4];
    let mut pixels = Vec::new();
    let stereo_pictures = match (mode, stereo) {
        (DebugView::StereoDiff, Some(s)) if eyes.len() == 2 => {
            Some(stereo_heat_maps(renderer, frame, eye, s)?)
        }
        (DebugView::StereoDiff, _) => {
            bail!("--debug-view stereo-diff needs both eyes (--eyes both)")
        }
        _ => None,
    };
    for (v, &headset_eye) in eyes.iter().enumerate() {
        let space = renderer.view(v).space.as_ref();
        let picture = match mode {
            DebugView::Off => return Ok(out),
            DebugView::Grid => {
                renderer.read_view_grid_ldr(frame, v, &mut pixels)?;
                stretch(&pixels, space.grid_size(), eye)
            }
            DebugView::Density => {
                // As `fovea render --debug-views`: a box average shows density, not the pattern.
                let radius = (eye.x / 160).max(2);
                heatmap_rgba(
                    &box_filter(&samples_per_pixel(space), eye.x, eye.y, radius),
                    eye.x,
                    eye.y,
                    space.gaze(),
                )
            }
            DebugView::Rings => {
                renderer.read_view_ldr(frame, v, &mut pixels)?;
                draw_rings(&mut pixels, eye, space.gaze(), hmd, headset_eye);
                std::mem::take(&mut pixels)
            }
            DebugView::StereoDiff => stereo_pictures.as_ref().expect("made above")[v].clone(),
        };
        for y in 0..h {
            let row = &picture[y * w * 4..(y + 1) * w * 4];
            out[(y * width + v * w) * 4..(y * width + v * w + w) * 4].copy_from_slice(row);
        }
    }
    Ok(out)
}

/// Each eye's binocular heat map: the other eye warped into it through the depth the CPU BVH
/// finds through its pixel centres.
fn stereo_heat_maps(
    renderer: &Renderer,
    frame: u64,
    eye: UVec2,
    stereo: &StereoScene,
) -> Result<[Vec<u8>; 2]> {
    let (mut left, mut right) = (Vec::new(), Vec::new());
    renderer.read_view_ldr(frame, 0, &mut left)?;
    renderer.read_view_ldr(frame, 1, &mut right)?;
    let [l, r] = stereo
        .cameras
        .map(|camera| EyeGeometry::trace(stereo.bvh, camera, eye.x, eye.y));
    Ok([
        heat_map(&left, &right, &Warp::new(&l, &r)),
        heat_map(&right, &left, &Warp::new(&r, &l)),
    ])
}

/// Nearest-texel scaling of an RGBA8 image from `from` to `to`.
fn stretch(pixels: &[u8], from: UVec2, to: UVec2) -> Vec<u8> {
    let mut out = Vec::with_capacity(to.x as usize * to.y as usize * 4);
    for y in 0..to.y {
        let sy = (y * from.y / to.y).min(from.y - 1);
        for x in 0..to.x {
            let sx = (x * from.x / to.x).min(from.x - 1);
            let i = (sy * from.x + sx) as usize * 4;
            out.extend_from_slice(&pixels[i..i + 4]);
        }
    }
    out
}

/// White rings where a pixel's angle from the gaze direction crosses one of `RINGS_DEG`
/// (render pixels mapped onto the headset eye's FOV, as the headset shows them).
fn draw_rings(pixels: &mut [u8], eye: UVec2, gaze: Vec2, hmd: &HmdDescription, headset_eye: Eye) {
    let view = hmd.eye(headset_eye);
    let scale = Vec2::new(
        view.recommended_width as f32 / eye.x as f32,
        view.recommended_height as f32 / eye.y as f32,
    );
    let gaze_dir = view.pixel_to_direction(gaze * scale - Vec2::splat(0.5));
    let ecc =
        |x: u32, y: u32| view.eccentricity_deg(Vec2::new(x as f32, y as f32) * scale, gaze_dir);
    for y in 0..eye.y.saturating_sub(1) {
        for x in 0..eye.x.saturating_sub(1) {
            // A ring passes between this pixel and its right or lower neighbour.
            let (e, right, down) = (ecc(x, y), ecc(x + 1, y), ecc(x, y + 1));
            let crosses = |a: f32, b: f32| RINGS_DEG.iter().any(|&r| (a - r) * (b - r) <= 0.0);
            if crosses(e, right) || crosses(e, down) {
                let i = (y * eye.x + x) as usize * 4;
                pixels[i..i + 4].copy_from_slice(&[255, 255, 255, 255]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_cycle_and_parse() {
        let mut m = DebugView::Off;
        for name in DebugView::NAMES {
            assert_eq!(DebugView::parse(name).unwrap(), m);
            assert_eq!(m.name(), *name);
            m = m.next(true);
        }
        assert_eq!(m, DebugView::Off);
        // One eye: the cycle leaves stereo-diff out.
        assert_eq!(DebugView::Rings.next(false), DebugView::Off);
        assert!(DebugView::parse("heat")
            .unwrap_err()
            .to_string()
            .contains("--debug-view heat"));
    }

    #[test]
    fn rings_are_drawn_around_the_gaze() {
        let hmd = HmdDescription::fove0();
        let eye = UVec2::new(160, 180);
        let mut pixels = vec![0u8; 160 * 180 * 4];
        draw_rings(&mut pixels, eye, Vec2::new(80.0, 90.0), &hmd, Eye::Left);
        let white = |x: usize, y: usize| pixels[(y * 160 + x) * 4] == 255;
        // Near the gaze (< 5°) nothing; along the row through it, rings on both sides.
        assert!(!white(80, 90) && !white(81, 90));
        let row: Vec<usize> = (0..160).filter(|&x| white(x, 90)).collect();
        assert!(
            row.iter().any(|&x| x < 80) && row.iter().any(|&x| x > 80),
            "{row:?}"
        );
    }

    #[test]
    fn stretching_keeps_corners() {
        let px = [1u8, 0, 0, 255, 2, 0, 0, 255, 3, 0, 0, 255, 4, 0, 0, 255];
        let out = stretch(&px, UVec2::new(2, 2), UVec2::new(4, 4));
        assert_eq!((out[0], out[3 * 4], out[12 * 4], out[15 * 4]), (1, 2, 3, 4));
    }
}
