//! `fovea xr`: both eyes on a headset through any OpenXR runtime with Vulkan. Per frame:
//! xrWaitFrame → the predicted display time → xrLocateViews (each eye's pose and FOV) → the gaze
//! at that time → both eyes rendered by the real-time engine, in one submit, into the acquired
//! swapchain image (side by side) → xrEndFrame with one projection layer. Writes
//! `DIR/frames.jsonl` (one row per frame) and `DIR/report.json`.

use super::flags::DeviceArgs;
use super::render::RenderArgs;
use super::render_args::{RenderDefaults, RenderOpts};
use super::setup::{check_common, filters_for_method, render_settings, scaled_eye_size, space_for};
use crate::output::{prepare_output_dir, write_json};
use crate::xr::frame_log::{FrameLog, FrameRow, GazeRow, ViewRow};
use crate::xr::gaze::{Timebase, XrFrameGaze, XrGaze};
use crate::xr::vulkan::{binding, open_context, XrSwapchain};
use anyhow::{bail, Context as _, Result};
use ash::vk;
use fovea_hal::openxr::{
    xr, GazeActions, OpenXrGaze, OpenXrRuntime, RuntimeFigures, SessionEnd, SessionOwner,
};
use fovea_hal::{Eye, GazeOrigin, HmdDescription};
use fovea_renderer::frame::{
    CameraPose, FrameInput, FrameStats, FrameTarget, RenderSettings, ViewInput, MAX_VIEWS,
};
use fovea_renderer::gpu_scene::GpuScene;
use fovea_renderer::graph::SubmitSync;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::vk::{Buffer, Context};
use fovea_stage::gaze::GazeDriver;
use glam::{Mat4, Quat, UVec2, Vec3, Vec4};
use gpu_allocator::MemoryLocation;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

pub struct XrArgs<'a> {
    /// Scene, method, filters, headset TOML (figures the runtime does not report), scale, seed,
    /// profile, frames in flight, output folder, validation.
    pub render: RenderArgs<'a>,
    /// Rendered frames before a clean session end; `None`: until the runtime or a signal ends it.
    pub frames: Option<u32>,
    /// `None`: the runtime's eye tracker when it has one, else the view centre.
    pub gaze: Option<&'a str>,
    pub record: Option<&'a Path>,
    pub screenshot: Option<&'a Path>,
    /// `--force`: the screenshot may replace an existing file.
    pub force: bool,
    /// The runtime space the scene camera is placed in (`--reference-space`).
    pub reference_space: ReferenceSpace,
}

/// Where the scene meets the runtime's tracking space (`--reference-space`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ReferenceSpace {
    /// LOCAL: the origin is the head where the session started; the scene camera stands there.
    #[default]
    Local,
    /// STAGE: the origin is on the floor of the play area; the scene camera's point on the
    /// ground (y = 0) stands there, so the scene's floor is the room's floor.
    Stage,
}

impl ReferenceSpace {
    pub const NAMES: &'static [&'static str] = &["local", "stage"];

    pub fn parse(name: &str) -> Result<ReferenceSpace> {
        match name {
            "local" => Ok(ReferenceSpace::Local),
            "stage" => Ok(ReferenceSpace::Stage),
            other => bail!(
                "--reference-space {other}: expected one of {}",
                ReferenceSpace::NAMES.join(", ")
            ),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            ReferenceSpace::Local => "local",
            ReferenceSpace::Stage => "stage",
        }
    }

    fn openxr(self) -> xr::ReferenceSpaceType {
        match self {
            ReferenceSpace::Local => xr::ReferenceSpaceType::LOCAL,
            ReferenceSpace::Stage => xr::ReferenceSpaceType::STAGE,
        }
    }
}

