//! Image-quality metrics of a test frame against a reference, whole-frame and per eccentricity
//! ring around the gaze point (`fovea eval`). Images are linear RGB floats (alpha ignored).
//!
//! Structure, so further per-pixel metrics (FLIP) plug in: every metric is first a per-pixel map
//! (`PixelMaps`), then `Rings` averages any map over each ring's pixels. RMSE and PSNR come from
//! the mean of the squared-error map, SSIM is the mean of the SSIM map.

use glam::Vec2;
use serde::Serialize;

/// Rec. 709 / sRGB luma weights (on linear RGB).
pub const LUMA_709: [f64; 3] = [0.2126, 0.7152, 0.0722];
/// PSNR reported for identical pixels (MSE = 0) and the cap for anything above it: JSON has no
/// infinity, and 100 dB (MSE 1e-10, far below f32 noise of radiance near 1) reads as "identical".
pub const PSNR_CAP_DB: f64 = 100.0;
/// SSIM window (Wang et al. 2004): 11×11 Gaussian, σ = 1.5; constants K1, K2 with range L = 1.
pub const SSIM_RADIUS: usize = 5;
pub const SSIM_SIGMA: f64 = 1.5;
const SSIM_C1: f64 = 0.01 * 0.01;
const SSIM_C2: f64 = 0.03 * 0.03;
/// The paper's normalised eccentricity: r_max (farthest screen corner) ↦ 80 "degrees".
pub const ECC_MAX: f64 = 80.0;

/// Rec. 709 luma of linear RGB.
pub fn luma(p: [f32; 4]) -> f64 {
    LUMA_709[0] * p[0] as f64 + LUMA_709[1] * p[1] as f64 + LUMA_709[2] * p[2] as f64
}

/// PSNR (dB) for peak 1.0 from an MSE, capped at `PSNR_CAP_DB`.
pub fn psnr_from_mse(mse: f64) -> f64 {
    if mse <= 0.0 {
        PSNR_CAP_DB
    } else {
        (-10.0 * mse.log10()).min(PSNR_CAP_DB)
    }
}

/// Per-pixel metric maps, row-major, one value per pixel.
pub struct PixelMaps {
    pub width: u32,
    pub height: u32,
    /// Squared error averaged over R, G, B.
    pub squared_error: Vec<f64>,
    /// SSIM of the luma around each pixel.
    pub ssim: Vec<f64>,
}

impl PixelMaps {
    pub fn new(reference: &[[f32; 4]], test: &[[f32; 4]], width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        assert!(
            reference.len() == n && test.len() == n,
            "images must both hold width×height pixels"
        );
        let squared_error = reference
            .iter()
            .zip(test)
            .map(|(a, b)| {
                (0..3)
                    .map(|c| (a[c] as f64 - b[c] as f64).powi(2))
                    .sum::<f64>()
                    / 3.0
            })
            .collect();
        let luma_of = |img: &[[f32; 4]]| img.iter().map(|&p| luma(p)).collect::<Vec<_>>();
        let ssim = ssim_map(
            &luma_of(reference),
            &luma_of(test),
            width as usize,
            height as usize,
        );
        Self {
            width,
            height,
            squared_error,
            ssim,
        }
    }
}

/// SSIM map (Wang et al. 2004) of two luma images. Borders clamp to the edge (the window's
/// out-of-image taps repeat the nearest pixel) so every pixel gets a value: the outermost
/// eccentricity rings lie in the image corners, and evaluating only where the whole window fits
/// would drop much of them.
pub fn ssim_map(x: &[f64], y: &[f64], width: usize, height: usize) -> Vec<f64> {
    let kernel = gaussian_kernel();
    let blur = |f: &dyn Fn(usize) -> f64| {
        blur_clamped(
            &(0..x.len()).map(f).collect::<Vec<_>>(),
            width,
            height,
            &kernel,
        )
    };
    let (mx, my) = (blur(&|i| x[i]), blur(&|i| y[i]));
    let (xx, yy, xy) = (
        blur(&|i| x[i] * x[i]),
        blur(&|i| y[i] * y[i]),
        blur(&|i| x[i] * y[i]),
    );
    (0..x.len())
        .map(|i| {
            let (vx, vy, cov) = (
                xx[i] - mx[i] * mx[i],
                yy[i] - my[i] * my[i],
                xy[i] - mx[i] * my[i],
            );
            ((2.0 * mx[i] * my[i] + SSIM_C1) * (2.0 * cov + SSIM_C2))
                / ((mx[i] * mx[i] + my[i] * my[i] + SSIM_C1) * (vx + vy + SSIM_C2))
        })
        .collect()
}

