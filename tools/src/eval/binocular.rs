//! Binocular consistency: how much two eyes' displayed frames disagree about the surfaces both
//! eyes see. One eye's frame is warped into the other through the scene's depth: each pixel of
//! the eye the measure is taken in (`to`) is followed through its depth to the surface point, the
//! point is projected into the other eye (`from`) and read there bilinearly. Only taps that see
//! the same surface count (a round trip through the `from` eye's depth lands back where it
//! started, within `ROUND_TRIP_PX`); pixels whose nearest tap is occluded, or whose point lies off
//! the other eye's screen or behind it, are masked (NaN in every map). Depth comes from the CPU
//! BVH through each pixel's centre ([`EyeGeometry::trace`]): the converged geometry, not a noisy
//! G-buffer, so a run and its converged reference pair are masked alike.
//!
//! The per-pixel difference is the mean over R, G, B of |to − warped from| of the displayed sRGB
//! values (0…1, as `metrics::flicker_map`). The converged pair's difference is what view-dependent
//! shading and resampling alone give; a run's difference above it is noise or filtering that the
//! two eyes do not share. Alpha-masked cut-outs are traced as solid by the CPU BVH: their
//! pixels compare the surfaces behind them as the GPU sees them, which the converged pair shares.

use fovea_renderer::frame::CameraPose;
use fovea_renderer::scene::bvh::instanced::SceneBvh;
use fovea_renderer::scene::Ray;
use glam::{DMat4, DVec2, DVec3, DVec4};

/// A tap counts when its surface, projected back into the measured eye, lands within this many
/// pixels of where the warp came from (occluders and other surfaces land far away).
pub const ROUND_TRIP_PX: f64 = 0.75;
/// Bilinear weights below this are dropped: a warp that lands on a pixel centre reads that pixel
/// alone (an eye warped into itself reads its own pixels exactly).
const CENTRE_SNAP: f64 = 1e-6;

/// One eye's camera and the view depth through each pixel's centre.
#[derive(Clone, Debug)]
pub struct EyeGeometry {
    pub camera: CameraPose,
    pub width: u32,
    pub height: u32,
    /// View depth (−z in the eye's view space) of the closest hit through each pixel centre,
    /// row-major; infinite where the ray leaves the scene.
    pub depth: Vec<f32>,
}

impl EyeGeometry {
    /// Traces one ray through each pixel centre of `camera`'s `width`×`height` image.
    pub fn trace(bvh: &SceneBvh, camera: CameraPose, width: u32, height: u32) -> EyeGeometry {
        let m = camera.world_from_view.as_dmat4();
        let origin = m.w_axis.truncate().as_vec3();
        let size = DVec2::new(width as f64, height as f64);
        let fov = camera.fov_tan.as_dvec4();
        let depth = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| {
                let v = view_direction(DVec2::new(x as f64 + 0.5, y as f64 + 0.5), fov, size);
                // Unnormalised (view z = −1): the hit's t is its view depth.
                let dir = m.transform_vector3(v).as_vec3();
                bvh.intersect(&Ray { origin, dir }, f32::INFINITY, false)
                    .map_or(f32::INFINITY, |h| h.t)
            })
            .collect();
        EyeGeometry {
            camera,
            width,
            height,
            depth,
        }
    }

    fn size(&self) -> DVec2 {
        DVec2::new(self.width as f64, self.height as f64)
    }

    /// The surface point seen through pixel centre `pixel` (w = 0: a direction, the ray escaped).
    fn point(&self, pixel: (u32, u32)) -> DVec4 {
        let centre = DVec2::new(pixel.0 as f64 + 0.5, pixel.1 as f64 + 0.5);
        let v = view_direction(centre, self.camera.fov_tan.as_dvec4(), self.size());
        let d = self.depth[(pixel.1 * self.width + pixel.0) as usize] as f64;
        let m = self.camera.world_from_view.as_dmat4();
        if d.is_finite() {
            m * (v * d).extend(1.0)
        } else {
            m * v.extend(0.0)
        }
    }

    /// Screen position (pixels) of a world point or direction; `None` behind the eye.
    fn project(&self, world: DVec4, view_from_world: &DMat4) -> Option<DVec2> {
        let p = *view_from_world * world;
        if p.z >= 0.0 {
            return None;
        }
        let t = p.truncate().truncate() / -p.z;
        let f = self.camera.fov_tan.as_dvec4();
        Some(DVec2::new((t.x - f.x) / (f.y - f.x), (f.w - t.y) / (f.w - f.z)) * self.size())
    }
}

