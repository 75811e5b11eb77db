//! Sample-density debug views of a sampling space: samples per screen pixel, a log-scale heatmap
//! of it, and a plot of density against eccentricity next to the acuity target, uniform sampling
//! at the same budget and Cartesian 1 spp (and the paper's layout when the space is screen-clipped);
//! the per-ring density gain of one space over another (`ring_density_gain`).

use crate::eval::metrics::{Rings, ECC_MAX};
use crate::eval::plot::{line_plot, Series};
use anyhow::Result;
use fovea_renderer::sampling::{SamplingSpace, VisualPolar, VisualPolarParams, VpLayout};
use glam::Vec2;
use std::path::Path;

/// Heatmap range: log2 density from 1/64 to 64 samples per pixel.
const LOG2_MIN: f32 = -6.0;
const LOG2_MAX: f32 = 6.0;

/// Reddy's acuity V(e) (cycles/degree); the same model as the renderer's Visual-Polar space.
pub fn acuity(e: f64) -> f64 {
    if e <= 5.79 {
        60.0
    } else {
        449.4 / (0.3 * e + 1.0).powi(2)
    }
}

/// Samples per screen pixel (row-major, width×height): every kept grid texel's centre is
/// counted in the pixel it lands in; off-screen and clipped texels count nowhere.
pub fn samples_per_pixel(space: &dyn SamplingSpace) -> Vec<f32> {
    let (grid, screen) = (space.grid_size(), space.screen_size());
    let mut counts = vec![0f32; screen.x as usize * screen.y as usize];
    for gy in 0..grid.y {
        for gx in 0..grid.x {
            let Some(s) = space.grid_to_screen(Vec2::new(gx as f32 + 0.5, gy as f32 + 0.5)) else {
                continue;
            };
            let p = s.floor();
            if p.x >= 0.0 && p.y >= 0.0 && p.x < screen.x as f32 && p.y < screen.y as f32 {
                counts[p.y as usize * screen.x as usize + p.x as usize] += 1.0;
            }
        }
    }
    counts
}

/// On-screen samples per pixel of two spaces in one eccentricity ring, and their ratio.
#[derive(Clone, Copy, Debug)]
pub struct RingGain {
    /// Ring bounds in the paper's normalised eccentricity (r / r_max · 80).
    pub e_lo: f64,
    pub e_hi: f64,
    pub pixels: usize,
    /// Mean samples per pixel of the space measured (`space`) and of the baseline.
    pub density: f64,
    pub baseline: f64,
}

impl RingGain {
    /// density / baseline (∞ where the baseline has no sample in the ring).
    pub fn gain(&self) -> f64 {
        self.density / self.baseline
    }
}

/// Per eccentricity ring (`rings` equal rings out to the farthest corner of `space`'s gaze), the
/// on-screen density of `space` against `baseline` (texel centres counted, as
/// `samples_per_pixel`); rings holding no pixel are left out. The last entry is the whole screen.
pub fn ring_density_gain(
    space: &dyn SamplingSpace,
    baseline: &dyn SamplingSpace,
    rings: usize,
) -> Vec<RingGain> {
    let screen = space.screen_size();
    let ring_set = Rings::new(screen.x, screen.y, space.gaze(), rings);
    let map = |s: &dyn SamplingSpace| {
        samples_per_pixel(s)
            .into_iter()
            .map(f64::from)
            .collect::<Vec<f64>>()
    };
    let (a, b) = (map(space), map(baseline));
    let (ma, mb, counts) = (
        ring_set.mean(&a),
        ring_set.mean(&b),
        ring_set.pixel_counts(),
    );
    let e = |r: f64| r / ring_set.r_max * ECC_MAX;
    let mut out: Vec<RingGain> = (0..rings)
        .filter_map(|i| {
            let (r0, r1) = ring_set.bounds(i);
            Some(RingGain {
                e_lo: e(r0),
                e_hi: e(r1),
                pixels: counts[i],
                density: ma[i]?,
                baseline: mb[i]?,
            })
        })
        .collect();
    let pixels = a.len() as f64;
    out.push(RingGain {
        e_lo: 0.0,
        e_hi: ECC_MAX,
        pixels: a.len(),
        density: a.iter().sum::<f64>() / pixels,
        baseline: b.iter().sum::<f64>() / pixels,
    });
    out
}

