//! Exposure: a fixed multiplier, or automatic — every view's screen radiance metered into one
//! histogram of log2 luminance (more weight around each view's gaze), one exposure adapted from
//! it over time like an eye and shared by both eyes. The tone mapping of every view reads the
//! exposure from the GPU (`ExposureState`), so frames in flight never see it change under them,
//! and each frame's copy is read back with the frame (`Renderer::frame_exposure`).

use crate::error::{Error, Result};
use crate::graph::{read_image, write_buffer, FrameRecorder};
use crate::layouts::{
    ExposureAdaptPush, ExposureMeterPush, ExposureState, EXPOSURE_BINS, EXPOSURE_LOG2_MAX,
    EXPOSURE_LOG2_MIN, EXPOSURE_WEIGHT_SCALE,
};
use crate::passes::{Kernel, Pass};
use crate::vk::{Buffer, Context, Image};
use ash::vk;
use glam::{UVec4, Vec2, Vec4};
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// How radiance is scaled before the tone curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Exposure {
    /// A fixed linear multiplier.
    Manual(f32),
    /// Metered from every frame and adapted over time.
    Auto(AutoExposure),
}

impl Default for Exposure {
    fn default() -> Self {
        Exposure::Manual(1.0)
    }
}

impl Exposure {
    /// Automatic exposure with its defaults.
    pub fn auto() -> Exposure {
        Exposure::Auto(AutoExposure::default())
    }

    /// A manual exposure of `ev` stops (multiplier 2^ev).
    pub fn stops(ev: f32) -> Exposure {
        Exposure::Manual(ev.exp2())
    }
}

/// Automatic exposure's metering and adaptation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AutoExposure {
    /// Stops added to the metered exposure (positive: brighter).
    pub compensation_ev: f32,
    /// Time constant of the adaptation toward a brighter scene (the exposure falls), seconds:
    /// the eye's fast light adaptation.
    pub brighten_seconds: f32,
    /// Toward a darker scene (the exposure rises), seconds: slower, as the eye's.
    pub darken_seconds: f32,
    /// Share of the histogram's weight left out at the dark end (shadows under a bright sky
    /// do not drag the exposure up) and at the bright end (light sources and sun glints).
    pub dark_share: f32,
    pub bright_share: f32,
    /// The luminance the metered mean is brought to (middle grey).
    pub key: f32,
    /// Extra weight of the pixels at the gaze over the periphery's (0: flat metering) and the
    /// radius of the weighted region, in degrees from the gaze.
    pub gaze_boost: f32,
    pub gaze_radius_deg: f32,
    /// The exposure's range in stops (a black frame never drives it to infinity).
    pub min_ev: f32,
    pub max_ev: f32,
}

impl Default for AutoExposure {
    fn default() -> Self {
        AutoExposure {
            compensation_ev: 0.0,
            brighten_seconds: 0.35,
            darken_seconds: 1.0,
            dark_share: 0.4,
            bright_share: 0.05,
            key: 0.18,
            gaze_boost: 4.0,
            gaze_radius_deg: 10.0,
            min_ev: -14.0,
            max_ev: 14.0,
        }
    }
}

impl AutoExposure {
    pub fn validate(&self) -> Result<()> {
        let fail = |what: &str| Err(Error::Invalid(format!("automatic exposure: {what}")));
        if !(self.compensation_ev.is_finite() && self.compensation_ev.abs() <= 13.0) {
            return fail("the compensation must be finite, within ±13 stops");
        }
        let positive = |v: f32| v.is_finite() && v > 0.0;
        if !(positive(self.brighten_seconds) && positive(self.darken_seconds)) {
            return fail("the adaptation time constants must be finite and positive");
        }
        let share = |v: f32| (0.0..0.5).contains(&v);
        if !(share(self.dark_share) && share(self.bright_share)) {
            return fail("the left-out shares must be in [0, 0.5)");
        }
        let boost = self.gaze_boost.is_finite() && self.gaze_boost >= 0.0;
        if !(positive(self.key) && positive(self.gaze_radius_deg) && boost) {
            return fail("key, gaze radius and gaze boost must be finite and positive");
        }
        if !(self.min_ev.is_finite() && self.max_ev.is_finite() && self.min_ev < self.max_ev) {
            return fail("the exposure range must be finite and not empty");
        }
        Ok(())
    }
}

