//! The real-time loop part of `fovea bench`: both eyes of the Cornell box in
//! Visual-Polar space with SVGF, driven the way `fovea render --eyes both` drives them (free the
//! slot's frame, then record and submit the next), three times on one device:
//! one stereo renderer with 1 and with 2 frames in flight, and two mono renderers (one scene
//! upload each) submitting one eye each per frame; then the stereo renderer with 2 in flight and
//! cross-eye reuse (`--cross-eye-reuse on`), for the share of its passes. Per run: frames/s over the steady state,
//! per-pass GPU ms, host ms spent recording + submitting, process CPU time, submits and fence
//! waits per frame, GPU bytes. Each run is made twice, in the order A B C D D C B A, so that a drift
//! of the machine's speed (other work on a shared CPU device) hits the four alike.

use super::setup::{filters, space_for};
use crate::cpu_time::{CpuTimes, CpuUse};
use crate::render_profile::RenderProfile;
use anyhow::{bail, Context as _, Result};
use fovea_hal::{Eye, HmdDescription};
use fovea_renderer::frame::{CameraPose, CrossEyeReuse, FrameInput, RenderSettings, ViewInput};
use fovea_renderer::gpu_scene::GpuScene;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::scene::bvh::Bvh;
use fovea_renderer::scene::Scene;
use fovea_renderer::vk::{Context, EngineCounters};
use fovea_stage::projection::{EyeRig, Projection};
use glam::{Vec2, Vec3};
use serde::Serialize;
use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::Instant;

const LOOP_SCENE: &str = "cornell-box";
const METHOD: &str = "vp";
const DENOISER: &str = "svgf";
const HEADSET: &str = "fove0";
/// Frames run before the timed ones: SVGF's history fills and lavapipe's one-off costs (lazy
/// set-up, first-touch page faults, read-backs made on a slot's first use) are paid.
pub const WARMUP_FRAMES: u32 = 2;
/// The fewest timed frames: with 2 in flight the last warm-up frame is seen complete only when
/// the second timed frame is submitted.
pub const MIN_FRAMES: u32 = 2;

#[derive(Serialize)]
pub struct LoopReport {
    pub scene: String,
    /// Per eye.
    pub width: u32,
    pub height: u32,
    pub eyes: u32,
    pub method: String,
    pub denoiser: String,
    pub warmup_frames: u32,
    /// Timed frames each time a run is made (after its own warm-up frames).
    pub frames: u32,
    /// Times each run is made (order A B C D D C B A); every figure is over all of them.
    pub repeats: u32,
    pub stereo_in_flight_1: LoopRun,
    pub stereo_in_flight_2: LoopRun,
    /// Two 1-view renderers (left, right), 2 in flight each, submitted one after the other.
    pub two_mono_in_flight_2: LoopRun,
    /// frames/s with 2 in flight / with 1 (stereo).
    pub in_flight_2_vs_1_fps: f64,
    /// Stereo / two mono renders (both 2 in flight): wall ms per frame, GPU ms, GPU bytes.
    pub stereo_vs_two_mono_frame_time: f64,
    pub stereo_vs_two_mono_gpu_ms: f64,
    pub stereo_vs_two_mono_bytes: f64,
    /// The stereo renderer, 2 in flight, with cross-eye reuse.
    pub stereo_cross_eye_in_flight_2: LoopRun,
    /// Its cross-eye passes (`cross_eye`, `cross_eye_resolve`) / its GPU ms per frame.
    pub cross_eye_share: f64,
    /// GPU ms per frame with cross-eye reuse / without (both stereo, 2 in flight).
    pub cross_eye_vs_stereo_gpu_ms: f64,
}