/// RGBA8 heatmap of a density map: viridis-like ramp over log2 density in [1/64, 64]
/// (clamped), black where no sample lands, the gaze marked by a white cross in a ring.
pub fn heatmap_rgba(density: &[f32], width: u32, height: u32, gaze: Vec2) -> Vec<u8> {
    assert_eq!(
        density.len(),
        width as usize * height as usize,
        "density map size"
    );
    let mut rgba: Vec<u8> = density
        .iter()
        .flat_map(|&d| {
            let [r, g, b] = if d > 0.0 {
                ramp((d.log2() - LOG2_MIN) / (LOG2_MAX - LOG2_MIN))
            } else {
                [0, 0, 0]
            };
            [r, g, b, 255]
        })
        .collect();
    // Cross of half-length 6 px plus a circle of radius 6 px around the gaze pixel.
    let centre = gaze.floor() + Vec2::splat(0.5);
    for y in 0..height {
        for x in 0..width {
            let d = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) - centre;
            let on_cross = (d.x.abs() < 0.5 || d.y.abs() < 0.5) && d.abs().max_element() <= 6.0;
            let on_circle = (d.length() - 6.0).abs() < 0.5;
            if on_cross || on_circle {
                let i = (y * width + x) as usize * 4;
                rgba[i..i + 4].copy_from_slice(&[255, 255, 255, 255]);
            }
        }
    }
    rgba
}

/// `frame` (RGBA8) with `heat` (RGBA8, same size) laid over it at `weight` (0: the frame, 1: the
/// heat map); the gaze marks, drawn white in `heat`, stay fully white.
pub fn overlay(frame: &[u8], heat: &[u8], weight: f32) -> Vec<u8> {
    assert_eq!(
        frame.len(),
        heat.len(),
        "overlay of images of different sizes"
    );
    frame
        .chunks_exact(4)
        .zip(heat.chunks_exact(4))
        .flat_map(|(f, h)| {
            if h[..3] == [255, 255, 255] {
                return [255, 255, 255, 255];
            }
            let mix =
                |k: usize| (f[k] as f32 * (1.0 - weight) + h[k] as f32 * weight).round() as u8;
            [mix(0), mix(1), mix(2), 255]
        })
        .collect()
}

/// Mean of `density` over a (2·radius + 1)² box around each pixel (clipped at the borders).
/// Peripheral counts are 0 or 1 per pixel; smoothing them first makes the heatmap readable.
pub fn box_filter(density: &[f32], width: u32, height: u32, radius: u32) -> Vec<f32> {
    let (w, h, r) = (width as usize, height as usize, radius as usize);
    // Summed-area table with a zero row and column in front.
    let mut sat = vec![0f64; (w + 1) * (h + 1)];
    for y in 0..h {
        for x in 0..w {
            sat[(y + 1) * (w + 1) + x + 1] =
                density[y * w + x] as f64 + sat[y * (w + 1) + x + 1] + sat[(y + 1) * (w + 1) + x]
                    - sat[y * (w + 1) + x];
        }
    }
    let mut out = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let (x0, y0, x1, y1) = (
                x.saturating_sub(r),
                y.saturating_sub(r),
                (x + r + 1).min(w),
                (y + r + 1).min(h),
            );
            let sum = sat[y1 * (w + 1) + x1] - sat[y0 * (w + 1) + x1] - sat[y1 * (w + 1) + x0]
                + sat[y0 * (w + 1) + x0];
            out.push((sum / ((x1 - x0) * (y1 - y0)) as f64) as f32);
        }
    }
    out
}

/// Viridis approximated by 5 stops (linear in between); `t` in [0, 1], clamped. Its top is yellow,
/// so white (the gaze mark) and black (no sample) stay distinct.
pub(crate) fn ramp(t: f32) -> [u8; 3] {
    const STOPS: [[f32; 3]; 5] = [
        [68.0, 1.0, 84.0],
        [59.0, 82.0, 139.0],
        [33.0, 145.0, 140.0],
        [94.0, 201.0, 98.0],
        [253.0, 231.0, 37.0],
    ];
    let x = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as f32;
    let i = (x as usize).min(STOPS.len() - 2);
    let f = x - i as f32;
    std::array::from_fn(|c| (STOPS[i][c] + (STOPS[i + 1][c] - STOPS[i][c]) * f).round() as u8)
}