struct Meter;
impl Kernel for Meter {
    const SHADER: &'static str = "passes/exposure_meter";
    type Push = ExposureMeterPush;
}

struct Adapt;
impl Kernel for Adapt {
    const SHADER: &'static str = "passes/exposure_adapt";
    type Push = ExposureAdaptPush;
}

/// Histogram entries per view at most: each is one block's mean luminance over 4×4 taps (a mean
/// of log luminance needs no more; blocks of at least 4×4 pixels average the noise of a frame
/// without a denoiser).
const METERED_BLOCKS: u32 = 1 << 15;
const MIN_BLOCK: u32 = 4;

/// The exposure automatic metering gives a view's screen radiance (`width` × `height`, rows top
/// to bottom) on its first frame, before any adaptation: `exposure_meter.comp` and the target of
/// `exposure_adapt.comp` on the CPU (the same blocks, taps, weights, bins and trimmed mean), for
/// an exposure held fixed over a comparison (`fovea quality --display-exposure metered`).
/// `tests/exposure.rs` holds it to the device's.
pub fn metered_exposure(
    radiance: &[[f32; 4]],
    width: u32,
    height: u32,
    settings: &AutoExposure,
    gaze: Vec2,
    pixels_per_degree: f32,
) -> f32 {
    const TAPS: u32 = 4;
    let block = (((width * height) as f32 / METERED_BLOCKS as f32)
        .sqrt()
        .ceil() as u32)
        .max(MIN_BLOCK);
    let inverse_radius = 1.0 / (settings.gaze_radius_deg * pixels_per_degree).max(1.0);
    let mut bins = vec![0u32; EXPOSURE_BINS as usize];
    for oy in (0..height).step_by(block as usize) {
        for ox in (0..width).step_by(block as usize) {
            let extent = (block.min(width - ox), block.min(height - oy));
            let (mut sum, mut n) = (0.0f32, 0u32);
            for ty in 0..TAPS {
                for tx in 0..TAPS {
                    let x = ox + (tx * extent.0 + extent.0 / 2) / TAPS;
                    let y = oy + (ty * extent.1 + extent.1 / 2) / TAPS;
                    let c = radiance[(y * width + x) as usize];
                    let l = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
                    // NaN and infinity are left out, as on the device.
                    if (0.0..3.0e38).contains(&l) {
                        sum += l;
                        n += 1;
                    }
                }
            }
            let mean = if n > 0 { sum / n as f32 } else { 0.0 };
            if mean > EXPOSURE_LOG2_MIN.exp2() && mean < 3.0e38 {
                let t = (mean.log2() - EXPOSURE_LOG2_MIN) / (EXPOSURE_LOG2_MAX - EXPOSURE_LOG2_MIN);
                let bin =
                    (t * EXPOSURE_BINS as f32).clamp(0.0, (EXPOSURE_BINS - 1) as f32) as usize;
                let centre = Vec2::new(ox as f32, oy as f32)
                    + 0.5 * Vec2::new(extent.0 as f32, extent.1 as f32);
                let d = (centre - gaze).length() * inverse_radius;
                let w = 1.0 + settings.gaze_boost * (-d * d).exp();
                bins[bin] += (EXPOSURE_WEIGHT_SCALE * w).round() as u32;
            }
        }
    }
    let total: f32 = bins.iter().map(|&b| b as f32).sum();
    if total <= 0.0 {
        return 1.0;
    }
    let (lo, hi) = (
        total * settings.dark_share,
        total * (1.0 - settings.bright_share),
    );
    let bin_log2 = (EXPOSURE_LOG2_MAX - EXPOSURE_LOG2_MIN) / EXPOSURE_BINS as f32;
    let (mut below, mut sum, mut weight) = (0.0f32, 0.0f32, 0.0f32);
    for (i, &b) in bins.iter().enumerate() {
        let w = b as f32;
        let kept = ((below + w).min(hi) - below.max(lo)).max(0.0);
        below += w;
        sum += kept * (EXPOSURE_LOG2_MIN + (i as f32 + 0.5) * bin_log2);
        weight += kept;
    }
    let mean = if weight > 0.0 { sum / weight } else { 0.0 };
    let target = (settings.key.log2() - mean + settings.compensation_ev).clamp(
        settings.min_ev.max(EXPOSURE_LOG2_MIN),
        settings.max_ev.min(EXPOSURE_LOG2_MAX),
    );
    target.exp2()
}