fn gaussian_kernel() -> Vec<f64> {
    let r = SSIM_RADIUS as f64;
    let w: Vec<f64> = (0..=2 * SSIM_RADIUS)
        .map(|i| (-(i as f64 - r).powi(2) / (2.0 * SSIM_SIGMA * SSIM_SIGMA)).exp())
        .collect();
    let sum: f64 = w.iter().sum();
    w.iter().map(|v| v / sum).collect()
}

/// Separable convolution with clamp-to-edge addressing.
fn blur_clamped(src: &[f64], width: usize, height: usize, kernel: &[f64]) -> Vec<f64> {
    let r = kernel.len() as isize / 2;
    let tap = |i: usize, k: usize, n: usize| {
        (i as isize + k as isize - r).clamp(0, n as isize - 1) as usize
    };
    let mut rows = vec![0.0; src.len()];
    for y in 0..height {
        for x in 0..width {
            rows[y * width + x] = kernel
                .iter()
                .enumerate()
                .map(|(k, w)| w * src[y * width + tap(x, k, width)])
                .sum();
        }
    }
    let mut out = vec![0.0; src.len()];
    for y in 0..height {
        for x in 0..width {
            out[y * width + x] = kernel
                .iter()
                .enumerate()
                .map(|(k, w)| w * rows[tap(y, k, height) * width + x])
                .sum();
        }
    }
    out
}

/// `n` equal-width rings of screen distance from the gaze point out to r_max, the largest
/// gaze-to-corner distance (as Visual-Polar's radius). Pixel (x, y) is at its centre
/// (x + 0.5, y + 0.5); y points down. `from_coordinates` rings any other per-pixel coordinate
/// (e.g. the true eccentricity through a headset's FOV); r_max is then that coordinate's top.
pub struct Rings {
    pub gaze: Vec2,
    pub r_max: f64,
    pub count: usize,
    width: u32,
    /// Ring of every pixel, row-major.
    index: Vec<u32>,
}

impl Rings {
    pub fn new(width: u32, height: u32, gaze: Vec2, count: usize) -> Self {
        assert!(count > 0, "at least one ring");
        let g = gaze.as_dvec2();
        let screen = glam::DVec2::new(width as f64, height as f64);
        let r_max = g
            .abs()
            .max((screen - g).abs())
            .length()
            .max(f64::MIN_POSITIVE);
        let distances: Vec<f64> = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| (glam::DVec2::new(x as f64 + 0.5, y as f64 + 0.5) - g).length())
            .collect();
        Self::from_coordinates(width, gaze, &distances, r_max, count)
    }

    /// `count` equal-width rings of a per-pixel coordinate (row-major, ≥ 0) over [0, max];
    /// values past max fall in the last ring.
    pub fn from_coordinates(
        width: u32,
        gaze: Vec2,
        coordinates: &[f64],
        max: f64,
        count: usize,
    ) -> Self {
        assert!(count > 0, "at least one ring");
        let max = max.max(f64::MIN_POSITIVE);
        let index = coordinates
            .iter()
            .map(|&c| ((c / max * count as f64).max(0.0) as usize).min(count - 1) as u32)
            .collect();
        Self {
            gaze,
            r_max: max,
            count,
            width,
            index,
        }
    }

    /// Ring of pixel (x, y).
    pub fn ring_of(&self, x: u32, y: u32) -> usize {
        self.index[(y * self.width + x) as usize] as usize
    }

    /// Inner and outer radius of ring `i` in pixels.
    pub fn bounds(&self, i: usize) -> (f64, f64) {
        let step = self.r_max / self.count as f64;
        (i as f64 * step, (i + 1) as f64 * step)
    }

    /// Pixels in each ring.
    pub fn pixel_counts(&self) -> Vec<usize> {
        let mut counts = vec![0; self.count];
        for &i in &self.index {
            counts[i as usize] += 1;
        }
        counts
    }

    /// Mean of a per-pixel map over each ring's pixels, skipping NaN entries (pixels a metric
    /// does not cover); `None` where a ring has no such pixel.
    pub fn mean(&self, map: &[f64]) -> Vec<Option<f64>> {
        assert_eq!(
            map.len(),
            self.index.len(),
            "map size differs from the image"
        );
        let mut sum = vec![(0.0, 0usize); self.count];
        for (&i, &v) in self.index.iter().zip(map) {
            if !v.is_nan() {
                sum[i as usize].0 += v;
                sum[i as usize].1 += 1;
            }
        }
        sum.into_iter()
            .map(|(s, n)| (n > 0).then(|| s / n as f64))
            .collect()
    }

    /// Mean of a per-pixel map over the innermost `inner` rings together (the fovea's pixels),
    /// skipping NaN entries.
    pub fn inner_mean(&self, map: &[f64], inner: usize) -> Option<f64> {
        let (mut s, mut n) = (0.0, 0usize);
        for (&i, &v) in self.index.iter().zip(map) {
            if (i as usize) < inner && !v.is_nan() {
                s += v;
                n += 1;
            }
        }
        (n > 0).then(|| s / n as f64)
    }
}