/// Plot of samples per pixel against eccentricity, per ring: VP measured, the acuity target,
/// uniform at VP's sample budget and Cartesian 1 spp. The paper's axis: normalised eccentricity
/// (r / r_max · 80; r_max is the farthest-corner radius, Visual-Polar's own with the default
/// radius mode). The headset axis: true eccentricity through the headset's FOV.
pub fn density_plot(path: &Path, vp: &VisualPolar, rings: usize) -> Result<()> {
    let screen = vp.screen();
    let measured: Vec<f64> = samples_per_pixel(vp).iter().map(|&c| c as f64).collect();
    let budget = vp.sample_count() as f64;
    let pixels: Vec<Vec2> = (0..screen.y)
        .flat_map(|y| (0..screen.x).map(move |x| Vec2::new(x as f32 + 0.5, y as f32 + 0.5)))
        .collect();
    // Per axis: the rings, the target per pixel, degrees per ring unit, the axis end and label.
    let (ring_set, target, ecc_per_unit, e_end, x_label): (Rings, Vec<f64>, f64, f64, &str) =
        match vp.headset() {
            None => {
                // Acuity target: density c·V(e(r)) with c chosen so that its integral over the whole
                // r_max disc equals VP's total sample count (VP spends its budget on that disc,
                // corners off screen included), i.e. c = budget / ∫₀^r_max V(e(r)) 2πr dr (midpoint rule).
                let ring_set = Rings::new(screen.x, screen.y, vp.gaze(), rings);
                let r_max = ring_set.r_max;
                let e_of = move |r: f64| r / r_max * ECC_MAX;
                let steps = 4096;
                let dr = r_max / steps as f64;
                let integral: f64 = (0..steps)
                    .map(|i| (i as f64 + 0.5) * dr)
                    .map(|r| acuity(e_of(r)) * std::f64::consts::TAU * r * dr)
                    .sum();
                let c = budget / integral;
                let target = pixels
                    .iter()
                    .map(|&p| c * acuity(e_of((p - vp.gaze()).length() as f64)))
                    .collect();
                (
                    ring_set,
                    target,
                    ECC_MAX / r_max,
                    ECC_MAX,
                    "normalised eccentricity (r / r_max · 80)",
                )
            }
            Some(axis) => {
                // Acuity target per unit of the polar measure e·de·dφ (φ: the pixel angle VP lays its
                // rows on) with VP's budget over [0, e_max]; a pixel holds e·|∂(e, φ)/∂(x, y)| of it.
                let gaze = vp.gaze();
                let ecc = |p: Vec2| axis.eccentricity(p - gaze) as f64;
                let e: Vec<f64> = pixels.iter().map(|&p| ecc(p)).collect();
                let e_max = axis.e_max as f64;
                let steps = 4096;
                let de = e_max / steps as f64;
                let integral: f64 = (0..steps)
                    .map(|i| (i as f64 + 0.5) * de)
                    .map(|e| acuity(e) * std::f64::consts::TAU * e * de)
                    .sum();
                let c = budget / integral;
                let target = pixels
                    .iter()
                    .zip(&e)
                    .map(|(&p, &e)| c * acuity(e) * e * polar_jacobian(&ecc, p - gaze, p))
                    .collect();
                let ring_set = Rings::from_coordinates(screen.x, gaze, &e, e_max, rings);
                (
                    ring_set,
                    target,
                    1.0,
                    e_max,
                    "true eccentricity (degrees through the headset's FOV)",
                )
            }
        };

    let mid = |i: usize| {
        let (r0, r1) = ring_set.bounds(i);
        0.5 * (r0 + r1) * ecc_per_unit
    };
    let per_ring = |label: &str, map: &[f64]| Series {
        label: label.into(),
        points: ring_set
            .mean(map)
            .into_iter()
            .enumerate()
            .filter_map(|(i, m)| Some((mid(i), m?)))
            .collect(),
    };
    let flat = |label: String, v: f64| Series {
        label,
        points: vec![(0.0, v), (e_end, v)],
    };
    let uniform = budget / (screen.x as f64 * screen.y as f64);
    let mut series = vec![
        per_ring("Visual-Polar (measured)", &measured),
        per_ring("acuity target (∝ V(e), same budget)", &target),
        flat(format!("uniform, same budget ({uniform:.2})"), uniform),
        flat("Cartesian 1 spp".into(), 1.0),
    ];
    if vp.params().layout != VpLayout::Paper {
        // What the screen-clipped layout buys: the paper's layout at the same gaze.
        let paper = VisualPolar::new(
            screen,
            vp.gaze(),
            VisualPolarParams {
                layout: VpLayout::Paper,
                ..*vp.params()
            },
        )?;
        let paper_map: Vec<f64> = samples_per_pixel(&paper)
            .iter()
            .map(|&c| c as f64)
            .collect();
        series[0].label = format!(
            "Visual-Polar, {} (measured)",
            crate::render_profile::layout_name(vp.params().layout)
        );
        series.push(per_ring(
            "Visual-Polar, paper's layout (measured)",
            &paper_map,
        ));
    }
    let title = format!(
        "Sample density, {}×{}, gaze ({:.0}, {:.0})",
        screen.x,
        screen.y,
        vp.gaze().x,
        vp.gaze().y
    );
    line_plot(path, &title, x_label, "samples per pixel", &series, true)
}

