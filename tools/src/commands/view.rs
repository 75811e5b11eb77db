//! `fovea view`: the real-time engine in a desktop window (winit + VK_KHR_swapchain). One eye or
//! both side by side, written by the engine's last pass straight into the swapchain image; gaze
//! from the mouse (or any `--gaze` source); a free camera (W A S D move, Space and C rise and
//! sink, Shift runs, dragging with the right button turns the head); keys switch method, denoiser
//! and TAA live and freeze the gaze; fps and GPU ms in the title, with a refused switch named
//! there. `--frames N --screenshot FILE` renders frames 0…N−1 exactly as `fovea render` does and
//! saves the last presented image.

use super::flags::DeviceArgs;
use super::render::RenderArgs;
use super::render_args::{RenderDefaults, RenderOpts, DEFAULT_SCALE};
use super::setup::{method_names, space_for, Eyes, Setup};
use crate::viewer::debug::{compose, DebugView, StereoScene};
use crate::viewer::swapchain::{Swapchain, PRESENT_MODES};
use anyhow::{anyhow, bail, Context as _, Result};
use ash::vk;
use fovea_renderer::frame::{
    CameraPose, FrameInput, FrameTarget, RenderSettings, ViewInput, MAX_VIEWS,
};
use fovea_renderer::gpu_scene::GpuScene;
use fovea_renderer::graph::SubmitSync;
use fovea_renderer::passes::denoise::DenoiserSettings;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::scene::bvh::instanced::SceneBvh;
use fovea_renderer::scene::bvh::BvhBuilder;
use fovea_renderer::vk::{Buffer, Context};
use glam::{Mat4, Quat, UVec2, Vec2, Vec3};
use gpu_allocator::MemoryLocation;
use std::collections::HashSet;
use std::ffi::CString;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, KeyCode, NamedKey, PhysicalKey};
use winit::raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use winit::window::{Window, WindowId};

pub struct ViewArgs<'a> {
    pub render: RenderArgs<'a>,
    /// `None`: run until the window closes.
    pub frames: Option<u32>,
    pub screenshot: Option<&'a Path>,
    /// `--force`: the screenshot may replace an existing file.
    pub force: bool,
    pub present_mode: &'a str,
    /// Gaze from the mouse (no `--gaze` given).
    pub mouse_gaze: bool,
    /// The debug view shown first (key v cycles).
    pub debug_view: DebugView,
}

/// Key n cycles through every registered denoiser (and none).
const DENOISERS: &[&str] = DenoiserSettings::NAMES;
const TAAS: &[&str] = &["off", "vp", "screen"];

pub fn run(args: &ViewArgs) -> Result<()> {
    let present_mode = PRESENT_MODES
        .iter()
        .find(|(name, _)| *name == args.present_mode)
        .map(|p| p.1)
        .ok_or_else(|| {
            anyhow!(
                "--present-mode {}: expected one of fifo, mailbox, immediate",
                args.present_mode
            )
        })?;
    if args.screenshot.is_some() && args.frames.is_none() {
        bail!("--screenshot needs --frames N (the screenshot is of frame N − 1)");
    }
    if args.debug_view == DebugView::StereoDiff && args.render.eyes != Eyes::Both {
        bail!("--debug-view stereo-diff compares the eyes: it needs --eyes both");
    }
    if let Some(path) = args.screenshot {
        // Before the window opens: an existing file is not replaced without --force.
        crate::output::check_new_file(path, args.force)
            .with_context(|| format!("--screenshot {}", path.display()))?;
    }
    let setup = Setup::new(&args.render, args.frames.unwrap_or(u32::MAX))?;
    let event_loop = EventLoop::new()
        .context("opening the display (X11 or Wayland; is DISPLAY or WAYLAND_DISPLAY set?)")?;
    let display = event_loop.display_handle()?.as_raw();
    let mut options = super::device_options(args.render.device, args.render.validation);
    options.instance_extensions = ash_window::enumerate_required_extensions(display)?
        .iter()
        .map(|&p| unsafe { std::ffi::CStr::from_ptr(p) }.to_owned())
        .collect();
    options.device_extensions = vec![CString::from(ash::khr::swapchain::NAME)];
    options.require_storage_write_without_format = true;
    let ctx = Context::new(&options).context("opening the Vulkan device")?;
    let scene = GpuScene::upload(&ctx, &setup.scene)?;
    let spaces = setup.spaces(args.render.method, &args.render.profile)?;
    let renderer = Renderer::with_views(
        &ctx,
        scene,
        spaces,
        setup.settings,
        super::setup::frames_in_flight(
            args.render.frames_in_flight,
            args.frames.unwrap_or(u32::MAX),
        ),
    )?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = Viewer {
        args,
        ctx: ctx.clone(),
        setup,
        renderer,
        present_mode,
        window: None,
        error: None,
        frame: 0,
        mouse: None,
        frozen: false,
        method: args.render.method.to_string(),
        denoiser: args.render.denoiser.to_string(),
        taa: args.render.taa.to_string(),
        debug: args.debug_view,
        stereo_bvh: None,
        title_at: Instant::now(),
        frames_since_title: 0,
        gpu_ms: None,
        refused: None,
        free: None,
        keys_held: HashSet::new(),
        cursor: None,
        drag: None,
        moved_at: Instant::now(),
    };
    event_loop.run_app(&mut app)?;
    if let Some(e) = app.error.take() {
        return Err(e);
    }
    super::check_validation(&ctx)
}