#[derive(Serialize)]
pub struct LoopRun {
    /// Renderers = scene uploads.
    pub renderers: usize,
    pub views_per_renderer: usize,
    pub frames_in_flight: usize,
    /// Timed frames over all repeats.
    pub timed_frames: u32,
    /// Timed frames over the wall clock from the last warm-up frame's completion to the last
    /// timed frame's, as the submitting thread sees them.
    pub frames_per_second: f64,
    pub wall_ms_per_frame: f64,
    /// Pass → mean GPU ms per frame (every renderer's and eye's passes of that name summed).
    pub passes_ms: BTreeMap<String, f64>,
    pub gpu_ms_per_frame: f64,
    /// The submitting thread's wall time in `Renderer::submit` (gaze, uniforms, recording,
    /// vkQueueSubmit), without the fence wait for the slot's previous frame.
    pub host_ms_per_frame: f64,
    /// Process user + system CPU time (getrusage) over the timed interval; on a CPU device this
    /// includes the device's own threads. `null` where getrusage is not available.
    pub process_cpu_ms_per_frame: Option<f64>,
    /// CPU time of every other process on the machine over the same interval, and time the
    /// hypervisor gave to others (/proc/stat; `null` off Linux): well above 0, the run was disturbed.
    pub others_cpu_ms_per_frame: Option<f64>,
    pub steal_ms_per_frame: Option<f64>,
    pub submits_per_frame: f64,
    /// Fence waits and waits for the newest submitted frame (drains) in the timed frames' retires
    /// (a ring of 2 in the steady state waits only for older frames: no drains).
    pub fence_waits_per_frame: f64,
    pub drain_waits: u64,
    /// `Context::allocated_bytes` of the scene upload(s) and renderer(s) after the run.
    pub gpu_bytes: i64,
    /// Of which the scene upload(s).
    pub scene_bytes: i64,
}

/// One loop renderer: which eyes it renders (each its own view).
type Spec = &'static [Eye];

/// One run's renderers and their frame slots.
pub(super) struct Config {
    specs: &'static [Spec],
    in_flight: usize,
    /// `RenderSettings::cross_eye_reuse` for this run; `None`: the default profile's.
    cross_eye: Option<CrossEyeReuse>,
}

const STEREO: &[Spec] = &[&[Eye::Left, Eye::Right]];
const TWO_MONO: &[Spec] = &[&[Eye::Left], &[Eye::Right]];
/// The stereo renderer with 2 frames in flight and the default profile's settings (the headset
/// loop's one run shape).
pub(super) const STEREO_2: Config = Config {
    specs: STEREO,
    in_flight: 2,
    cross_eye: None,
};
/// The real-time loop's runs: the engine's shapes without cross-eye reuse, then with it.
const CONFIGS: [Config; 4] = [
    Config {
        specs: STEREO,
        in_flight: 1,
        cross_eye: Some(CrossEyeReuse::Off),
    },
    Config {
        specs: STEREO,
        in_flight: 2,
        cross_eye: Some(CrossEyeReuse::Off),
    },
    Config {
        specs: TWO_MONO,
        in_flight: 2,
        cross_eye: Some(CrossEyeReuse::Off),
    },
    Config {
        specs: STEREO,
        in_flight: 2,
        cross_eye: Some(CrossEyeReuse::On),
    },
];
/// Forwards, then backwards.
const ORDER: [usize; 8] = [0, 1, 2, 3, 3, 2, 1, 0];
/// The cross-eye reuse passes' names in the timings.
const CROSS_EYE_PASSES: [&str; 2] = ["cross_eye", "cross_eye_resolve"];

/// A scene with its world tree, built once for every loop run over it (each run uploads it).
pub struct LoopScene {
    pub name: String,
    scene: Scene,
    positions: Vec<[Vec3; 3]>,
    bvh: Bvh,
}

impl LoopScene {
    /// Loads `name` lit as `fovea render` lights it (the default sun and sky where the scene's
    /// own emitters do not light it) and builds its tree.
    pub fn load(name: &str) -> Result<LoopScene> {
        let mut scene = fovea_stage::scenes::load(name)?;
        if let Some(notice) = fovea_stage::look::apply_environment(
            &mut scene,
            &fovea_stage::look::EnvironmentOptions::default(),
        ) {
            println!("{notice}");
        }
        let positions = scene.flat_positions();
        let bvh = Bvh::build(&positions);
        Ok(LoopScene {
            name: name.to_string(),
            scene,
            positions,
            bvh,
        })
    }
}