/// |∂(e, φ)/∂(x, y)| at pixel `p` (offset `d` from the gaze): degrees × radians per pixel², by
/// central differences of `ecc` and φ = atan2(d.y, d.x) exactly.
fn polar_jacobian(ecc: &dyn Fn(Vec2) -> f64, d: Vec2, p: Vec2) -> f64 {
    let r2 = d.length_squared() as f64;
    if r2 < 1e-12 {
        return 0.0;
    }
    let h = 0.25f32;
    let de_dx = (ecc(p + Vec2::X * h) - ecc(p - Vec2::X * h)) / (2.0 * h) as f64;
    let de_dy = (ecc(p + Vec2::Y * h) - ecc(p - Vec2::Y * h)) / (2.0 * h) as f64;
    (de_dx * d.x as f64 / r2 + de_dy * d.y as f64 / r2).abs()
}

#[cfg(test)]
mod tests {
    use super::*;
    use fovea_renderer::sampling::{Cartesian, VisualPolarParams};
    use glam::UVec2;

    fn centred_vp() -> VisualPolar {
        VisualPolar::new(
            UVec2::new(320, 360),
            Vec2::new(160.0, 180.0),
            VisualPolarParams::default(),
        )
        .unwrap()
    }

    #[test]
    fn overlay_mixes_by_weight_and_keeps_the_gaze_marks_white() {
        let frame = [100, 0, 200, 255, 10, 20, 30, 255];
        let heat = [0, 100, 0, 255, 255, 255, 255, 255];
        assert_eq!(
            overlay(&frame, &heat, 0.25),
            vec![75, 25, 150, 255, 255, 255, 255, 255]
        );
        assert_eq!(overlay(&frame, &heat, 0.0)[..4], frame[..4]);
    }

    #[test]
    fn cartesian_is_one_sample_everywhere() {
        let d = samples_per_pixel(&Cartesian::new(UVec2::new(37, 23)));
        assert_eq!(d.len(), 37 * 23);
        assert!(d.iter().all(|&c| c == 1.0));
    }

    #[test]
    fn totals_match_the_on_screen_texels() {
        for gaze in [Vec2::new(160.0, 180.0), Vec2::new(20.0, 30.0)] {
            let vp =
                VisualPolar::new(UVec2::new(320, 360), gaze, VisualPolarParams::default()).unwrap();
            let (grid, on_screen) = (vp.grid_size(), |s: Vec2| {
                s.x >= 0.0 && s.y >= 0.0 && s.x < 320.0 && s.y < 360.0
            });
            let expected = (0..grid.y)
                .flat_map(|y| (0..grid.x).map(move |x| Vec2::new(x as f32 + 0.5, y as f32 + 0.5)))
                .filter(|&g| vp.grid_to_screen(g).is_some_and(on_screen))
                .count();
            let total: f64 = samples_per_pixel(&vp).iter().map(|&c| c as f64).sum();
            assert_eq!(total as usize, expected);
            assert!(expected as u64 <= vp.sample_count());
        }
    }