/// What exists once the window does.
struct WindowState {
    window: Arc<Window>,
    surface_loader: ash::khr::surface::Instance,
    surface: vk::SurfaceKHR,
    swapchain: Option<Swapchain>,
    /// One per frame slot: signalled when the slot's image is acquired.
    acquired: Vec<vk::Semaphore>,
    screenshot: Option<Buffer>,
    /// The debug views' picture on its way into the swapchain image (made when first needed).
    debug_staging: Option<Buffer>,
}

struct Viewer<'a> {
    args: &'a ViewArgs<'a>,
    ctx: Arc<Context>,
    setup: Setup,
    renderer: Renderer,
    present_mode: vk::PresentModeKHR,
    window: Option<WindowState>,
    error: Option<anyhow::Error>,
    frame: u32,
    /// Last cursor position over an eye, in that eye's pixels.
    mouse: Option<Vec2>,
    frozen: bool,
    method: String,
    denoiser: String,
    taa: String,
    debug: DebugView,
    /// The scene's CPU BVH for the stereo-diff view (built when first shown).
    stereo_bvh: Option<SceneBvh>,
    title_at: Instant,
    frames_since_title: u32,
    /// The newest completed frame's GPU ms (all passes, the trace's), read when its slot is retired.
    gpu_ms: Option<(f64, f64)>,
    /// The last switch the renderer refused, and when (shown in the title for a while).
    refused: Option<(String, Instant)>,
    /// The free camera, made by the first move (until then the head follows `--camera-path`).
    free: Option<FreeCamera>,
    keys_held: HashSet<KeyCode>,
    /// The cursor in window pixels, and where the right-button drag last turned the camera.
    cursor: Option<Vec2>,
    drag: Option<Vec2>,
    /// When the free camera last moved (its speed is per second).
    moved_at: Instant,
}

/// The viewer's head when the user moves it: a position and a heading with pitch, turned by
/// dragging and moved along the view with the keys (rolls are not a desktop habit).
#[derive(Clone, Copy, Debug)]
struct FreeCamera {
    position: Vec3,
    yaw: f32,
    pitch: f32,
    /// The head pose's FOV (the scene camera's; the eyes take the headset's under
    /// `--projection headset`).
    fov_tan: glam::Vec4,
}

/// Radians of turn per pixel dragged.
const TURN_PER_PIXEL: f32 = 0.004;
/// Scene diagonals per second of free-camera movement (Shift: four times faster).
const MOVE_DIAGONALS_PER_SECOND: f32 = 0.15;
/// How long a refused switch stays in the title.
const REFUSED_SHOWN_FOR: std::time::Duration = std::time::Duration::from_secs(4);