/// The moving head and gaze of a run: the default orbit over the run's frames and the simulated
/// gaze (`--gaze sim:1`), each eye's gaze point per frame.
struct Motion {
    scene_centre: Vec3,
    frames: u32,
    gazes: Vec<[Vec2; 2]>,
}

/// The simulated gaze of the moving runs (as `fovea render --gaze sim:1`).
pub const MOVING_GAZE: &str = "sim:1";

/// What every run shares: the scene, the eyes' cameras and gazes, the settings.
pub(super) struct LoopSetup<'a> {
    scene: &'a LoopScene,
    hmd: HmdDescription,
    method: String,
    profile: RenderProfile,
    settings: RenderSettings,
    screen: glam::UVec2,
    head: CameraPose,
    rig: EyeRig,
    motion: Option<Motion>,
}

/// `--loop-frames` checked (before the bench's other, slower parts run).
pub fn check_frames(frames: u32) -> Result<()> {
    if frames < MIN_FRAMES {
        bail!("--loop-frames {frames}: at least {MIN_FRAMES} (frames/s is measured between frame completions)");
    }
    Ok(())
}

pub fn measure(ctx: &Arc<Context>, (width, height): (u32, u32), frames: u32) -> Result<LoopReport> {
    check_frames(frames)?;
    let scene = LoopScene::load(LOOP_SCENE)?;
    let hmd = HmdDescription::resolve(HEADSET).with_context(|| format!("headset {HEADSET}"))?;
    let setup = LoopSetup::new(&scene, hmd, (width, height), (METHOD, DENOISER), None)?;
    let mut sums: [Sums; 4] = Default::default();
    for i in ORDER {
        sums[i].add(run(ctx, &setup, &CONFIGS[i], frames)?);
    }
    let [stereo_1, stereo_2, mono_2, cross_eye_2] = sums.map(Sums::report);
    let cross_eye_ms: f64 = CROSS_EYE_PASSES
        .iter()
        .filter_map(|p| cross_eye_2.passes_ms.get(*p))
        .sum();
    let report = LoopReport {
        scene: LOOP_SCENE.to_string(),
        width,
        height,
        eyes: 2,
        method: METHOD.to_string(),
        denoiser: DENOISER.to_string(),
        warmup_frames: WARMUP_FRAMES,
        frames,
        repeats: (ORDER.len() / CONFIGS.len()) as u32,
        in_flight_2_vs_1_fps: stereo_2.frames_per_second / stereo_1.frames_per_second,
        stereo_vs_two_mono_frame_time: stereo_2.wall_ms_per_frame / mono_2.wall_ms_per_frame,
        stereo_vs_two_mono_gpu_ms: stereo_2.gpu_ms_per_frame / mono_2.gpu_ms_per_frame,
        stereo_vs_two_mono_bytes: stereo_2.gpu_bytes as f64 / mono_2.gpu_bytes as f64,
        cross_eye_share: cross_eye_ms / cross_eye_2.gpu_ms_per_frame,
        cross_eye_vs_stereo_gpu_ms: cross_eye_2.gpu_ms_per_frame / stereo_2.gpu_ms_per_frame,
        stereo_in_flight_1: stereo_1,
        stereo_in_flight_2: stereo_2,
        two_mono_in_flight_2: mono_2,
        stereo_cross_eye_in_flight_2: cross_eye_2,
    };
    print_summary(&report, &ctx.info.name);
    Ok(report)
}

