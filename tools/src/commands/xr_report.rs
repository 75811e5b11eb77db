//! `fovea xr`'s report.json: `fovea render`'s figures (per eye and rendered frame) plus the
//! runtime, the system's properties, which headset figure came from the runtime and which from
//! the `--headset` TOML, and the gaze's age at display.

use super::render_args::RenderArgs;
use anyhow::{Context, Result};
use ash::vk;
use fovea_hal::openxr::{OpenXrRuntime, RuntimeFigures, SessionEnd};
use fovea_hal::HmdDescription;
use fovea_renderer::frame::FrameStats;
use serde::Serialize;
use std::collections::BTreeMap;

pub struct Tally<'a> {
    pub frames: u64,
    pub rendered: u32,
    /// Rendered frames whose GPU times were read.
    pub timed: u32,
    /// live, held, centre.
    pub origins: [u32; 3],
    /// Of the centre frames, those whose gaze lay behind or outside an eye's view.
    pub outside_view: u32,
    pub live_ages_ns: &'a [i64],
    pub pass_sums: &'a BTreeMap<String, f64>,
    pub stats: FrameStats,
    pub cpu_ms: f64,
}

pub struct Inputs<'a> {
    pub render: &'a RenderArgs<'a>,
    /// `--reference-space`, as the report names it.
    pub reference_space: &'static str,
    /// The denoiser and TAA that ran (`auto` resolved).
    pub denoiser: &'a str,
    pub taa: &'a str,
    pub rt: &'a OpenXrRuntime,
    pub base: &'a HmdDescription,
    pub hmd: &'a HmdDescription,
    pub figures: RuntimeFigures,
    pub gaze_source: &'a str,
    pub notice: Option<&'a str>,
    pub device: &'a str,
    pub swapchain_format: vk::Format,
    /// Per eye, as rendered.
    pub eye_size: (u32, u32),
    pub end: SessionEnd,
    pub tally: &'a Tally<'a>,
    pub logged: u64,
    pub recorded: Option<usize>,
    pub wall_seconds: f64,
    pub frames_in_flight: usize,
}

#[derive(Serialize)]
pub struct Runtime {
    pub name: String,
    pub version: String,
}

#[derive(Serialize)]
struct System {
    name: String,
    vendor_id: u32,
    max_swapchain_width: u32,
    max_swapchain_height: u32,
    max_layer_count: u32,
    orientation_tracking: bool,
    position_tracking: bool,
    eye_gaze_interaction: bool,
}

/// "runtime" or "headset TOML" for each figure of the headset description.
#[derive(Serialize)]
struct FigureSources {
    name: &'static str,
    recommended_size: &'static str,
    fov: &'static str,
    eye_offsets: &'static str,
    refresh_hz: &'static str,
    tracker: &'static str,
}

#[derive(Serialize)]
struct GazeAge {
    /// Over frames with live gaze: predicted display time − sample time.
    median_ms: Option<f64>,
    p99_ms: Option<f64>,
    frames: usize,
}

#[derive(Serialize)]
pub struct XrReport {
    pub runtime: Runtime,
    system: System,
    /// CLOCK_MONOTONIC − XrTime in ns (XR_KHR_convert_timespec_time), to relate the per-frame log's
    /// times to other logs; null when the runtime cannot convert.
    monotonic_minus_xr_time_ns: Option<i64>,
    headset: String,
    headset_toml: String,
    figure_sources: FigureSources,
    refresh_hz: f32,
    method: String,
    denoiser: String,
    taa: String,
    scene: String,
    eyes: &'static str,
    device: String,
    swapchain_format: String,
    /// Per eye.
    width: u32,
    height: u32,
    /// The runtime space the scene camera stands in: local | stage.
    reference_space: &'static str,
    /// Metres per scene unit (`--world-scale`).
    world_scale: f32,
    /// Frames of the loop (xrWaitFrame … xrEndFrame), rendered or not.
    frames: u64,
    frames_rendered: u32,
    frames_logged: u64,
    frames_in_flight: usize,
    gaze_source: String,
    gaze_notice: Option<String>,
    gaze_live: u32,
    gaze_held: u32,
    gaze_centre: u32,
    /// Of `gaze_centre`: frames whose gaze lay behind or outside an eye's view.
    gaze_outside_view: u32,
    gaze_age: GazeAge,
    gaze_recorded: Option<usize>,
    /// Per eye and rendered frame.
    samples_traced: u64,
    samples_offscreen: u64,
    samples_culled: u64,
    rays_traced: u64,
    /// Pass → mean GPU ms per rendered frame (both eyes' passes summed).
    passes: BTreeMap<String, f64>,
    pub frame_gpu_ms: f64,
    /// Mean host ms per rendered frame (xrWaitFrame's return to xrEndFrame's).
    cpu_ms: f64,
    fps: f64,
    wall_seconds: f64,
    /// exiting | loss_pending | instance_loss_pending.
    session_end: &'static str,
    interrupted: bool,
    seed: u32,
    max_depth: u32,
}