impl FreeCamera {
    fn from_pose(pose: &CameraPose) -> FreeCamera {
        let forward = pose
            .world_from_view
            .transform_vector3(Vec3::NEG_Z)
            .normalize();
        FreeCamera {
            position: pose.world_from_view.w_axis.truncate(),
            yaw: (-forward.x).atan2(-forward.z),
            pitch: forward.y.clamp(-1.0, 1.0).asin(),
            fov_tan: pose.fov_tan,
        }
    }

    fn rotation(&self) -> Quat {
        Quat::from_rotation_y(self.yaw) * Quat::from_rotation_x(self.pitch)
    }

    fn pose(&self) -> CameraPose {
        CameraPose {
            world_from_view: Mat4::from_rotation_translation(self.rotation(), self.position),
            fov_tan: self.fov_tan,
        }
    }

    fn turn(&mut self, pixels: Vec2) {
        self.yaw -= pixels.x * TURN_PER_PIXEL;
        let limit = 89f32.to_radians();
        self.pitch = (self.pitch - pixels.y * TURN_PER_PIXEL).clamp(-limit, limit);
    }

    /// Moves by `step` scene units along the held keys' directions (view-relative, up is +Y).
    fn travel(&mut self, keys: &HashSet<KeyCode>, step: f32) {
        let r = self.rotation();
        let axes = [
            (KeyCode::KeyW, r * Vec3::NEG_Z),
            (KeyCode::KeyS, r * Vec3::Z),
            (KeyCode::KeyA, r * Vec3::NEG_X),
            (KeyCode::KeyD, r * Vec3::X),
            (KeyCode::Space, Vec3::Y),
            (KeyCode::KeyC, Vec3::NEG_Y),
        ];
        let direction: Vec3 = axes
            .iter()
            .filter(|(k, _)| keys.contains(k))
            .map(|(_, d)| *d)
            .sum();
        if direction.length_squared() > 0.0 {
            self.position += direction.normalize() * step;
        }
    }
}

impl ApplicationHandler for Viewer<'_> {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        if let Err(e) = self.open_window(event_loop) {
            self.fail(event_loop, e);
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let result = match event {
            WindowEvent::CloseRequested => {
                event_loop.exit();
                Ok(())
            }
            WindowEvent::Resized(_) => self.rebuild_swapchain(),
            WindowEvent::CursorMoved { position, .. } => {
                let eye_width = self.setup.width as f32;
                let p = Vec2::new(position.x as f32, position.y as f32);
                self.cursor = Some(p);
                if let Some(from) = self.drag.replace(p) {
                    self.free_camera().turn(p - from);
                } else if !self.frozen {
                    self.mouse = Some(Vec2::new(p.x % eye_width, p.y));
                }
                Ok(())
            }
            WindowEvent::MouseInput {
                button: MouseButton::Right,
                state,
                ..
            } => {
                // Dragging turns the head; the gaze stays where the cursor was.
                self.drag = None;
                if state == ElementState::Pressed && self.args.frames.is_none() {
                    self.drag = self.cursor;
                }
                Ok(())
            }
            WindowEvent::KeyboardInput { event, .. } => {
                if let PhysicalKey::Code(code) = event.physical_key {
                    match event.state {
                        ElementState::Pressed => self.keys_held.insert(code),
                        ElementState::Released => self.keys_held.remove(&code),
                    };
                }
                match event.state {
                    ElementState::Pressed => self.key(event_loop, &event.logical_key),
                    ElementState::Released => Ok(()),
                }
            }
            WindowEvent::Focused(false) => {
                self.keys_held.clear();
                self.drag = None;
                Ok(())
            }
            WindowEvent::RedrawRequested => self.redraw(event_loop),
            _ => Ok(()),
        };
        if let Err(e) = result {
            self.fail(event_loop, e);
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(w) = &self.window {
            w.window.request_redraw();
        }
    }

    fn exiting(&mut self, _event_loop: &ActiveEventLoop) {
        // Nothing in flight may use the swapchain or the semaphores once they go.
        let _ = self.renderer.finish();
        if let Some(w) = self.window.take() {
            drop(w.swapchain);
            unsafe {
                for s in &w.acquired {
                    self.ctx.device.destroy_semaphore(*s, None);
                }
                w.surface_loader.destroy_surface(w.surface, None);
            }
        }
    }
}