impl<'a> LoopSetup<'a> {
    /// `moving`: `Some(frames)` moves the head along the default orbit and the gaze as the
    /// simulated gaze over that many frames; `None` keeps the scene camera and the centred gaze.
    pub(super) fn new(
        scene: &'a LoopScene,
        hmd: HmdDescription,
        (width, height): (u32, u32),
        (method, denoiser): (&str, &str),
        moving: Option<u32>,
    ) -> Result<LoopSetup<'a>> {
        let profile = RenderProfile::default();
        let (denoiser, taa) = filters(denoiser, "off", &profile)?;
        let settings = RenderSettings {
            blur: profile.blur,
            denoiser,
            taa,
            cross_eye_reuse: profile.cross_eye_reuse,
            ..Default::default()
        };
        let Some(camera) = scene.scene.default_camera() else {
            bail!("{}: no camera", scene.name)
        };
        let rig = EyeRig {
            projection: Projection::Headset,
            hmd: hmd.clone(),
            stereo: true,
            width,
            height,
            metres_per_unit: 1.0,
        };
        let head = rig.head(camera);
        let motion = match moving {
            None => None,
            Some(frames) => {
                let mut gaze = fovea_stage::gaze::GazeDriver::open_timed(
                    MOVING_GAZE,
                    &hmd,
                    width,
                    height,
                    &profile.gaze_timing,
                )?;
                let gazes = (0..frames)
                    .map(|f| Ok(gaze.frame(f, &[Eye::Left, Eye::Right])?.pixels))
                    .collect::<Result<_>>()?;
                Some(Motion {
                    scene_centre: scene.scene.bounds().center(),
                    frames,
                    gazes,
                })
            }
        };
        Ok(LoopSetup {
            rig,
            scene,
            hmd,
            method: method.to_string(),
            profile,
            settings,
            screen: glam::UVec2::new(width, height),
            head,
            motion,
        })
    }

    /// A renderer of `eyes` over its own scene upload, like `fovea render --eyes`, and the
    /// upload's GPU bytes.
    fn renderer(
        &self,
        ctx: &Arc<Context>,
        eyes: Spec,
        in_flight: usize,
        cross_eye: Option<CrossEyeReuse>,
    ) -> Result<(Renderer, i64)> {
        let spaces = eyes
            .iter()
            .map(|&eye| space_for(&self.method, &self.profile, &self.hmd, eye, self.screen))
            .collect::<Result<_>>()?;
        let before = ctx.allocated_bytes();
        let s = self.scene;
        let scene = GpuScene::upload_with_bvh(ctx, &s.scene, &s.positions, &s.bvh)?;
        let scene_bytes = ctx.allocated_bytes() - before;
        Ok((
            Renderer::with_views(
                ctx,
                scene,
                spaces,
                RenderSettings {
                    cross_eye_reuse: cross_eye.unwrap_or(self.settings.cross_eye_reuse),
                    ..self.settings
                },
                in_flight,
            )?,
            scene_bytes,
        ))
    }

    /// Frame `frame` of `eyes`: the head pose (still, or on the orbit) offset by each eye, the
    /// gaze at the centre or the simulated gaze.
    fn input(&self, eyes: Spec, frame: u32) -> Result<FrameInput> {
        let centre = self.screen.as_vec2() * 0.5;
        let head = match &self.motion {
            None => self.head,
            Some(m) => fovea_stage::camera_path::pose(
                &self.head,
                m.scene_centre,
                frame,
                m.frames,
                &fovea_stage::camera_path::CameraMotion::Orbit,
                self.hmd.refresh_hz,
            ),
        };
        let views: Vec<ViewInput> = eyes
            .iter()
            .map(|&eye| ViewInput {
                camera: self.rig.eye(&head, eye),
                gaze: Some(match &self.motion {
                    None => centre,
                    Some(m) => m.gazes[frame as usize][eye.index()],
                }),
            })
            .collect();
        let mut input = FrameInput::views(&views, frame)?;
        if self.motion.is_some() {
            // Frames follow each other at the headset's refresh (the orbit's clock too).
            input.frame_seconds = 1.0 / self.hmd.refresh_hz;
        }
        Ok(input)
    }
}

/// Running sums of one run's timed frames.
#[derive(Default)]
struct Tally {
    pass_ms: BTreeMap<String, f64>,
    host_seconds: f64,
    /// When the last warm-up frame was seen complete (wall clock, CPU times).
    start: Option<(Instant, CpuTimes)>,
}

impl Tally {
    fn add_timings(&mut self, renderer: &Renderer, frame: u64) -> Result<()> {
        for t in renderer.frame_timings(frame)? {
            *self.pass_ms.entry(t.name.to_string()).or_default() += t.ms;
        }
        Ok(())
    }
}