/// World (scene units) from the runtime's tracking space: the scene camera's position (STAGE: its
/// point on the ground) and heading, but not its pitch or roll — the runtime's spaces are
/// gravity-aligned, and a tilted world would tilt under the viewer's feet. Positions the runtime
/// gives in metres become scene units through `metres_per_unit` (`--world-scale`).
pub fn world_from_tracking(camera: Mat4, space: ReferenceSpace) -> Mat4 {
    let position = camera.w_axis.truncate();
    let forward = camera.transform_vector3(Vec3::NEG_Z);
    // The heading: −Z turned toward the camera's forward projected on the ground (looking
    // straight up or down keeps −Z).
    let yaw = if forward.x.abs() + forward.z.abs() > 1e-6 {
        (-forward.x).atan2(-forward.z)
    } else {
        0.0
    };
    let origin = match space {
        ReferenceSpace::Local => position,
        ReferenceSpace::Stage => Vec3::new(position.x, 0.0, position.z),
    };
    Mat4::from_rotation_translation(Quat::from_rotation_y(yaw), origin)
}

/// The session, the engine on the runtime's device, and what one frame needs.
struct XrRun<'a> {
    args: &'a XrArgs<'a>,
    ctx: Arc<Context>,
    owner: SessionOwner<xr::Vulkan>,
    local: xr::Space,
    view_space: xr::Space,
    swapchain: XrSwapchain,
    renderer: Renderer,
    gaze: XrGaze,
    /// World from the runtime's tracking space (`world_from_tracking`).
    world_from_local: Mat4,
    /// Metres per scene unit (`--world-scale`).
    metres_per_unit: f32,
    log: FrameLog,
    screenshot: Option<Buffer>,
    tally: Tally,
}

/// Sums over the run for report.json.
#[derive(Default)]
struct Tally {
    frames: u64,
    rendered: u32,
    origins: [u32; 3],
    /// Frames foveated at the centre because the gaze lay behind or outside an eye's view.
    outside_view: u32,
    live_ages_ns: Vec<i64>,
    pass_sums: BTreeMap<String, f64>,
    stats: FrameStats,
    cpu_ms: f64,
    /// Rendered frames whose GPU times were read (all, once the ring is drained).
    timed: u32,
}

pub fn run(args: &XrArgs) -> Result<()> {
    let r = &args.render;
    if r.width.is_some() || r.height.is_some() {
        bail!("fovea xr: the size is the runtime's recommended one × --scale; --width/--height do not apply");
    }
    if r.camera_path.moves() || r.exr || r.debug_views {
        bail!("fovea xr: --camera-path, --exr and --debug-views do not apply (the headset moves the camera; frames go to the runtime)");
    }
    if args.screenshot.is_some() && args.frames.is_none() {
        bail!("--screenshot needs --frames N (the screenshot is of the last rendered frame)");
    }
    if let Some(path) = args.screenshot {
        crate::output::check_new_file(path, args.force)
            .with_context(|| format!("--screenshot {}", path.display()))?;
    }
    if args.frames == Some(0) {
        bail!("--frames must be at least 1");
    }
    check_common(r)?;
    let base =
        HmdDescription::resolve(r.headset).with_context(|| format!("--headset {}", r.headset))?;
    let (denoiser, taa) = filters_for_method(r.denoiser, r.taa, r.method, &r.profile, &base)?;
    // The runtime's views are known only later; the profile's frustums frame the scene.
    let (yfov, aspect) = fovea_stage::projection::inscribed_view(&base);
    let framing = fovea_stage::look::Framing {
        yfov: Some(yfov),
        aspect,
    };
    let (scene, camera) =
        fovea_stage::look::load(r.scene, r.camera, &r.profile.environment, framing)?;
    let camera = &camera;
    let out_dir = prepare_output_dir(r.out)?;
    let rt = Arc::new(
        OpenXrRuntime::create("fovea")
            .context("fovea xr needs an OpenXR runtime (see docs/guide/xr.md)")?,
    );
    let ctx = open_context(&rt, super::device_options(r.device, r.validation))?;
    let settings = render_settings(r, denoiser, taa);
    let started = Instant::now();
    let (mut run, session) = XrRun::start(
        args,
        &rt,
        ctx,
        &base,
        &scene,
        world_from_tracking(camera.world_from_view, args.reference_space),
        settings,
    )?;
    let end = run.frame_loop()?;
    run.finish(&rt, &base, &session, end, started)?;
    out_dir.remove_stale()?;
    match crate::interrupt::requested() {
        Some(interrupted) => Err(interrupted.into()),
        None => Ok(()),
    }
}