impl Viewer<'_> {
    fn fail(&mut self, event_loop: &ActiveEventLoop, e: anyhow::Error) {
        self.error.get_or_insert(e);
        event_loop.exit();
    }

    fn open_window(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let eyes = self.setup.eyes.list().len() as u32;
        let size = winit::dpi::PhysicalSize::new(self.setup.width * eyes, self.setup.height);
        let attrs = Window::default_attributes()
            .with_title("fovea")
            .with_inner_size(size)
            .with_resizable(true);
        let window = Arc::new(event_loop.create_window(attrs)?);
        let surface = unsafe {
            ash_window::create_surface(
                &self.ctx.entry,
                &self.ctx.instance,
                window.display_handle()?.as_raw(),
                window.window_handle()?.as_raw(),
                None,
            )?
        };
        let surface_loader = ash::khr::surface::Instance::new(&self.ctx.entry, &self.ctx.instance);
        if !self.ctx.queue_supports_surface(&surface_loader, surface)? {
            bail!(
                "the compute queue of {} cannot present to this window",
                self.ctx.info.name
            );
        }
        let acquired = (0..self.renderer.frames_in_flight())
            .map(|_| unsafe {
                self.ctx
                    .device
                    .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
            })
            .collect::<std::result::Result<Vec<_>, _>>()?;
        self.window = Some(WindowState {
            window,
            surface_loader,
            surface,
            swapchain: None,
            acquired,
            screenshot: None,
            debug_staging: None,
        });
        self.rebuild_swapchain()
    }

    /// A new swapchain at the window's size, and views resized to it (each eye half the width).
    fn rebuild_swapchain(&mut self) -> Result<()> {
        let Some(mut w) = self.window.take() else {
            return Ok(());
        };
        let result = self.rebuild_swapchain_of(&mut w);
        self.window = Some(w);
        result
    }

    fn rebuild_swapchain_of(&mut self, w: &mut WindowState) -> Result<()> {
        let size = w.window.inner_size();
        if size.width == 0 || size.height == 0 {
            return Ok(()); // minimised: keep the old one until it comes back
        }
        // A resize is not the steady state: drain the frames that use the old images.
        self.renderer.finish()?;
        let old = w.swapchain.take();
        let swapchain = Swapchain::new(
            &self.ctx,
            &w.surface_loader,
            w.surface,
            (size.width, size.height),
            self.present_mode,
            old.as_ref().map_or(vk::SwapchainKHR::null(), |s| s.raw),
        )?;
        drop(old);
        if w.swapchain.is_none() && self.frame == 0 {
            eprintln!(
                "view: swapchain {:?} {}×{}, {:?}; sRGB encoded by the tonemap shader (sRGB formats lack STORAGE)",
                swapchain.format, swapchain.extent.width, swapchain.extent.height, swapchain.present_mode
            );
        }
        let eyes = self.setup.eyes.list().len() as u32;
        let eye = UVec2::new(swapchain.extent.width / eyes, swapchain.extent.height);
        // `--frames` runs keep the render's size (the screenshot must match `fovea render`).
        if self.args.frames.is_none() && eye != self.setup.screen() && eye.x > 0 {
            self.setup.width = eye.x;
            self.setup.height = eye.y;
            self.setup.start_pose = fovea_renderer::frame::CameraPose {
                fov_tan: scaled_fov(self.setup.start_pose.fov_tan, eye),
                ..self.setup.start_pose
            };
            self.rebuild_views()?;
        }
        if self.args.screenshot.is_some() {
            if !swapchain.allows(vk::ImageUsageFlags::TRANSFER_SRC) {
                bail!("this surface does not allow copying its images (TRANSFER_SRC): no --screenshot");
            }
            let bytes = swapchain.extent.width as u64 * swapchain.extent.height as u64 * 4;
            w.screenshot = Some(Buffer::new(
                &self.ctx,
                "screenshot",
                bytes,
                vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )?);
        }
        w.debug_staging = None; // sized by the extent
        w.swapchain = Some(swapchain);
        Ok(())
    }

    fn rebuild_views(&mut self) -> Result<()> {
        let profile = &self.args.render.profile;
        let spaces = self
            .setup
            .eyes
            .list()
            .iter()
            .map(|&eye| {
                space_for(
                    &self.method,
                    profile,
                    &self.setup.hmd,
                    eye,
                    self.setup.screen(),
                )
            })
            .collect::<Result<Vec<_>>>()?;
        let (denoiser, taa) = super::setup::filters_for_method(
            &self.denoiser,
            &self.taa,
            &self.method,
            profile,
            &self.setup.hmd,
        )?;
        let settings = RenderSettings {
            denoiser,
            taa,
            ..self.renderer.settings
        };
        self.renderer.replace_views(spaces, settings)?;
        Ok(())
    }

    fn key(&mut self, event_loop: &ActiveEventLoop, key: &Key) -> Result<()> {
        let next = |list: &[&str], current: &str| {
            list[(list.iter().position(|m| *m == current).unwrap_or(0) + 1) % list.len()]
                .to_string()
        };
        let before = (self.method.clone(), self.denoiser.clone(), self.taa.clone());
        match key.as_ref() {
            Key::Named(NamedKey::Escape) | Key::Character("q") => {
                event_loop.exit();
                return Ok(());
            }
            Key::Character("m") => self.method = next(&method_names(), &self.method),
            // `n` for the noise filter: `d` moves the free camera right.
            Key::Character("n") => self.denoiser = next(DENOISERS, &self.denoiser),
            Key::Character("t") => self.taa = next(TAAS, &self.taa),
            Key::Character("f") => {
                self.frozen = !self.frozen;
                return Ok(());
            }
            Key::Character("v") => {
                self.debug = self.debug.next(self.setup.eyes == Eyes::Both);
                return Ok(());
            }
            _ => return Ok(()),
        }
        if let Err(e) = self.rebuild_views() {
            // An unsupported combination is reported, not fatal: the old views stay, and the
            // title names what runs and what was refused.
            let asked = format!("{} · {} · taa {}", self.method, self.denoiser, self.taa);
            eprintln!("view: {asked} refused: {e:#}");
            (self.method, self.denoiser, self.taa) = before;
            self.refused = Some((asked, Instant::now()));
            self.title_at = Instant::now() - std::time::Duration::from_secs(1);
        }
        Ok(())
    }

    /// The free camera, made at the head's pose of this frame on its first use.
    fn free_camera(&mut self) -> &mut FreeCamera {
        if self.free.is_none() {
            let head = fovea_stage::camera_path::pose(
                &self.setup.start_pose,
                self.setup.scene_centre,
                self.frame,
                u32::MAX,
                &self.args.render.camera_path,
                self.setup.hmd.refresh_hz,
            );
            self.free = Some(FreeCamera::from_pose(&head));
        }
        self.free.as_mut().expect("made above")
    }

    /// Moves the free camera by the keys held since the last frame.
    fn travel(&mut self) {
        let now = Instant::now();
        let seconds = (now - self.moved_at).as_secs_f32().min(0.1);
        self.moved_at = now;
        let moving = [
            KeyCode::KeyW,
            KeyCode::KeyA,
            KeyCode::KeyS,
            KeyCode::KeyD,
            KeyCode::Space,
            KeyCode::KeyC,
        ];
        if self.args.frames.is_some() || !moving.iter().any(|k| self.keys_held.contains(k)) {
            return;
        }
        let fast = self.keys_held.contains(&KeyCode::ShiftLeft)
            || self.keys_held.contains(&KeyCode::ShiftRight);
        let diagonal = self.setup.scene.bounds().bounding_sphere_radius() * 2.0;
        let step = diagonal * MOVE_DIAGONALS_PER_SECOND * seconds * if fast { 4.0 } else { 1.0 };
        let keys = self.keys_held.clone();
        self.free_camera().travel(&keys, step);
    }

    /// GPU ms of a completed frame, kept for the title.
    fn note_timings(&mut self, frame: u64) -> Result<()> {
        let timings = self.renderer.frame_timings(frame)?;
        let total = timings.iter().map(|t| t.ms).sum();
        let trace = timings
            .iter()
            .filter(|t| t.name == "trace")
            .map(|t| t.ms)
            .sum();
        self.gpu_ms = Some((total, trace));
        Ok(())
    }

    fn redraw(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        if self.args.frames.is_some_and(|n| self.frame >= n) {
            self.save_screenshot()?;
            event_loop.exit();
            return Ok(());
        }
        if self.debug != DebugView::Off {
            return self.redraw_debug();
        }
        // The slot's previous frame must be done before its acquire semaphore is reused; its GPU
        // times are read now, before the slot takes the next frame.
        if let Some(done) = self.renderer.retire_next()? {
            self.note_timings(done)?;
        }
        let slot = self.renderer.ring().next_slot();
        let Some(w) = &self.window else { return Ok(()) };
        let Some(swapchain) = &w.swapchain else {
            return Ok(());
        };
        let acquired = w.acquired[slot];
        let (index, _) = match unsafe {
            swapchain.loader.acquire_next_image(
                swapchain.raw,
                u64::MAX,
                acquired,
                vk::Fence::null(),
            )
        } {
            Ok(r) => r,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => return self.rebuild_swapchain(),
            Err(e) => return Err(e.into()),
        };
        let input = self.frame_input()?;
        let last = self.args.frames.is_some_and(|n| self.frame + 1 == n);
        let w = self.window.as_ref().expect("window");
        let swapchain = w.swapchain.as_ref().expect("swapchain");
        let image = &swapchain.images[index as usize];
        let rendered = [swapchain.rendered[index as usize]];
        let waits = [(acquired, vk::PipelineStageFlags::COMPUTE_SHADER)];
        let mut offsets = [UVec2::ZERO; MAX_VIEWS];
        for (v, offset) in offsets.iter_mut().enumerate() {
            *offset = UVec2::new(v as u32 * self.setup.width, 0);
        }
        let target = FrameTarget {
            image,
            offsets,
            sync: SubmitSync {
                wait: &waits,
                signal: &rendered,
            },
            copy_to: if last { w.screenshot.as_ref() } else { None },
        };
        self.renderer.submit(&input, Some(&target))?;
        let swapchains = [swapchain.raw];
        let indices = [index];
        let present = vk::PresentInfoKHR::default()
            .wait_semaphores(&rendered)
            .swapchains(&swapchains)
            .image_indices(&indices);
        let result = {
            let _queue = self.ctx.queue_guard();
            unsafe { swapchain.loader.queue_present(self.ctx.queue, &present) }
        };
        self.frame += 1;
        self.frames_since_title += 1;
        match result {
            Ok(false) => {}
            Ok(true) | Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => self.rebuild_swapchain()?,
            Err(e) => return Err(e.into()),
        }
        self.update_title();
        Ok(())
    }

    /// A debug view: the frame into the engine's own images, waited for, its debug picture made
    /// on the CPU and copied into the swapchain image (and saved as the screenshot of a last frame).
    fn redraw_debug(&mut self) -> Result<()> {
        let input = self.frame_input()?.with_grid(self.debug == DebugView::Grid);
        let stereo_diff = self.debug == DebugView::StereoDiff;
        if stereo_diff && self.stereo_bvh.is_none() {
            self.stereo_bvh = Some(SceneBvh::build(&self.setup.scene, BvhBuilder::BINNED));
        }
        let frame = self.renderer.submit(&input, None)?;
        self.renderer.finish()?;
        self.note_timings(frame)?;
        let stereo = match (stereo_diff, &self.stereo_bvh, input.view_inputs()) {
            (true, Some(bvh), [left, right]) => Some(StereoScene {
                bvh,
                cameras: [left.camera, right.camera],
            }),
            _ => None,
        };
        let eye = self.setup.screen();
        let pixels = compose(
            self.debug,
            &self.renderer,
            frame,
            eye,
            &self.setup.hmd,
            self.setup.eyes.list(),
            stereo.as_ref(),
        )?;
        let last = self.args.frames.is_some_and(|n| self.frame + 1 == n);
        let Some(w) = self.window.as_mut() else {
            return Ok(());
        };
        let Some(swapchain) = &w.swapchain else {
            return Ok(());
        };
        let (width, height) = (eye.x * self.setup.eyes.list().len() as u32, eye.y);
        if (swapchain.extent.width, swapchain.extent.height) != (width, height) {
            return Ok(()); // mid-resize: the views follow on the next frame
        }
        if !swapchain.allows(vk::ImageUsageFlags::TRANSFER_DST) {
            bail!("this surface does not allow copying into its images (TRANSFER_DST): no debug views");
        }
        if w.debug_staging.is_none() {
            w.debug_staging = Some(Buffer::new(
                &self.ctx,
                "debug view",
                pixels.len() as u64,
                vk::BufferUsageFlags::TRANSFER_SRC,
                MemoryLocation::CpuToGpu,
            )?);
        }
        let presented =
            swapchain.present_pixels(w.debug_staging.as_ref().expect("made above"), &pixels)?;
        if let (true, Some(path)) = (last, self.args.screenshot) {
            crate::output::write_png(path, width, height, &pixels)
                .with_context(|| format!("--screenshot {}", path.display()))?;
        }
        self.frame += 1;
        self.frames_since_title += 1;
        if !presented {
            self.rebuild_swapchain()?;
        }
        self.update_title();
        Ok(())
    }

    /// Frame k's input: exactly `fovea render`'s for `--frames` runs and gaze sources; the
    /// mouse (or the frozen gaze) otherwise.
    fn frame_input(&mut self) -> Result<FrameInput> {
        self.travel();
        let head = self.free.as_ref().map(FreeCamera::pose);
        let (input, _) = self.setup.frame_input_from(self.frame, head)?;
        if !self.args.mouse_gaze || self.args.frames.is_some() {
            return Ok(input);
        }
        let mut views = [ViewInput {
            camera: input.view_inputs()[0].camera,
            gaze: None,
        }; MAX_VIEWS];
        let count = input.view_inputs().len();
        for (view, given) in views.iter_mut().zip(input.view_inputs()) {
            // None keeps the space's gaze: frozen, or no cursor yet.
            *view = ViewInput {
                camera: given.camera,
                gaze: if self.frozen {
                    None
                } else {
                    self.mouse.or(given.gaze)
                },
            };
        }
        Ok(FrameInput::views(&views[..count], self.frame)?)
    }

    fn update_title(&mut self) {
        let elapsed = self.title_at.elapsed().as_secs_f64();
        if elapsed < 0.5 {
            return;
        }
        let fps = self.frames_since_title as f64 / elapsed;
        let gpu = match self.gpu_ms {
            Some((total, trace)) => format!("GPU {total:.1} ms (trace {trace:.1})"),
            None => "GPU … ms".into(),
        };
        let refused = match &self.refused {
            Some((asked, at)) if at.elapsed() < REFUSED_SHOWN_FOR => {
                format!("REFUSED {asked} (see the terminal) · ")
            }
            _ => String::new(),
        };
        let title = format!(
            "fovea — {} · {} · taa {} · {:.1} fps · {gpu} · {refused}{}{}[m d t f v: method denoiser taa freeze debug view · WASD Space C, right-drag: move]",
            self.method,
            self.denoiser,
            self.taa,
            fps,
            if self.frozen { "gaze frozen · " } else { "" },
            if self.debug != DebugView::Off { format!("debug view {} · ", self.debug.name()) } else { String::new() }
        );
        if let Some(w) = &self.window {
            w.window.set_title(&title);
        }
        self.title_at = Instant::now();
        self.frames_since_title = 0;
    }

    fn save_screenshot(&mut self) -> Result<()> {
        if self.debug != DebugView::Off {
            return Ok(()); // redraw_debug saved the picture it presented
        }
        let (Some(path), Some(w)) = (self.args.screenshot, &self.window) else {
            return Ok(());
        };
        self.renderer.finish()?;
        let (Some(buffer), Some(swapchain)) = (&w.screenshot, &w.swapchain) else {
            return Ok(());
        };
        let mut pixels = vec![0u8; buffer.size as usize];
        buffer.read_into(&mut pixels)?;
        if swapchain.format == vk::Format::B8G8R8A8_UNORM {
            pixels.chunks_exact_mut(4).for_each(|p| p.swap(0, 2));
        }
        crate::output::write_png(
            path,
            swapchain.extent.width,
            swapchain.extent.height,
            &pixels,
        )
        .with_context(|| format!("--screenshot {}", path.display()))
    }
}