/// The engine's counters at one moment of a run.
#[derive(Clone, Copy, Default)]
struct Counts {
    submits: u64,
    fence_waits: u64,
    drains: u64,
}

impl Counts {
    fn now(ctx: &Context, renderers: &[Renderer]) -> Counts {
        Counts {
            submits: EngineCounters::get(&ctx.counters.submits),
            fence_waits: EngineCounters::get(&ctx.counters.fence_waits),
            drains: renderers.iter().map(|r| r.ring().drain_waits()).sum(),
        }
    }

    fn since(self, earlier: Counts) -> Counts {
        Counts {
            submits: self.submits - earlier.submits,
            fence_waits: self.fence_waits - earlier.fence_waits,
            drains: self.drains - earlier.drains,
        }
    }

    fn add(&mut self, other: Counts) {
        self.submits += other.submits;
        self.fence_waits += other.fence_waits;
        self.drains += other.drains;
    }
}

/// One run's sums over its timed frames, over every time it was made.
#[derive(Default)]
pub(super) struct Sums {
    renderers: usize,
    views_per_renderer: usize,
    in_flight: usize,
    frames: u32,
    wall_seconds: f64,
    cpu: CpuUse,
    pass_ms: BTreeMap<String, f64>,
    host_seconds: f64,
    counts: Counts,
    gpu_bytes: i64,
    scene_bytes: i64,
}

impl Sums {
    pub(super) fn add(&mut self, other: Sums) {
        let first = self.frames == 0;
        for (pass, ms) in other.pass_ms {
            *self.pass_ms.entry(pass).or_default() += ms;
        }
        if first {
            self.cpu = other.cpu;
        } else {
            self.cpu.add(other.cpu);
        }
        self.counts.add(other.counts);
        self.frames += other.frames;
        self.wall_seconds += other.wall_seconds;
        self.host_seconds += other.host_seconds;
        // The same renderers each time: the largest footprint seen.
        self.gpu_bytes = self.gpu_bytes.max(other.gpu_bytes);
        self.scene_bytes = self.scene_bytes.max(other.scene_bytes);
        self.renderers = other.renderers;
        self.views_per_renderer = other.views_per_renderer;
        self.in_flight = other.in_flight;
    }

    pub(super) fn report(self) -> LoopRun {
        let n = self.frames as f64;
        let passes_ms: BTreeMap<String, f64> =
            self.pass_ms.into_iter().map(|(k, v)| (k, v / n)).collect();
        LoopRun {
            renderers: self.renderers,
            views_per_renderer: self.views_per_renderer,
            frames_in_flight: self.in_flight,
            timed_frames: self.frames,
            frames_per_second: n / self.wall_seconds,
            wall_ms_per_frame: self.wall_seconds * 1e3 / n,
            gpu_ms_per_frame: passes_ms.values().sum(),
            passes_ms,
            host_ms_per_frame: self.host_seconds * 1e3 / n,
            process_cpu_ms_per_frame: self.cpu.process.map(|s| s * 1e3 / n),
            others_cpu_ms_per_frame: self.cpu.others.map(|s| s * 1e3 / n),
            steal_ms_per_frame: self.cpu.steal.map(|s| s * 1e3 / n),
            submits_per_frame: self.counts.submits as f64 / n,
            fence_waits_per_frame: self.counts.fence_waits as f64 / n,
            drain_waits: self.counts.drains,
            gpu_bytes: self.gpu_bytes,
            scene_bytes: self.scene_bytes,
        }
    }
}