/// What report.json says about the session beside the run's figures.
struct SessionFacts {
    hmd: HmdDescription,
    figures: RuntimeFigures,
    gaze_source: String,
    notice: Option<String>,
}

impl<'a> XrRun<'a> {
    fn start(
        args: &'a XrArgs<'a>,
        rt: &Arc<OpenXrRuntime>,
        ctx: Arc<Context>,
        base: &HmdDescription,
        scene: &fovea_renderer::scene::Scene,
        world_from_local: Mat4,
        settings: RenderSettings,
    ) -> Result<(XrRun<'a>, SessionFacts)> {
        let r = &args.render;
        // SAFETY: the handles are the context's, which outlives the session (dropped after it).
        let mut owner = unsafe { SessionOwner::vulkan(rt, binding(&ctx)) }?;
        // Without --gaze the runtime's eye gaze drives the fovea; a runtime without an eye tracker
        // gives no gaze, so the invalid-gaze policy keeps the fovea at the view centre.
        let use_runtime_gaze = matches!(args.gaze, None | Some("openxr"));
        let mut notice = None;
        if let Some(why) = rt.missing_eye_tracker().filter(|_| use_runtime_gaze) {
            if args.gaze.is_some() {
                bail!("--gaze openxr: {why}");
            }
            let line = format!("fovea xr: no eye tracker ({why}); foveating at the view centre");
            eprintln!("{line}");
            notice = Some(line);
        }
        let (hmd, figures, source) = if use_runtime_gaze {
            let actions = GazeActions::new(rt)?;
            owner.attach_action_sets(&actions.action_set().into_iter().collect::<Vec<_>>())?;
            let gaze = OpenXrGaze::new(rt, &owner, actions, base)?;
            let (hmd, figures) = (
                fovea_hal::GazeSource::describe(&gaze).clone(),
                gaze.runtime_figures(),
            );
            (hmd, figures, Some(gaze))
        } else {
            let (hmd, figures) = owner.describe(base, false)?;
            (hmd, figures, None)
        };
        let eye_size = scaled_eye_size(hmd.eye(Eye::Left), r.scale);
        let timing = &r.profile.gaze_timing;
        let (driver, timebase, gaze_source) = match source {
            Some(gaze) => {
                if timing.latency_ms.is_some() || timing.tracker_hz.is_some() {
                    bail!("--latency-ms and --tracker-hz model the latency of recorded or simulated gaze; the runtime's eye tracker has its own (--gaze-predict applies)");
                }
                let driver = GazeDriver::from_source(Box::new(gaze), &hmd, eye_size.0, eye_size.1);
                let driver = match timing.predict {
                    Some(mode) => driver.with_live_prediction(mode),
                    None => driver,
                };
                (driver, Timebase::Runtime, "openxr".to_string())
            }
            None => {
                let spec = args.gaze.unwrap_or("center");
                (
                    GazeDriver::open_timed(spec, &hmd, eye_size.0, eye_size.1, timing)?,
                    Timebase::FromFirstFrame,
                    spec.to_string(),
                )
            }
        };
        let gaze = XrGaze::new(driver, timebase, base, args.record)?;
        let offered = owner
            .session()
            .enumerate_reference_spaces()
            .context("xrEnumerateReferenceSpaces")?;
        let wanted = args.reference_space.openxr();
        if !offered.contains(&wanted) {
            bail!(
                "--reference-space {}: the runtime offers only {offered:?}",
                args.reference_space.name()
            );
        }
        let local = owner.create_reference_space(wanted)?;
        let view_space = owner.create_reference_space(xr::ReferenceSpaceType::VIEW)?;
        let swapchain = XrSwapchain::new(&ctx, &owner, eye_size.0, eye_size.1)?;
        eprintln!(
            "fovea xr: {} — 2 × {}×{} in one {:?} swapchain, {} Hz",
            hmd.display_name, eye_size.0, eye_size.1, swapchain.format, hmd.refresh_hz
        );
        let screen = UVec2::new(eye_size.0, eye_size.1);
        let spaces = [Eye::Left, Eye::Right]
            .iter()
            .map(|&e| space_for(r.method, &r.profile, &hmd, e, screen))
            .collect::<Result<Vec<_>>>()?;
        let renderer = Renderer::with_views(
            &ctx,
            GpuScene::upload(&ctx, scene)?,
            spaces,
            settings,
            super::setup::frames_in_flight(r.frames_in_flight, args.frames.unwrap_or(u32::MAX)),
        )?;
        let screenshot = match args.screenshot {
            Some(_) => Some(Buffer::new(
                &ctx,
                "xr screenshot",
                swapchain.images[0].bytes(),
                vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )?),
            None => None,
        };
        let log = FrameLog::create(&r.out.join("frames.jsonl"))?;
        let run = XrRun {
            args,
            ctx,
            owner,
            local,
            view_space,
            swapchain,
            renderer,
            gaze,
            world_from_local,
            metres_per_unit: r.camera.world_scale,
            log,
            screenshot,
            tally: Tally::default(),
        };
        Ok((
            run,
            SessionFacts {
                hmd,
                figures,
                gaze_source,
                notice,
            },
        ))
    }

