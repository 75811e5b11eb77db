//! `fovea replay`'s checks of one rendered frame against its baseline: change (FLIP and RMSE of
//! the displayed image per ring of distance from the gaze), quality (FLIP against the converged
//! reference, tonemapped like the frame, per ring: it may not grow past a tolerance), gaze (the
//! playback itself).

pub mod baseline;

use crate::eval::metrics::Rings;
use baseline::FrameRecord;
use glam::Vec2;
use serde::{Deserialize, Serialize};

/// What counts as a regression (documented in docs/guide/replay.md; flags override).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Tolerances {
    /// Largest mean FLIP of a ring against the baseline's frame.
    pub change_flip: f64,
    /// Largest RMSE of a ring's displayed sRGB values (0…1) against the baseline's frame.
    pub change_rmse: f64,
    /// A ring's mean FLIP against the reference may grow to baseline × (1 + rel) + abs.
    pub quality_rel: f64,
    pub quality_abs: f64,
    /// Largest gaze-pixel difference from the baseline's.
    pub gaze_px: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        // Same device and build: frames are bit-identical; these allow another driver's rounding.
        Tolerances {
            change_flip: 0.01,
            change_rmse: 0.004,
            quality_rel: 0.05,
            quality_abs: 0.005,
            gaze_px: 1e-3,
        }
    }
}

#[derive(Serialize, Deserialize, Clone, Debug)]
pub struct RingChange {
    pub ring: usize,
    pub flip: Option<f64>,
    pub rmse: Option<f64>,
    pub changed: bool,
}

#[derive(Serialize, Deserialize, Clone, Debug)]
pub struct RingQuality {
    pub ring: usize,
    pub baseline: Option<f64>,
    pub actual: Option<f64>,
    pub limit: Option<f64>,
    pub regressed: bool,
}

#[derive(Serialize, Deserialize, Clone, Debug)]
pub struct FrameCheck {
    pub frame: u32,
    pub change: Vec<RingChange>,
    pub quality: Vec<RingQuality>,
    pub gaze: [f32; 2],
    pub gaze_baseline: [f32; 2],
    pub origin: String,
    pub origin_baseline: String,
    pub gaze_differs: bool,
    /// With the latency model: where the eye is at the frame's display time (left eye's render
    /// pixels) and the frame's FLIP against the reference per ring around it (report only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gaze_true: Option<[f32; 2]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub quality_flip_true_gaze: Option<Vec<Option<f64>>>,
}

impl FrameCheck {
    pub fn changed(&self) -> bool {
        self.change.iter().any(|r| r.changed)
    }

    pub fn regressed(&self) -> bool {
        self.quality.iter().any(|r| r.regressed)
    }

    pub fn failed(&self) -> bool {
        self.changed() || self.regressed() || self.gaze_differs
    }
}

/// One frame's images and gaze, as rendered now.
pub struct FrameImages<'a> {
    pub width: u32,
    pub height: u32,
    /// Displayed image (RGBA8 sRGB) now and in the baseline.
    pub ldr: &'a [u8],
    pub ldr_baseline: &'a [u8],
    /// Per-pixel FLIP of now against the converged reference (tonemapped like the frame).
    pub reference_flip: &'a [f64],
    pub gaze: Vec2,
    pub origin: &'a str,
}

/// Per-ring mean FLIP of the frame against the reference (what a baseline stores).
pub fn quality_flip(images: &FrameImages, rings: usize) -> Vec<Option<f64>> {
    Rings::new(images.width, images.height, images.gaze, rings).mean(images.reference_flip)
}

/// The frame against its baseline record; `flip_map`: per-pixel FLIP of now against the baseline.
pub fn check_frame(
    images: &FrameImages,
    base: &FrameRecord,
    flip_map: &[f64],
    tol: &Tolerances,
) -> FrameCheck {
    let rings = Rings::new(
        images.width,
        images.height,
        images.gaze,
        base.quality_flip.len(),
    );
    let squared: Vec<f64> = images
        .ldr
        .chunks_exact(4)
        .zip(images.ldr_baseline.chunks_exact(4))
        .map(|(a, b)| {
            (0..3)
                .map(|c| ((a[c] as f64 - b[c] as f64) / 255.0).powi(2))
                .sum::<f64>()
                / 3.0
        })
        .collect();
    let (flip, mse) = (rings.mean(flip_map), rings.mean(&squared));
    let change = (0..rings.count)
        .map(|i| {
            let rmse = mse[i].map(f64::sqrt);
            let changed = flip[i].is_some_and(|f| f > tol.change_flip)
                || rmse.is_some_and(|r| r > tol.change_rmse);
            RingChange {
                ring: i,
                flip: flip[i],
                rmse,
                changed,
            }
        })
        .collect();
    let quality = rings
        .mean(images.reference_flip)
        .into_iter()
        .zip(&base.quality_flip)
        .enumerate()
        .map(|(ring, (actual, &baseline))| {
            let limit = baseline.map(|b| b * (1.0 + tol.quality_rel) + tol.quality_abs);
            let regressed = matches!((actual, limit), (Some(a), Some(l)) if a > l);
            RingQuality {
                ring,
                baseline,
                actual,
                limit,
                regressed,
            }
        })
        .collect();
    let gaze_baseline = Vec2::from_array(base.gaze);
    FrameCheck {
        frame: base.frame,
        change,
        quality,
        gaze: images.gaze.to_array(),
        gaze_baseline: base.gaze,
        origin: images.origin.to_string(),
        origin_baseline: base.origin.clone(),
        gaze_differs: (images.gaze - gaze_baseline).length() as f64 > tol.gaze_px
            || images.origin != base.origin,
        gaze_true: None,
        quality_flip_true_gaze: None,
    }
}