/// The exposure passes and their buffers, one per renderer.
pub struct ExposurePass {
    meter: Pass<Meter>,
    adapt: Pass<Adapt>,
    histogram: Buffer,
    state: Buffer,
    /// Each frame slot's copy of the state, written by the adaptation.
    per_slot: Vec<Buffer>,
}

impl ExposurePass {
    pub fn new(ctx: &Arc<Context>, slots: usize) -> Result<ExposurePass> {
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let histogram = Buffer::device_local(
            ctx,
            "exposure.histogram",
            &[0u32; EXPOSURE_BINS as usize],
            storage,
        )?;
        let initial = ExposureState {
            values: Vec4::new(1.0, 0.0, 0.0, 0.0),
        };
        let state = Buffer::device_local(ctx, "exposure.state", &[initial], storage)?;
        let per_slot = (0..slots)
            .map(|_| {
                Buffer::new(
                    ctx,
                    "exposure.frame",
                    std::mem::size_of::<ExposureState>() as u64,
                    storage,
                    MemoryLocation::GpuToCpu,
                )
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(ExposurePass {
            meter: Pass::single(ctx)?,
            adapt: Pass::single(ctx)?,
            histogram,
            state,
            per_slot,
        })
    }

    /// The state every tone mapping reads (`ExposureState`).
    pub fn state(&self) -> &Buffer {
        &self.state
    }

    /// Adds one view's screen radiance to this frame's histogram; `gaze` in pixels,
    /// `pixels_per_degree` at the view's centre.
    pub fn record_meter(
        &self,
        rec: &mut FrameRecorder,
        settings: &AutoExposure,
        radiance: &Image,
        gaze: Vec2,
        pixels_per_degree: f32,
    ) -> Result<()> {
        let pixels = radiance.width * radiance.height;
        let block = ((pixels as f32 / METERED_BLOCKS as f32).sqrt().ceil() as u32).max(MIN_BLOCK);
        let radius = (settings.gaze_radius_deg * pixels_per_degree).max(1.0);
        let push = ExposureMeterPush {
            gaze: Vec4::new(gaze.x, gaze.y, 1.0 / radius, settings.gaze_boost),
            config: UVec4::new(block, 0, 0, 0),
        };
        let binds = [
            read_image("radiance", radiance),
            write_buffer("histogram", &self.histogram),
        ];
        let threads = [
            radiance.width.div_ceil(block),
            radiance.height.div_ceil(block),
            1,
        ];
        self.meter
            .dispatch(rec, "exposure_meter", &binds, &push, threads)
    }

    /// This frame's exposure, after every view's meter: adapted from the histogram over
    /// `seconds` since the last frame (automatic), or `exposure`'s multiplier (manual).
    pub fn record_adapt(
        &self,
        rec: &mut FrameRecorder,
        exposure: &Exposure,
        seconds: f32,
        slot: usize,
    ) -> Result<()> {
        let auto = match exposure {
            Exposure::Auto(a) => *a,
            Exposure::Manual(_) => AutoExposure::default(),
        };
        let (mode, manual) = match exposure {
            Exposure::Auto(_) => (1.0, 1.0),
            Exposure::Manual(m) => (0.0, *m),
        };
        let push = ExposureAdaptPush {
            params: Vec4::new(mode, manual, auto.compensation_ev, seconds.max(0.0)),
            adapt: Vec4::new(
                auto.brighten_seconds,
                auto.darken_seconds,
                auto.dark_share,
                auto.bright_share,
            ),
            limits: Vec4::new(
                auto.min_ev.max(EXPOSURE_LOG2_MIN),
                auto.max_ev.min(EXPOSURE_LOG2_MAX),
                auto.key.log2(),
                0.0,
            ),
        };
        let binds = [
            write_buffer("histogram", &self.histogram),
            write_buffer("state", &self.state),
            write_buffer("frame_exposure", &self.per_slot[slot]),
        ];
        self.adapt
            .dispatch(rec, "exposure_adapt", &binds, &push, [1, 1, 1])
    }

    /// The exposure multiplier slot `slot`'s frame applied (valid once that frame completed).
    pub fn read_slot(&self, slot: usize) -> Result<f32> {
        let mut state = [ExposureState { values: Vec4::ZERO }];
        self.per_slot[slot].read_into(&mut state)?;
        Ok(state[0].values.x)
    }
}