    /// Runs frames until the session ends; returns why it ended.
    fn frame_loop(&mut self) -> Result<SessionEnd> {
        let exit = self.owner.exit_handle();
        crate::interrupt::running(); // a signal from here on ends the session cleanly
        loop {
            let done = self.args.frames.is_some_and(|n| self.tally.rendered >= n);
            if done || crate::interrupt::requested().is_some() {
                exit.request(); // the owner sends xrRequestExitSession once and ends on STOPPING
            }
            let status = self.owner.poll_events()?;
            if let Some(end) = status.end {
                return Ok(end);
            }
            if !status.running {
                std::thread::sleep(Duration::from_millis(5));
                continue;
            }
            let state = self.owner.wait_frame()?;
            let host = Instant::now();
            self.owner.begin_frame()?;
            let t = state.predicted_display_time.as_nanos();
            let render = state.should_render && !exit.requested();
            let rendered = if render { self.render_frame(t)? } else { None };
            let (mut row, engine_frame) = match rendered {
                Some((row, frame)) => (row, Some(frame)),
                None => {
                    self.owner.end_frame(t, &[])?;
                    (FrameRow::not_rendered(t, state.should_render), None)
                }
            };
            row.frame = self.tally.frames;
            row.predicted_display_period_ns = state.predicted_display_period.as_nanos();
            row.cpu_ms = host.elapsed().as_secs_f64() * 1e3;
            self.tally.frames += 1;
            if engine_frame.is_some() {
                self.tally.cpu_ms += row.cpu_ms;
            }
            self.log.push(row, engine_frame)?;
        }
    }