/// Runs `WARMUP_FRAMES + frames` frames of `config` on fresh renderers (one scene upload each).
pub(super) fn run(
    ctx: &Arc<Context>,
    setup: &LoopSetup,
    config: &Config,
    frames: u32,
) -> Result<Sums> {
    let (specs, in_flight) = (config.specs, config.in_flight);
    let bytes_before = ctx.allocated_bytes();
    let (mut renderers, scene_bytes): (Vec<Renderer>, Vec<i64>) = specs
        .iter()
        .map(|eyes| setup.renderer(ctx, eyes, in_flight, config.cross_eye))
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .unzip();
    // Built before the loop: the timed frames make no inputs.
    let inputs = (0..WARMUP_FRAMES + frames)
        .map(|f| {
            specs
                .iter()
                .map(|eyes| setup.input(eyes, f))
                .collect::<Result<Vec<_>>>()
        })
        .collect::<Result<Vec<_>>>()?;
    let mut tally = Tally::default();
    let mut counts_before = Counts::default();
    for (f, frame_inputs) in inputs.iter().enumerate() {
        if f as u32 == WARMUP_FRAMES {
            counts_before = Counts::now(ctx, &renderers);
        }
        run_frame(
            &mut tally,
            &mut renderers,
            frame_inputs,
            f as u32 >= WARMUP_FRAMES,
        )?;
    }
    // Over the timed frames' retires and submits, before `finish` drains the ring.
    let counts = Counts::now(ctx, &renderers).since(counts_before);
    for renderer in &mut renderers {
        renderer.finish()?;
    }
    let (end, end_cpu) = (Instant::now(), CpuTimes::now());
    let total = (WARMUP_FRAMES + frames) as u64;
    for renderer in &renderers {
        // The frames still in flight at the loop's end (those before were read when retired).
        for done in total
            .saturating_sub(in_flight as u64)
            .max(WARMUP_FRAMES as u64)..total
        {
            tally.add_timings(renderer, done)?;
        }
    }
    let Some((start, start_cpu)) = tally.start else {
        bail!("the last warm-up frame was never retired")
    };
    Ok(Sums {
        renderers: renderers.len(),
        views_per_renderer: specs[0].len(),
        in_flight,
        frames,
        wall_seconds: (end - start).as_secs_f64(),
        cpu: end_cpu.since(start_cpu),
        pass_ms: tally.pass_ms,
        host_seconds: tally.host_seconds,
        counts,
        gpu_bytes: ctx.allocated_bytes() - bytes_before,
        scene_bytes: scene_bytes.iter().sum(),
    })
}

/// One loop frame: each renderer frees its next slot (the fence wait, outside the host time),
/// then records and submits its frame.
fn run_frame(
    tally: &mut Tally,
    renderers: &mut [Renderer],
    inputs: &[FrameInput],
    timed: bool,
) -> Result<()> {
    let last = renderers.len() - 1;
    for (i, (renderer, input)) in renderers.iter_mut().zip(inputs).enumerate() {
        if let Some(done) = renderer.retire_next()? {
            collect(tally, renderer, done, i == last)?;
        }
        let started = Instant::now();
        renderer.submit(input, None)?;
        if timed {
            tally.host_seconds += started.elapsed().as_secs_f64();
        }
    }
    Ok(())
}

/// A frame just retired: its timings if timed; the start of the timed interval once the last
/// renderer's last warm-up frame is done (one queue: every earlier submission is done too).
fn collect(tally: &mut Tally, renderer: &Renderer, done: u64, last_renderer: bool) -> Result<()> {
    if done >= WARMUP_FRAMES as u64 {
        tally.add_timings(renderer, done)?;
    } else if done + 1 == WARMUP_FRAMES as u64 && last_renderer {
        tally.start = Some((Instant::now(), CpuTimes::now()));
    }
    Ok(())
}