pub fn build(i: &Inputs) -> Result<XrReport> {
    let props =
        i.rt.instance
            .properties()
            .context("xrGetInstanceProperties")?;
    let sys =
        i.rt.instance
            .system_properties(i.rt.system)
            .context("xrGetSystemProperties")?;
    let t = i.tally;
    let r = i.render;
    let source = |from_runtime: bool| {
        if from_runtime {
            "runtime"
        } else {
            "headset TOML"
        }
    };
    let eye_frames = (t.timed as u64 * 2).max(1);
    let passes: BTreeMap<String, f64> = t
        .pass_sums
        .iter()
        .map(|(k, v)| (k.clone(), v / t.timed.max(1) as f64))
        .collect();
    Ok(XrReport {
        runtime: Runtime {
            name: props.runtime_name.clone(),
            version: props.runtime_version.to_string(),
        },
        monotonic_minus_xr_time_ns: i
            .rt
            .now()
            .ok()
            .and_then(|t| Some(i.rt.time_to_monotonic(t).ok()? - t)),
        system: System {
            name: sys.system_name.clone(),
            vendor_id: sys.vendor_id,
            max_swapchain_width: sys.graphics_properties.max_swapchain_image_width,
            max_swapchain_height: sys.graphics_properties.max_swapchain_image_height,
            max_layer_count: sys.graphics_properties.max_layer_count,
            orientation_tracking: sys.tracking_properties.orientation_tracking,
            position_tracking: sys.tracking_properties.position_tracking,
            eye_gaze_interaction: i.rt.missing_eye_tracker().is_none(),
        },
        headset: i.hmd.id.clone(),
        headset_toml: i.base.id.clone(),
        figure_sources: FigureSources {
            name: source(i.figures.name),
            recommended_size: source(i.figures.recommended_size),
            fov: source(i.figures.fov),
            eye_offsets: source(i.figures.offsets),
            refresh_hz: source(i.figures.refresh),
            tracker: "headset TOML",
        },
        refresh_hz: i.hmd.refresh_hz,
        method: r.method.to_string(),
        denoiser: i.denoiser.to_string(),
        taa: i.taa.to_string(),
        scene: r.scene.to_string(),
        eyes: "both",
        device: i.device.to_string(),
        swapchain_format: format!("{:?}", i.swapchain_format),
        width: i.eye_size.0,
        height: i.eye_size.1,
        reference_space: i.reference_space,
        world_scale: r.camera.world_scale,
        frames: t.frames,
        frames_rendered: t.rendered,
        frames_logged: i.logged,
        frames_in_flight: i.frames_in_flight,
        gaze_source: i.gaze_source.to_string(),
        gaze_notice: i.notice.map(str::to_string),
        gaze_live: t.origins[0],
        gaze_held: t.origins[1],
        gaze_centre: t.origins[2],
        gaze_outside_view: t.outside_view,
        gaze_age: gaze_age(t.live_ages_ns),
        gaze_recorded: i.recorded,
        samples_traced: t.stats.samples_traced / eye_frames,
        samples_offscreen: t.stats.samples_offscreen / eye_frames,
        samples_culled: t.stats.samples_culled / eye_frames,
        rays_traced: t.stats.rays_traced() / eye_frames,
        frame_gpu_ms: passes.values().sum(),
        passes,
        cpu_ms: t.cpu_ms / t.rendered.max(1) as f64,
        fps: t.frames as f64 / i.wall_seconds.max(1e-9),
        wall_seconds: i.wall_seconds,
        session_end: match i.end {
            SessionEnd::Exiting => "exiting",
            SessionEnd::LossPending => "loss_pending",
            SessionEnd::InstanceLossPending => "instance_loss_pending",
        },
        interrupted: crate::interrupt::requested().is_some(),
        seed: r.seed,
        max_depth: r.max_depth,
    })
}

/// Median and 99th percentile (nearest rank) in milliseconds.
fn gaze_age(ages_ns: &[i64]) -> GazeAge {
    let mut sorted = ages_ns.to_vec();
    sorted.sort_unstable();
    let rank = |q: f64| -> Option<f64> {
        if sorted.is_empty() {
            return None;
        }
        let i = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len()) - 1;
        Some(sorted[i] as f64 / 1e6)
    };
    GazeAge {
        median_ms: rank(0.5),
        p99_ms: rank(0.99),
        frames: sorted.len(),
    }
}