/// The FOV tangents for a new eye size: the vertical extent kept, the horizontal following the
/// aspect ratio (pixels stay square), like `CameraPose::from_scene_camera`.
fn scaled_fov(fov: glam::Vec4, eye: UVec2) -> glam::Vec4 {
    let ty = fov.w;
    let tx = ty * eye.x as f32 / eye.y as f32;
    glam::Vec4::new(-tx, tx, fov.z, fov.w)
}

// `fovea view` (its help is the variant's in `crate::cli::Command`).
#[derive(clap::Args)]
pub struct ViewCommand {
    #[command(flatten)]
    pub opts: Box<RenderOpts>,
    /// Save the last presented image (both eyes side by side) as PNG; needs --frames N. An
    /// existing file is replaced only with --force.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// Let --screenshot replace an existing file.
    #[arg(long)]
    pub force: bool,
    /// fifo (vsync, default), mailbox or immediate (fifo when the surface lacks it).
    #[arg(long, default_value = "fifo")]
    pub present_mode: String,
    /// The debug view shown first: off, grid (the sampling grid as traced), density (samples
    /// per pixel), rings (eccentricity rings at 5, 10, 20, 30, 40°) or stereo-diff (with
    /// --eyes both: each eye's binocular difference as a heat map, the other eye warped into
    /// it through the scene's depth); key v cycles them.
    #[arg(long, default_value = "off")]
    pub debug_view: String,
    #[command(flatten)]
    pub device: DeviceArgs,
}