    #[test]
    fn visual_polar_is_dense_at_the_gaze_and_sparse_in_the_corners() {
        let vp = centred_vp();
        let d = samples_per_pixel(&vp);
        let mean_where = |keep: &dyn Fn(f32) -> bool| {
            let v: Vec<f32> = (0..360 * 320)
                .filter(|i| {
                    keep(
                        (Vec2::new((i % 320) as f32 + 0.5, (i / 320) as f32 + 0.5) - vp.gaze())
                            .length(),
                    )
                })
                .map(|i| d[i])
                .collect();
            v.iter().sum::<f32>() / v.len() as f32
        };
        let fovea = mean_where(&|r| r < vp.r_fovea());
        let corners = mean_where(&|r| r > 0.9 * vp.r_max());
        assert!(fovea > 2.0, "fovea density {fovea}");
        assert!(corners < 0.2, "corner density {corners}");
    }

    #[test]
    fn heatmap_marks_the_gaze() {
        let (w, h) = (40u32, 30u32);
        let density: Vec<f32> = (0..w * h)
            .map(|i| if i % 7 == 0 { 0.0 } else { 2.0 })
            .collect();
        let rgba = heatmap_rgba(&density, w, h, Vec2::new(12.3, 20.7));
        let px = |x: u32, y: u32| &rgba[((y * w + x) * 4) as usize..((y * w + x) * 4 + 4) as usize];
        assert_eq!(px(12, 20), [255, 255, 255, 255]);
        assert_eq!(px(12, 14), [255, 255, 255, 255]); // top of the cross
        assert_eq!(px(0, 0), [0, 0, 0, 255]); // index 0: no sample → black
        assert_ne!(px(1, 0), [255, 255, 255, 255]);
        assert_ne!(px(1, 0), [0, 0, 0, 255]);
        // Denser is brighter on the ramp (viridis rises in green).
        assert!(ramp(0.9)[1] > ramp(0.1)[1]);
    }

    #[test]
    fn box_filter_keeps_the_mean_of_a_flat_map_and_spreads_a_spike() {
        let flat = box_filter(&[3.0; 12 * 9], 12, 9, 2);
        assert!(flat.iter().all(|&v| (v - 3.0).abs() < 1e-6));
        let mut spike = vec![0.0; 9 * 9];
        spike[4 * 9 + 4] = 25.0;
        let s = box_filter(&spike, 9, 9, 2);
        assert_eq!((s[4 * 9 + 4], s[2 * 9 + 2], s[9 + 4]), (1.0, 1.0, 0.0));
    }

    /// The screen-clipped layout against the paper's, gaze in a corner of the 1280×1440 FOVE eye
    /// (853×960 grid), 16 rings of 5°: every ring at least as dense, the screen as a whole ≫.
    #[test]
    fn screen_clipped_density_gain_per_ring() {
        let (screen, gaze) = (UVec2::new(1280, 1440), Vec2::new(10.0, 10.0));
        let params = VisualPolarParams {
            layout: VpLayout::ScreenClipped,
            ..Default::default()
        };
        let clipped = VisualPolar::new(screen, gaze, params).unwrap();
        let paper = VisualPolar::new(screen, gaze, VisualPolarParams::default()).unwrap();
        assert_eq!(clipped.grid_size(), UVec2::new(853, 960));
        let gains = ring_density_gain(&clipped, &paper, 16);
        println!("eccentricity | pixels | paper spp | screen-clipped spp | gain");
        for g in &gains {
            println!(
                "{:>4.0}–{:<3.0}° | {:>7} | {:>9.3} | {:>18.3} | {:>6.2}×",
                g.e_lo,
                g.e_hi,
                g.pixels,
                g.baseline,
                g.density,
                g.gain()
            );
        }
        let (rings, whole) = gains.split_at(gains.len() - 1);
        assert_eq!(rings.len(), 16, "every ring of a corner gaze holds pixels");
        for g in rings {
            assert!(
                g.gain() >= 1.0,
                "ring {:.0}–{:.0}°: gain {}",
                g.e_lo,
                g.e_hi,
                g.gain()
            );
        }
        // The paper's layout keeps ≈ 24 % of its samples on screen with the gaze in a corner.
        assert!(
            whole[0].gain() > 3.5,
            "whole screen: gain {}",
            whole[0].gain()
        );
        let total = |s: &VisualPolar| samples_per_pixel(s).iter().map(|&c| c as f64).sum::<f64>();
        assert_eq!(
            total(&clipped),
            clipped.sample_count() as f64,
            "every texel centre lands on the screen"
        );
    }