/// Fireflies of an 8-bit RGBA image (as `tonemap_preview` writes it): pixels whose luma (Rec. 709
/// weights on the encoded values) is more than `levels` above that of every neighbour in its 3×3
/// window (border pixels compare with the neighbours they have).
pub fn isolated_bright_pixels(rgba: &[u8], width: usize, height: usize, levels: f64) -> usize {
    let luma = |i: usize| {
        0.2126 * rgba[4 * i] as f64
            + 0.7152 * rgba[4 * i + 1] as f64
            + 0.0722 * rgba[4 * i + 2] as f64
    };
    let mut count = 0;
    for y in 0..height {
        for x in 0..width {
            let centre = luma(y * width + x);
            let brightest_neighbour = (y.saturating_sub(1)..(y + 2).min(height))
                .flat_map(|ny| (x.saturating_sub(1)..(x + 2).min(width)).map(move |nx| (nx, ny)))
                .filter(|&(nx, ny)| (nx, ny) != (x, y))
                .map(|(nx, ny)| luma(ny * width + nx))
                .fold(f64::NEG_INFINITY, f64::max);
            count += (centre - brightest_neighbour > levels) as usize;
        }
    }
    count
}

/// Mean of a map, skipping NaN entries.
pub fn mean(map: &[f64]) -> Option<f64> {
    let (s, n) = map
        .iter()
        .filter(|v| !v.is_nan())
        .fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    (n > 0).then(|| s / n as f64)
}

/// Metrics over a set of pixels; `None` (JSON null) when the set is empty.
#[derive(Clone, Debug, Serialize)]
pub struct Metrics {
    pub pixels: usize,
    pub rmse: Option<f64>,
    /// dB, peak 1.0, capped at `PSNR_CAP_DB` (identical pixels).
    pub psnr: Option<f64>,
    pub ssim: Option<f64>,
    /// Mean FLIP (LDR, the image as displayed) where it was measured ([`add_flip`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub flip: Option<f64>,
}

impl Metrics {
    /// From the mean squared error and mean SSIM over `pixels` pixels.
    pub fn from_means(mse: Option<f64>, ssim: Option<f64>, pixels: usize) -> Self {
        Self {
            pixels,
            rmse: mse.map(f64::sqrt),
            psnr: mse.map(psnr_from_mse),
            ssim,
            flip: None,
        }
    }
}

/// Temporal flicker of a frame pair: per pixel, |Δtest − Δreference| of the displayed sRGB values
/// (mean of R, G, B in 0…1) from the previous frame to this one — the frame-to-frame change the
/// converged images do not have (0 for a still camera's reference: all change is flicker).
pub fn flicker_map(
    test_prev: &[u8],
    test: &[u8],
    reference_prev: &[u8],
    reference: &[u8],
) -> Vec<f64> {
    let grey = |p: &[u8]| (p[0] as f64 + p[1] as f64 + p[2] as f64) / (3.0 * 255.0);
    test_prev
        .chunks_exact(4)
        .zip(test.chunks_exact(4))
        .zip(
            reference_prev
                .chunks_exact(4)
                .zip(reference.chunks_exact(4)),
        )
        .map(|((tp, t), (rp, r))| ((grey(t) - grey(tp)) - (grey(r) - grey(rp))).abs())
        .collect()
}