impl ViewCommand {
    pub fn run(self) -> Result<()> {
        self.device.choose_traversal()?;
        let camera = self.opts.look.camera()?;
        // Without --frames the run has no length: the camera path's period is a long one.
        let render = self.opts.args(
            &camera,
            &self.device,
            RenderDefaults {
                frames: u32::MAX,
                gaze: "center",
                out: "out/render",
                scale: DEFAULT_SCALE,
            },
        )?;
        run(&ViewArgs {
            frames: self.opts.frames,
            screenshot: self.screenshot.as_deref(),
            force: self.force,
            present_mode: &self.present_mode,
            mouse_gaze: self.opts.gaze.is_none(),
            debug_view: DebugView::parse(&self.debug_view)?,
            render,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_free_camera_starts_at_the_head_moves_along_the_view_and_turns_without_rolling() {
        let head = CameraPose {
            world_from_view: Mat4::from_rotation_translation(
                Quat::from_rotation_y(0.5) * Quat::from_rotation_x(-0.2),
                Vec3::new(1.0, 2.0, 3.0),
            ),
            fov_tan: glam::Vec4::new(-1.0, 1.0, -1.0, 1.0),
        };
        let mut free = FreeCamera::from_pose(&head);
        let pose = free.pose();
        assert!(
            pose.world_from_view.abs_diff_eq(head.world_from_view, 1e-5),
            "{pose:?}"
        );
        let forward = head.world_from_view.transform_vector3(Vec3::NEG_Z);
        free.travel(&HashSet::from([KeyCode::KeyW]), 2.0);
        assert!((free.position - (Vec3::new(1.0, 2.0, 3.0) + forward * 2.0)).length() < 1e-5);
        free.travel(&HashSet::from([KeyCode::Space]), 1.0);
        assert!((free.position.y - (2.0 + forward.y * 2.0 + 1.0)).abs() < 1e-5);
        // Opposite keys cancel; no key, no move.
        let at = free.position;
        free.travel(&HashSet::from([KeyCode::KeyA, KeyCode::KeyD]), 1.0);
        free.travel(&HashSet::new(), 1.0);
        assert_eq!(free.position, at);
        // Dragging right turns right; the horizon stays level and the pitch stops short of 90°.
        let yaw = free.yaw;
        free.turn(Vec2::new(100.0, 0.0));
        assert!(free.yaw < yaw);
        free.turn(Vec2::new(0.0, -1e6));
        assert!(free.pitch < 90f32.to_radians());
        let right = free.pose().world_from_view.transform_vector3(Vec3::X);
        assert!(right.y.abs() < 1e-5, "no roll: {right}");
    }
}