/// View-space direction (z = −1) through a screen position, as `view_direction` in
/// shaders/common/camera.glsl.
fn view_direction(screen: DVec2, fov_tan: DVec4, size: DVec2) -> DVec3 {
    let f = screen / size;
    DVec3::new(
        fov_tan.x + (fov_tan.y - fov_tan.x) * f.x,
        fov_tan.w + (fov_tan.z - fov_tan.w) * f.y,
        -1.0,
    )
}

/// Up to four bilinear taps (pixel index, weight) of the other eye for one pixel.
type Taps = Vec<(usize, f64)>;

/// Where each pixel of one eye (`to`) finds its surface in the other (`from`).
pub struct Warp {
    pub width: u32,
    pub height: u32,
    /// Per pixel of `to`, row-major: the other eye's taps (weights summing to 1), or `None` where
    /// the surface is not visible in both eyes.
    taps: Vec<Option<Taps>>,
}

impl Warp {
    /// The warp of `from`'s image into `to`'s pixels (both images of one size).
    pub fn new(to: &EyeGeometry, from: &EyeGeometry) -> Warp {
        assert_eq!(
            (to.width, to.height),
            (from.width, from.height),
            "both eyes render one size"
        );
        let to_view = to.camera.world_from_view.as_dmat4().inverse();
        let from_view = from.camera.world_from_view.as_dmat4().inverse();
        let taps = (0..to.height)
            .flat_map(|y| (0..to.width).map(move |x| (x, y)))
            .map(|(x, y)| {
                let centre = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                let s = from.project(to.point((x, y)), &from_view)?;
                let size = from.size();
                if s.x < 0.0 || s.y < 0.0 || s.x >= size.x || s.y >= size.y {
                    return None;
                }
                // Bilinear footprint, clamped at the image's edge.
                let u = s - DVec2::splat(0.5);
                let base = u.floor();
                let frac = u - base;
                let mut found: Taps = Vec::with_capacity(4);
                let mut nearest_kept = false;
                let nearest = (frac.x >= 0.5, frac.y >= 0.5);
                for (dx, dy) in [(false, false), (true, false), (false, true), (true, true)] {
                    let w = if dx { frac.x } else { 1.0 - frac.x }
                        * if dy { frac.y } else { 1.0 - frac.y };
                    if w < CENTRE_SNAP {
                        continue;
                    }
                    let tx = (base.x as i64 + dx as i64).clamp(0, from.width as i64 - 1) as u32;
                    let ty = (base.y as i64 + dy as i64).clamp(0, from.height as i64 - 1) as u32;
                    // The tap's own surface, back in `to`: it should land where the warp came
                    // from, offset as the tap is from `s`.
                    let tap_centre = DVec2::new(tx as f64 + 0.5, ty as f64 + 0.5);
                    let expected = centre + (tap_centre - s);
                    let tap_point = from.point((tx, ty));
                    let same_kind = (tap_point.w == 0.0)
                        == (to.depth[(y * to.width + x) as usize].is_infinite());
                    let back = to.project(tap_point, &to_view);
                    let consistent =
                        same_kind && back.is_some_and(|b| (b - expected).length() <= ROUND_TRIP_PX);
                    if consistent {
                        found.push(((ty * from.width + tx) as usize, w));
                        nearest_kept |= (dx, dy) == nearest;
                    }
                }
                if !nearest_kept {
                    return None;
                }
                let total: f64 = found.iter().map(|t| t.1).sum();
                Some(found.into_iter().map(|(i, w)| (i, w / total)).collect())
            })
            .collect();
        Warp {
            width: to.width,
            height: to.height,
            taps,
        }
    }