/// Fills `flip` of the whole frame and of every ring of `eval` from a per-pixel FLIP map.
pub fn add_flip(eval: &mut Evaluation, flip_map: &[f64]) {
    let rings = Rings::new(
        eval.width,
        eval.height,
        Vec2::from_array(eval.gaze),
        eval.rings.len(),
    );
    for (ring, flip) in eval.rings.iter_mut().zip(rings.mean(flip_map)) {
        ring.metrics.flip = flip;
    }
    eval.frame.flip = mean(flip_map);
}

/// Fills `flip` of every ring of a coordinate ring set.
pub fn add_flip_rings(found: &mut [CoordinateRing], rings: &Rings, flip_map: &[f64]) {
    for (ring, flip) in found.iter_mut().zip(rings.mean(flip_map)) {
        ring.metrics.flip = flip;
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct RingMetrics {
    pub ring: usize,
    pub r_inner_px: f64,
    pub r_outer_px: f64,
    /// Normalised eccentricity: r / r_max · 80.
    pub ecc_inner: f64,
    pub ecc_outer: f64,
    #[serde(flatten)]
    pub metrics: Metrics,
}

#[derive(Clone, Debug, Serialize)]
pub struct Evaluation {
    pub width: u32,
    pub height: u32,
    pub gaze: [f32; 2],
    pub r_max_px: f64,
    pub frame: Metrics,
    pub rings: Vec<RingMetrics>,
}

/// One ring of `evaluate_rings`: its coordinate bounds and metrics.
#[derive(Clone, Debug, Serialize)]
pub struct CoordinateRing {
    pub ring: usize,
    pub inner: f64,
    pub outer: f64,
    #[serde(flatten)]
    pub metrics: Metrics,
}

/// Per-ring RMSE, PSNR and SSIM of `test` against `reference` over any ring set.
pub fn evaluate_rings(
    reference: &[[f32; 4]],
    test: &[[f32; 4]],
    width: u32,
    height: u32,
    rings: &Rings,
) -> Vec<CoordinateRing> {
    let maps = PixelMaps::new(reference, test, width, height);
    let (mse, ssim, counts) = (
        rings.mean(&maps.squared_error),
        rings.mean(&maps.ssim),
        rings.pixel_counts(),
    );
    (0..rings.count)
        .map(|i| {
            let (inner, outer) = rings.bounds(i);
            CoordinateRing {
                ring: i,
                inner,
                outer,
                metrics: Metrics::from_means(mse[i], ssim[i], counts[i]),
            }
        })
        .collect()
}

/// Whole-frame and per-ring RMSE, PSNR and SSIM of `test` against `reference`.
pub fn evaluate(
    reference: &[[f32; 4]],
    test: &[[f32; 4]],
    width: u32,
    height: u32,
    gaze: Vec2,
    rings: usize,
) -> Evaluation {
    let maps = PixelMaps::new(reference, test, width, height);
    let ring_set = Rings::new(width, height, gaze, rings);
    let (mse, ssim, counts) = (
        ring_set.mean(&maps.squared_error),
        ring_set.mean(&maps.ssim),
        ring_set.pixel_counts(),
    );
    let rings = (0..rings)
        .map(|i| {
            let (r0, r1) = ring_set.bounds(i);
            RingMetrics {
                ring: i,
                r_inner_px: r0,
                r_outer_px: r1,
                ecc_inner: r0 / ring_set.r_max * ECC_MAX,
                ecc_outer: r1 / ring_set.r_max * ECC_MAX,
                metrics: Metrics::from_means(mse[i], ssim[i], counts[i]),
            }
        })
        .collect();
    Evaluation {
        width,
        height,
        gaze: gaze.to_array(),
        r_max_px: ring_set.r_max,
        frame: Metrics::from_means(
            mean(&maps.squared_error),
            mean(&maps.ssim),
            maps.squared_error.len(),
        ),
        rings,
    }
}

#[cfg(test)]
#[path = "metrics_tests.rs"]
mod tests;