/// The loop figures as a Markdown table (ready for docs/performance.md) and the ratios.
fn print_summary(r: &LoopReport, device: &str) {
    println!(
        "loop {} 2 × {}×{} ({} + {}; each run {} × {} timed frames after {} warm-up, order A B C D D C B A) on {device}:",
        r.scene, r.width, r.height, r.method, r.denoiser, r.repeats, r.frames, r.warmup_frames
    );
    println!("| run | frames in flight | scene uploads | submits/frame | frames/s | wall ms/frame | GPU ms/frame | host ms/frame | process CPU ms/frame | others' CPU ms/frame | GPU MiB |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let runs = [
        ("stereo (1 renderer, 2 views)", &r.stereo_in_flight_1),
        ("stereo (1 renderer, 2 views)", &r.stereo_in_flight_2),
        ("2 × mono (2 renderers)", &r.two_mono_in_flight_2),
        (
            "stereo, cross-eye reuse (1 renderer)",
            &r.stereo_cross_eye_in_flight_2,
        ),
    ];
    let ms = |v: Option<f64>| v.map_or("n/a".to_string(), |ms| format!("{ms:.0}"));
    for (name, run) in runs {
        println!(
            "| {name} | {} | {} | {:.0} | {:.2} | {:.1} | {:.1} | {:.2} | {} | {} | {:.1} |",
            run.frames_in_flight,
            run.renderers,
            run.submits_per_frame,
            run.frames_per_second,
            run.wall_ms_per_frame,
            run.gpu_ms_per_frame,
            run.host_ms_per_frame,
            ms(run.process_cpu_ms_per_frame),
            ms(run.others_cpu_ms_per_frame),
            run.gpu_bytes as f64 / (1 << 20) as f64,
        );
    }
    println!(
        "2 vs 1 in flight: {:.3}× frames/s; stereo / (2 × mono): frame time {:.3}, GPU ms {:.3}, GPU bytes {:.3}",
        r.in_flight_2_vs_1_fps, r.stereo_vs_two_mono_frame_time, r.stereo_vs_two_mono_gpu_ms, r.stereo_vs_two_mono_bytes
    );
    println!(
        "cross-eye reuse: its passes {:.1} % of the stereo frame; GPU ms {:.3}× the stereo frame without it",
        100.0 * r.cross_eye_share,
        r.cross_eye_vs_stereo_gpu_ms
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A moving setup swings the head along the orbit from the still pose, gives each eye the
    /// simulated gaze of that frame and spaces frames by the headset's refresh; a still one keeps
    /// the head and the centred gaze.
    #[test]
    fn moving_runs_follow_the_orbit_and_the_simulated_gaze() {
        let scene = LoopScene::load(LOOP_SCENE).unwrap();
        let hmd = HmdDescription::resolve("psvr2").unwrap();
        let (size, frames) = ((96, 108), 180);
        let moving =
            LoopSetup::new(&scene, hmd.clone(), size, (METHOD, DENOISER), Some(frames)).unwrap();
        let still = LoopSetup::new(&scene, hmd.clone(), size, (METHOD, DENOISER), None).unwrap();
        let mut gaze = fovea_stage::gaze::GazeDriver::open_timed(
            MOVING_GAZE,
            &hmd,
            size.0,
            size.1,
            &RenderProfile::default().gaze_timing,
        )
        .unwrap();
        let centre = Vec2::new(48.0, 54.0);
        let still_views = still.input(STEREO[0], 0).unwrap().view_inputs().to_vec();
        let mut gazes_seen = Vec::new();
        for f in 0..frames {
            let input = moving.input(STEREO[0], f).unwrap();
            assert_eq!(input.frame_seconds, 1.0 / hmd.refresh_hz);
            let expected = gaze.frame(f, &[Eye::Left, Eye::Right]).unwrap().pixels;
            for (i, view) in input.view_inputs().iter().enumerate() {
                assert_eq!(view.gaze, Some(expected[i]), "frame {f}, view {i}");
                // Phase 0 of the swing is the still pose; a quarter of the run later it is 8° off.
                let forward = |c: &CameraPose| c.world_from_view.z_axis.truncate().normalize();
                let degrees = forward(&view.camera)
                    .angle_between(forward(&still_views[i].camera))
                    .to_degrees();
                if f == 0 {
                    assert_eq!(view.camera, still_views[i].camera, "view {i}");
                } else if f == frames / 4 {
                    assert!((degrees - 8.0).abs() < 1e-2, "view {i}: {degrees}°");
                }
            }
            gazes_seen.push(expected[0]);
            let s = still.input(STEREO[0], f).unwrap();
            assert!(s.view_inputs().iter().all(|v| v.gaze == Some(centre)));
            assert_eq!(s.view_inputs()[0].camera, still_views[0].camera);
        }
        assert!(
            gazes_seen.iter().any(|g| *g != gazes_seen[0]),
            "the simulated gaze never moved in {frames} frames"
        );
    }
}