    /// The screen-aware ρ axis against the screen-clipped layout, gaze in a corner of the FOVE eye:
    /// samples per pixel / V(e) is flat beyond the fovea (the acuity target) instead of rising
    /// again in the outermost rings, and the outermost rings give their samples back to the rest.
    #[test]
    fn screen_aware_density_follows_acuity() {
        let (screen, gaze) = (UVec2::new(1280, 1440), Vec2::new(10.0, 10.0));
        let space = |layout| {
            VisualPolar::new(
                screen,
                gaze,
                VisualPolarParams {
                    layout,
                    ..Default::default()
                },
            )
            .unwrap()
        };
        let (aware, clipped) = (space(VpLayout::ScreenAware), space(VpLayout::ScreenClipped));
        assert_eq!(aware.sample_count(), clipped.sample_count());
        let gains = ring_density_gain(&aware, &clipped, 16);
        println!("eccentricity | pixels | screen-clipped spp | screen-aware spp | spp / V(e) (screen-aware, screen-clipped)");
        let per_acuity = |g: &RingGain, d: f64| d / acuity(0.5 * (g.e_lo + g.e_hi));
        for g in &gains[..gains.len() - 1] {
            println!(
                "{:>4.0}–{:<3.0}° | {:>7} | {:>9.3} | {:>9.3} | {:.5} {:.5}",
                g.e_lo,
                g.e_hi,
                g.pixels,
                g.baseline,
                g.density,
                per_acuity(g, g.density),
                per_acuity(g, g.baseline)
            );
        }
        // Rings beyond 10° (past the fovea and its edge ring), whole rings of the acuity target.
        let periphery: Vec<&RingGain> = gains[..gains.len() - 1]
            .iter()
            .filter(|g| g.e_lo >= 10.0)
            .collect();
        let spread = |d: &dyn Fn(&RingGain) -> f64| {
            let v: Vec<f64> = periphery.iter().map(|g| per_acuity(g, d(g))).collect();
            v.iter().cloned().fold(0.0, f64::max) / v.iter().cloned().fold(f64::INFINITY, f64::min)
        };
        let (aware_spread, clipped_spread) = (spread(&|g| g.density), spread(&|g| g.baseline));
        println!("spp / V(e) max/min beyond 10°: screen-aware {aware_spread:.2}, screen-clipped {clipped_spread:.2}");
        assert!(
            aware_spread < 1.35,
            "screen-aware: spp / V(e) varies {aware_spread}× beyond 10°"
        );
        assert!(
            clipped_spread > 3.0,
            "the screen-clipped layout's outer rings were expected to rise: {clipped_spread}"
        );
        let outermost = periphery.last().unwrap();
        assert!(
            outermost.gain() < 0.5,
            "75–80°: {} of the screen-clipped density",
            outermost.gain()
        );
        let total = |s: &VisualPolar| samples_per_pixel(s).iter().map(|&c| c as f64).sum::<f64>();
        assert!(
            total(&aware) > 0.99 * aware.sample_count() as f64,
            "texel centres land on the screen"
        );
    }

    #[test]
    fn density_plot_writes_a_png() {
        let path = std::env::temp_dir().join(format!("fovea-density-{}.png", std::process::id()));
        density_plot(&path, &centred_vp(), 24).unwrap();
        assert!(image::open(&path).is_ok());
        // The screen-clipped layout adds the paper's layout as a series.
        let params = VisualPolarParams {
            layout: VpLayout::ScreenClipped,
            ..Default::default()
        };
        density_plot(
            &path,
            &VisualPolar::new(UVec2::new(320, 360), Vec2::new(20.0, 30.0), params).unwrap(),
            24,
        )
        .unwrap();
        assert!(image::open(&path).is_ok());
        // The headset axis plots against true eccentricity.
        let fov = fovea_renderer::sampling::FovTangents::from_angles_deg(-45.0, 45.0, -48.4, 48.4);
        let params = VisualPolarParams {
            eccentricity: fovea_renderer::sampling::Eccentricity::Headset(fov),
            ..Default::default()
        };
        density_plot(
            &path,
            &VisualPolar::new(UVec2::new(320, 360), Vec2::new(100.0, 150.0), params).unwrap(),
            24,
        )
        .unwrap();
        assert!(image::open(&path).is_ok());
        std::fs::remove_file(&path).unwrap();
    }
}