    /// One rendered frame: views, gaze, both eyes into the acquired image, the projection layer.
    /// `None` when the runtime has no valid views for this time (ended without layers).
    fn render_frame(&mut self, t: i64) -> Result<Option<(FrameRow, u64)>> {
        let (flags, views) = self.owner.locate_views(t, &self.local)?;
        let (head_flags, eyes_in_head) = self.owner.locate_views(t, &self.view_space)?;
        let valid = |f: xr::ViewStateFlags| f.contains(xr::ViewStateFlags::ORIENTATION_VALID);
        if !valid(flags) || !valid(head_flags) || views.len() != 2 || eyes_in_head.len() != 2 {
            return Ok(None); // no pose to render with: ended without layers by the caller
        }
        // One xrSyncActions per frame for every attached set, before the gaze source reads.
        self.owner.sync_actions()?;
        let eye_size = (self.swapchain.eye_width, self.swapchain.height);
        let gaze = self
            .gaze
            .frame(t, self.tally.rendered, &eyes_in_head, eye_size)?;
        self.count_gaze(&gaze);
        let mut inputs = [ViewInput {
            camera: self.camera(&views[0]),
            gaze: None,
        }; MAX_VIEWS];
        for (i, view) in views.iter().enumerate() {
            inputs[i] = ViewInput {
                camera: self.camera(view),
                gaze: Some(gaze.pixels[i]),
            };
        }
        let input = FrameInput::views(&inputs, self.tally.rendered)?;
        let index = self
            .swapchain
            .handle
            .acquire_image()
            .context("xrAcquireSwapchainImage")? as usize;
        self.swapchain
            .handle
            .wait_image(xr::Duration::INFINITE)
            .context("xrWaitSwapchainImage")?;
        // The slot this frame takes held frame − frames in flight: read its GPU times first.
        if let Some(done) = self.renderer.retire_next()? {
            self.read_finished(done)?;
        }
        let last = self
            .args
            .frames
            .is_some_and(|n| self.tally.rendered + 1 == n);
        let mut offsets = [UVec2::ZERO; MAX_VIEWS];
        offsets[1] = UVec2::new(self.swapchain.eye_width, 0);
        let target = FrameTarget {
            image: &self.swapchain.images[index],
            offsets,
            sync: SubmitSync::default(),
            copy_to: if last { self.screenshot.as_ref() } else { None },
        };
        // Submitted before the release: the runtime waits for the queue's work on the image.
        let engine_frame = self.renderer.submit(&input, Some(&target))?;
        self.swapchain
            .handle
            .release_image()
            .context("xrReleaseSwapchainImage")?;
        self.end_with_layer(t, &views)?;
        self.tally.rendered += 1;
        let row = FrameRow {
            frame: 0,
            predicted_display_time_ns: t,
            predicted_display_period_ns: 0,
            should_render: true,
            rendered: true,
            views: vec![
                ViewRow::new("left", &views[0]),
                ViewRow::new("right", &views[1]),
            ],
            gaze: Some(gaze_row(&gaze)),
            gpu_ms: None,
            cpu_ms: 0.0,
        };
        Ok(Some((row, engine_frame)))
    }

    fn end_with_layer(&mut self, t: i64, views: &[xr::View]) -> Result<()> {
        let (w, h) = (
            self.swapchain.eye_width as i32,
            self.swapchain.height as i32,
        );
        let projection: Vec<_> = views
            .iter()
            .enumerate()
            .map(|(i, v)| {
                let rect = xr::Rect2Di {
                    offset: xr::Offset2Di {
                        x: i as i32 * w,
                        y: 0,
                    },
                    extent: xr::Extent2Di {
                        width: w,
                        height: h,
                    },
                };
                xr::CompositionLayerProjectionView::new()
                    .pose(v.pose)
                    .fov(v.fov)
                    .sub_image(
                        xr::SwapchainSubImage::new()
                            .swapchain(&self.swapchain.handle)
                            .image_rect(rect),
                    )
            })
            .collect();
        let layer = xr::CompositionLayerProjection::new()
            .space(&self.local)
            .views(&projection);
        self.owner.end_frame(t, &[&layer])?;
        Ok(())
    }

    /// An eye's camera: its located pose (the tracking space) placed at the scene camera, its FOV.
    fn camera(&self, view: &xr::View) -> CameraPose {
        let (p, o, f) = (view.pose.position, view.pose.orientation, view.fov);
        let local_from_eye = Mat4::from_rotation_translation(
            Quat::from_xyzw(o.x, o.y, o.z, o.w).normalize(),
            Vec3::new(p.x, p.y, p.z) / self.metres_per_unit,
        );
        CameraPose {
            world_from_view: self.world_from_local * local_from_eye,
            fov_tan: Vec4::new(
                f.angle_left.tan(),
                f.angle_right.tan(),
                f.angle_down.tan(),
                f.angle_up.tan(),
            ),
        }
    }

    fn count_gaze(&mut self, gaze: &XrFrameGaze) {
        self.tally.origins[origin_index(gaze.origin)] += 1;
        self.tally.outside_view += u32::from(gaze.reason.is_some());
        if gaze.origin == GazeOrigin::Live {
            self.tally.live_ages_ns.push(gaze.age_ns);
        }
    }