    /// Whether pixel `i` of the measured eye sees a surface the other eye sees too.
    pub fn covers(&self, i: usize) -> bool {
        self.taps[i].is_some()
    }

    /// 1 where the surface is visible in both eyes, 0 elsewhere (its ring means are the share of
    /// each ring the measure covers).
    pub fn coverage_map(&self) -> Vec<f64> {
        self.taps
            .iter()
            .map(|t| if t.is_some() { 1.0 } else { 0.0 })
            .collect()
    }

    /// The other eye's displayed RGBA8 image read at each pixel's surface (RGB in 0…1).
    pub fn sample(&self, from_rgba: &[u8]) -> Vec<Option<DVec3>> {
        self.taps
            .iter()
            .map(|taps| {
                let taps = taps.as_ref()?;
                Some(taps.iter().fold(DVec3::ZERO, |sum, &(i, w)| {
                    sum + w * rgb(&from_rgba[4 * i..4 * i + 3])
                }))
            })
            .collect()
    }
}

fn rgb(p: &[u8]) -> DVec3 {
    DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) / 255.0
}

/// Per pixel of the measured eye: the mean over R, G, B of |to − warped from| (displayed sRGB,
/// 0…1); NaN where the surface is not visible in both eyes.
pub fn difference_map(to_rgba: &[u8], from_rgba: &[u8], warp: &Warp) -> Vec<f64> {
    signed(to_rgba, from_rgba, warp, |d| {
        (d.x.abs() + d.y.abs() + d.z.abs()) / 3.0
    })
}

/// Per pixel: the mean over R, G, B of (to − warped from), signed (the flicker of the
/// difference compares it between frames); NaN where masked.
pub fn signed_difference_map(to_rgba: &[u8], from_rgba: &[u8], warp: &Warp) -> Vec<f64> {
    signed(to_rgba, from_rgba, warp, |d| (d.x + d.y + d.z) / 3.0)
}

fn signed(to_rgba: &[u8], from_rgba: &[u8], warp: &Warp, f: impl Fn(DVec3) -> f64) -> Vec<f64> {
    let n = warp.width as usize * warp.height as usize;
    assert!(
        to_rgba.len() == 4 * n && from_rgba.len() == 4 * n,
        "images must hold width×height RGBA8 pixels"
    );
    warp.sample(from_rgba)
        .into_iter()
        .enumerate()
        .map(|(i, warped)| match warped {
            Some(w) => f(rgb(&to_rgba[4 * i..4 * i + 3]) - w),
            None => f64::NAN,
        })
        .collect()
}

/// The difference of [`difference_map`] at which the heat map saturates (displayed sRGB, 0…1).
pub const HEAT_MAP_MAX: f64 = 0.1;

/// The binocular difference as a picture of the measured eye (RGBA8): 0…`HEAT_MAP_MAX` along the
/// viridis ramp of the density views, black where the surface is not visible in both eyes.
pub fn heat_map(to_rgba: &[u8], from_rgba: &[u8], warp: &Warp) -> Vec<u8> {
    difference_map(to_rgba, from_rgba, warp)
        .into_iter()
        .flat_map(|d| {
            let [r, g, b] = match d.is_nan() {
                true => [0, 0, 0],
                false => crate::eval::density::ramp((d / HEAT_MAP_MAX) as f32),
            };
            [r, g, b, 255]
        })
        .collect()
}