    /// GPU times and counts of a completed engine frame into the log and the tally.
    fn read_finished(&mut self, frame: u64) -> Result<()> {
        let mut per_eye = [0.0; 2];
        for t in self.renderer.frame_timings(frame)? {
            per_eye[(t.view as usize).min(1)] += t.ms;
            *self.tally.pass_sums.entry(t.name.to_string()).or_default() += t.ms;
        }
        for view in 0..2 {
            let s = self.renderer.frame_stats(frame, view)?;
            let total = &mut self.tally.stats;
            total.samples_traced += s.samples_traced;
            total.samples_offscreen += s.samples_offscreen;
            total.samples_culled += s.samples_culled;
            total.primary_rays += s.primary_rays;
            total.shadow_rays += s.shadow_rays;
            total.continuation_rays += s.continuation_rays;
        }
        self.tally.timed += 1;
        self.log.complete(frame, per_eye)
    }

    /// Drains the ring, writes the log, the screenshot, the recording and report.json.
    fn finish(
        mut self,
        rt: &OpenXrRuntime,
        base: &HmdDescription,
        facts: &SessionFacts,
        end: SessionEnd,
        started: Instant,
    ) -> Result<()> {
        self.renderer.finish()?;
        let submitted = self.renderer.ring().next_frame();
        let in_flight = self.renderer.frames_in_flight() as u64;
        for frame in submitted.saturating_sub(in_flight)..submitted {
            self.read_finished(frame)?;
        }
        self.save_screenshot()?;
        super::check_validation(&self.ctx)?;
        let (denoiser, taa) = (
            self.renderer.settings.denoiser.name(),
            self.renderer.settings.taa.name(),
        );
        let XrRun {
            args,
            log,
            gaze,
            tally,
            swapchain,
            ctx,
            ..
        } = self;
        let logged = log.commit()?;
        let recorded = gaze.finish()?;
        let report = super::xr_report::build(&super::xr_report::Inputs {
            render: &args.render,
            reference_space: args.reference_space.name(),
            denoiser,
            taa,
            rt,
            base,
            hmd: &facts.hmd,
            figures: facts.figures,
            gaze_source: &facts.gaze_source,
            notice: facts.notice.as_deref(),
            device: &ctx.info.name,
            swapchain_format: swapchain.format,
            eye_size: (swapchain.eye_width, swapchain.height),
            end,
            tally: &super::xr_report::Tally {
                frames: tally.frames,
                rendered: tally.rendered,
                timed: tally.timed,
                origins: tally.origins,
                outside_view: tally.outside_view,
                live_ages_ns: &tally.live_ages_ns,
                pass_sums: &tally.pass_sums,
                stats: tally.stats,
                cpu_ms: tally.cpu_ms,
            },
            logged,
            recorded,
            wall_seconds: started.elapsed().as_secs_f64(),
            frames_in_flight: in_flight as usize,
        })?;
        write_json(&args.render.out.join("report.json"), &report)?;
        println!(
            "fovea xr: {} frame(s), {} rendered (2 × {}×{}) on {} via {}: {:.1} ms GPU per frame, gaze {} → {}",
            tally.frames,
            tally.rendered,
            swapchain.eye_width,
            swapchain.height,
            ctx.info.name,
            report.runtime.name,
            report.frame_gpu_ms,
            facts.gaze_source,
            args.render.out.display()
        );
        drop(swapchain);
        Ok(())
    }

    fn save_screenshot(&self) -> Result<()> {
        let (Some(path), Some(buffer)) = (self.args.screenshot, &self.screenshot) else {
            return Ok(());
        };
        let mut pixels = vec![0u8; buffer.size as usize];
        buffer.read_into(&mut pixels)?;
        if self.swapchain.format == vk::Format::B8G8R8A8_UNORM {
            pixels.chunks_exact_mut(4).for_each(|p| p.swap(0, 2));
        }
        let (w, h) = (self.swapchain.eye_width * 2, self.swapchain.height);
        crate::output::write_png(path, w, h, &pixels)
            .with_context(|| format!("--screenshot {}", path.display()))
    }
}

fn origin_index(origin: GazeOrigin) -> usize {
    match origin {
        GazeOrigin::Live => 0,
        GazeOrigin::Held => 1,
        GazeOrigin::Centre => 2,
    }
}

fn gaze_row(g: &XrFrameGaze) -> GazeRow {
    GazeRow {
        sample_time_ns: g.sample_time_ns,
        direction: g.direction.to_array(),
        origin: g.origin.name(),
        age_ns: g.age_ns,
        pixels: [g.pixels[0].to_array(), g.pixels[1].to_array()],
        reason: g.reason,
        latency: g.latency,
    }
}

#[cfg(test)]
mod placement_tests {
    use super::*;

    #[test]
    fn the_tracking_space_keeps_the_cameras_place_and_heading_but_not_its_tilt() {
        // A camera at (1, 2, 3) turned 90° to the left (looking down −X), then pitched 30° down.
        let camera = Mat4::from_rotation_translation(
            Quat::from_rotation_y(90f32.to_radians()) * Quat::from_rotation_x(-30f32.to_radians()),
            Vec3::new(1.0, 2.0, 3.0),
        );
        let local = world_from_tracking(camera, ReferenceSpace::Local);
        assert!((local.w_axis.truncate() - Vec3::new(1.0, 2.0, 3.0)).length() < 1e-6);
        let forward = local.transform_vector3(Vec3::NEG_Z);
        assert!((forward - Vec3::NEG_X).length() < 1e-5, "{forward}");
        assert!((local.transform_vector3(Vec3::Y) - Vec3::Y).length() < 1e-6);
        let stage = world_from_tracking(camera, ReferenceSpace::Stage);
        assert!((stage.w_axis.truncate() - Vec3::new(1.0, 0.0, 3.0)).length() < 1e-6);
        // Looking straight down: no heading to keep, no NaN.
        let down = Mat4::from_rotation_x(-90f32.to_radians());
        assert!(world_from_tracking(down, ReferenceSpace::Local).is_finite());
        assert_eq!(
            ReferenceSpace::parse("stage").unwrap(),
            ReferenceSpace::Stage
        );
        assert!(ReferenceSpace::parse("floor")
            .unwrap_err()
            .to_string()
            .contains("local, stage"));
    }
}

// `fovea xr` (its help is the variant's in `crate::cli::Command`).
#[derive(clap::Args)]
pub struct XrCommand {
    #[command(flatten)]
    pub opts: Box<RenderOpts>,
    /// Write the gaze that drove the OpenXR session as a trace (a new file), replayable with
    /// `fovea render --headset <same> --gaze TRACE.csv`.
    #[arg(long)]
    pub record: Option<PathBuf>,
    /// Save the last rendered frame as submitted (both eyes side by side) as PNG; needs
    /// --frames. An existing file is replaced only with --force.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// Let --screenshot replace an existing file.
    #[arg(long)]
    pub force: bool,
    /// The runtime space the scene camera stands in: local (the default: where the head was
    /// when the OpenXR session started) or stage (the play area's floor is the scene's y = 0).
    #[arg(long, default_value = "local")]
    pub reference_space: String,
    #[command(flatten)]
    pub device: DeviceArgs,
}

impl XrCommand {
    pub fn run(self) -> Result<()> {
        self.device.choose_traversal()?;
        let camera = self.opts.look.camera()?;
        // The `frames` of RenderArgs is unused: xr ends after --frames rendered frames or when the
        // OpenXR session ends.
        let render = self.opts.args(
            &camera,
            &self.device,
            RenderDefaults {
                frames: u32::MAX,
                gaze: "center",
                out: "out/xr",
                scale: 1.0,
            },
        )?;
        if self.opts.eyes != "left" && self.opts.eyes != "both" {
            bail!(
                "fovea xr renders both eyes; --eyes {} does not apply",
                self.opts.eyes
            );
        }
        run(&XrArgs {
            render,
            frames: self.opts.frames,
            gaze: self.opts.gaze.as_deref(),
            record: self.record.as_deref(),
            screenshot: self.screenshot.as_deref(),
            force: self.force,
            reference_space: ReferenceSpace::parse(&self.reference_space)?,
        })
    }
}