/// Temporal flicker of the eyes' difference from one frame to the next: per pixel,
/// |Δ(signed difference of the run) − Δ(signed difference of the converged pair)| — how much the
/// disagreement between the eyes changes beyond what the converged images' does. NaN where any
/// of the four maps is masked.
pub fn difference_flicker_map(
    test_prev: &[f64],
    test: &[f64],
    reference_prev: &[f64],
    reference: &[f64],
) -> Vec<f64> {
    test_prev
        .iter()
        .zip(test)
        .zip(reference_prev.iter().zip(reference))
        .map(|((tp, t), (rp, r))| ((t - tp) - (r - rp)).abs())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use fovea_renderer::scene::bvh::BvhBuilder;
    use glam::{Mat4, Vec3, Vec4};

    /// A wall at z = −2 (two triangles, 4×4 wide) and a small square 1 in front of it.
    fn scene_bvh(with_occluder: bool) -> SceneBvh {
        let quad = |c: Vec3, h: f32| {
            let [a, b, cc, d] = [
                c + Vec3::new(-h, -h, 0.0),
                c + Vec3::new(h, -h, 0.0),
                c + Vec3::new(h, h, 0.0),
                c + Vec3::new(-h, h, 0.0),
            ];
            [[a, b, cc], [a, cc, d]]
        };
        let mut tris: Vec<[Vec3; 3]> = quad(Vec3::new(0.0, 0.0, -2.0), 4.0).to_vec();
        if with_occluder {
            tris.extend(quad(Vec3::new(0.0, 0.0, -1.0), 0.1));
        }
        let world = fovea_renderer::scene::bvh::wide::Bvh4::from_binary(
            &fovea_renderer::scene::Bvh::build_with(&tris, BvhBuilder::BINNED),
        );
        SceneBvh {
            world,
            world_tris: tris,
            ..Default::default()
        }
    }

    fn eye(x: f32) -> CameraPose {
        CameraPose {
            world_from_view: Mat4::from_translation(Vec3::new(x, 0.0, 0.0)),
            fov_tan: Vec4::new(-0.5, 0.5, -0.5, 0.5),
        }
    }

    fn gradient(width: u32, height: u32, shift: f64) -> Vec<u8> {
        (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .flat_map(|(x, y)| {
                let v = ((x as f64 + shift) * 4.0).clamp(0.0, 255.0) as u8;
                [v, (y * 4) as u8, 128, 255]
            })
            .collect()
    }

    #[test]
    fn an_eye_warped_into_itself_reads_its_own_pixels() {
        let bvh = scene_bvh(true);
        let g = EyeGeometry::trace(&bvh, eye(0.0), 40, 30);
        let warp = Warp::new(&g, &g);
        assert!((0..40 * 30).all(|i| warp.covers(i)), "all visible");
        let image = gradient(40, 30, 0.0);
        let d = difference_map(&image, &image, &warp);
        assert!(d.iter().all(|&v| v == 0.0));
    }

    #[test]
    fn a_wall_seen_from_two_eyes_warps_by_its_disparity() {
        // Eyes 0.1 apart, wall 2 away, 40 px across a tangent of 1: disparity 0.1/2 · 40 = 2 px.
        let bvh = scene_bvh(false);
        let (left, right) = (
            EyeGeometry::trace(&bvh, eye(-0.05), 40, 30),
            EyeGeometry::trace(&bvh, eye(0.05), 40, 30),
        );
        let warp = Warp::new(&left, &right);
        // The right eye sees the wall 2 px further left: its image is the left's shifted by 2.
        let (l, r) = (gradient(40, 30, 0.0), gradient(40, 30, 2.0));
        let d = difference_map(&l, &r, &warp);
        let covered: Vec<f64> = d.iter().copied().filter(|v| !v.is_nan()).collect();
        // The two left columns lie off the right eye's screen.
        assert_eq!(covered.len(), 38 * 30);
        assert!(covered.iter().all(|&v| v < 1e-9), "{covered:?}");
    }

    #[test]
    fn occluded_surfaces_are_masked() {
        let bvh = scene_bvh(true);
        let (left, right) = (
            EyeGeometry::trace(&bvh, eye(-0.05), 40, 30),
            EyeGeometry::trace(&bvh, eye(0.05), 40, 30),
        );
        let warp = Warp::new(&left, &right);
        // The occluder (0.2 wide at depth 1: 4 px) shifts by 4 px between the eyes, the wall
        // behind by 2: the wall the right eye cannot see beside it is masked.
        let masked = (0..40 * 30).filter(|&i| !warp.covers(i)).count();
        let off_screen = 2 * 30;
        assert!(masked > off_screen + 4, "{masked} masked");
        assert!(masked < off_screen + 4 * 8, "{masked} masked");
        // The centre of the occluder itself is seen by both.
        assert!(warp.covers(15 * 40 + 20));
    }
}
