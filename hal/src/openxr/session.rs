//! The one owner of an OpenXR session: creation (headless or Vulkan), the single event loop,
//! action-set attachment, frame calls, and what the runtime reports about the headset.

use super::{call, fail, OpenXrRuntime};
use crate::error::HalError;
use crate::hmd::{Fov, HmdDescription};
use crate::sample::XrTime;
use glam::Vec3;
use openxr as xr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

const VIEW_TYPE: xr::ViewConfigurationType = xr::ViewConfigurationType::PRIMARY_STEREO;

/// Why a session is over. After any of these the owner does nothing more but can be dropped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SessionEnd {
    /// `XR_SESSION_STATE_EXITING` (after [`ExitHandle::request`] or the runtime's own request),
    /// or an exit requested before the session ever ran.
    Exiting,
    /// `XR_SESSION_STATE_LOSS_PENDING`: the device went away.
    LossPending,
    /// `XrEventDataInstanceLossPending`: the runtime is going away.
    InstanceLossPending,
}

/// A snapshot of the session as the owner's event loop last left it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SessionStatus {
    pub state: xr::SessionState,
    /// Between a successful `xrBeginSession` and `xrEndSession`.
    pub running: bool,
    pub end: Option<SessionEnd>,
    /// How often the owner called `xrBeginSession` / `xrEndSession` (once each per run).
    pub begins: u32,
    pub ends: u32,
    /// How often [`SessionOwner::sync_actions`] ran (the gaze source syncs only in frames where
    /// it did not).
    pub syncs: u64,
}

impl SessionStatus {
    const INITIAL: SessionStatus = SessionStatus {
        state: xr::SessionState::UNKNOWN,
        running: false,
        end: None,
        begins: 0,
        ends: 0,
        syncs: 0,
    };

    /// Actions (gaze) are only delivered while focused.
    pub fn focused(&self) -> bool {
        self.state == xr::SessionState::FOCUSED
    }
}

/// The owner's session state, shared read-only with borrowers (the gaze source), so they never
/// poll the instance-wide event queue themselves.
#[derive(Clone)]
pub struct SessionStateHandle(Arc<Mutex<SessionStatus>>);

impl SessionStateHandle {
    pub fn get(&self) -> SessionStatus {
        *self.0.lock().unwrap_or_else(|p| p.into_inner())
    }

    fn set(&self, status: SessionStatus) {
        *self.0.lock().unwrap_or_else(|p| p.into_inner()) = status;
    }
}

/// Asks the owner for a clean end (`xrRequestExitSession` on its next poll). Only an atomic
/// store, so it is safe to call from a Ctrl-C handler or another thread.
#[derive(Clone, Default)]
pub struct ExitHandle(Arc<AtomicBool>);

impl ExitHandle {
    pub fn request(&self) {
        self.0.store(true, Ordering::SeqCst);
    }

    pub fn requested(&self) -> bool {
        self.0.load(Ordering::SeqCst)
    }
}

/// The Vulkan objects a session renders with (all created through the runtime, see
/// [`OpenXrRuntime::create_vulkan_instance`] and friends).
#[derive(Clone, Copy)]
pub struct VulkanBinding {
    pub instance: xr::sys::platform::VkInstance,
    pub physical_device: xr::sys::platform::VkPhysicalDevice,
    pub device: xr::sys::platform::VkDevice,
    pub queue_family_index: u32,
    pub queue_index: u32,
}

/// Which figures of a [`SessionOwner::describe`] result the runtime reported (the rest are the
/// headset TOML's).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RuntimeFigures {
    /// `id`, `display_name` (from `xrGetSystemProperties`).
    pub name: bool,
    /// `recommended_width/height` (`xrEnumerateViewConfigurationViews`).
    pub recommended_size: bool,
    /// Per-eye FOV (`xrLocateViews`).
    pub fov: bool,
    /// Eye offsets (`xrLocateViews`, position valid).
    pub offsets: bool,
    /// `refresh_hz` (`XR_FB_display_refresh_rate`).
    pub refresh: bool,
}

/// Owns one session: the only place that polls events, begins and ends the session, and
/// attaches action sets. `G` is `xr::Headless` (no rendering) or `xr::Vulkan`.
pub struct SessionOwner<G: xr::Graphics> {
    instance: xr::Instance,
    system: xr::SystemId,
    has_timespec: bool,
    has_refresh_rate: bool,
    /// No display (and Monado leaves the refresh rate unwritten for such sessions).
    headless: bool,
    session: xr::Session<G>,
    waiter: xr::FrameWaiter,
    stream: xr::FrameStream<G>,
    status: SessionStatus,
    shared: SessionStateHandle,
    exit: ExitHandle,
    exit_sent: bool,
    attached: Option<Vec<xr::ActionSet>>,
}

impl SessionOwner<xr::Headless> {
    /// A session without graphics (`XR_MND_headless`): gaze and poses, no frames to submit.
    pub fn headless(rt: &OpenXrRuntime) -> Result<Self, HalError> {
        if !rt.has_headless {
            return Err(fail(
                "the runtime lacks XR_MND_headless: create a Vulkan session instead",
            ));
        }
        // SAFETY: headless sessions take no graphics handles.
        let parts = call("xrCreateSession(headless)", unsafe {
            rt.instance
                .create_session::<xr::Headless>(rt.system, &xr::headless::SessionCreateInfo {})
        })?;
        Ok(Self::from_parts(rt, parts, true))
    }
}

impl SessionOwner<xr::Vulkan> {
    /// A Vulkan session. Queries the graphics requirements first, as `XR_KHR_vulkan_enable2`
    /// demands before `xrCreateSession`.
    ///
    /// # Safety
    /// `binding` must hold live handles created through this runtime's
    /// `create_vulkan_instance` / `vulkan_physical_device` / `create_vulkan_device`, and must
    /// outlive the owner.
    pub unsafe fn vulkan(rt: &OpenXrRuntime, binding: VulkanBinding) -> Result<Self, HalError> {
        rt.vulkan_requirements()?;
        let info = xr::vulkan::SessionCreateInfo {
            instance: binding.instance,
            physical_device: binding.physical_device,
            device: binding.device,
            queue_family_index: binding.queue_family_index,
            queue_index: binding.queue_index,
        };
        // SAFETY: the caller vouches for the handles.
        let parts = call("xrCreateSession(Vulkan)", unsafe {
            rt.instance.create_session::<xr::Vulkan>(rt.system, &info)
        })?;
        Ok(Self::from_parts(rt, parts, false))
    }
}

/// `VK_FORMAT_R8G8B8A8_UNORM` / `B8G8R8A8_UNORM`: sRGB formats rarely allow storage writes,
/// so compute writes UNORM and encodes sRGB itself.
pub const STORAGE_FORMATS: [u32; 2] = [37, 44];

impl SessionOwner<xr::Vulkan> {
    /// The runtime's swapchain formats (`VkFormat` values), its preferred first.
    pub fn swapchain_formats(&self) -> Result<Vec<u32>, HalError> {
        call(
            "xrEnumerateSwapchainFormats",
            self.session.enumerate_swapchain_formats(),
        )
    }

    /// A single-sample colour swapchain that compute shaders can write (`UNORDERED_ACCESS`, i.e.
    /// `VK_IMAGE_USAGE_STORAGE_BIT`), plus colour-attachment and transfer usage (transfer-source:
    /// screenshots of what was submitted).
    /// `format` must be one of [`Self::swapchain_formats`] (see [`STORAGE_FORMATS`]).
    pub fn create_storage_swapchain(
        &self,
        format: u32,
        width: u32,
        height: u32,
    ) -> Result<xr::Swapchain<xr::Vulkan>, HalError> {
        let offered = self.swapchain_formats()?;
        if !offered.contains(&format) {
            return Err(fail(format!(
                "swapchain format {format} is not offered by the runtime (offered: {offered:?})"
            )));
        }
        let info = xr::SwapchainCreateInfo::<xr::Vulkan> {
            create_flags: xr::SwapchainCreateFlags::EMPTY,
            usage_flags: xr::SwapchainUsageFlags::UNORDERED_ACCESS
                | xr::SwapchainUsageFlags::COLOR_ATTACHMENT
                | xr::SwapchainUsageFlags::TRANSFER_DST
                | xr::SwapchainUsageFlags::TRANSFER_SRC,
            format,
            sample_count: 1,
            width,
            height,
            face_count: 1,
            array_size: 1,
            mip_count: 1,
        };
        call("xrCreateSwapchain", self.session.create_swapchain(&info))
    }
}

impl<G: xr::Graphics> SessionOwner<G> {
    fn from_parts(
        rt: &OpenXrRuntime,
        (session, waiter, stream): (xr::Session<G>, xr::FrameWaiter, xr::FrameStream<G>),
        headless: bool,
    ) -> Self {
        SessionOwner {
            instance: rt.instance.clone(),
            system: rt.system,
            has_timespec: rt.has_timespec,
            has_refresh_rate: rt.has_refresh_rate,
            headless,
            session,
            waiter,
            stream,
            status: SessionStatus::INITIAL,
            shared: SessionStateHandle(Arc::new(Mutex::new(SessionStatus::INITIAL))),
            exit: ExitHandle::default(),
            exit_sent: false,
            attached: None,
        }
    }

    pub fn session(&self) -> &xr::Session<G> {
        &self.session
    }

    pub fn instance(&self) -> &xr::Instance {
        &self.instance
    }

    pub fn status(&self) -> SessionStatus {
        self.status
    }

    /// For borrowers that need the state without polling (the gaze source).
    pub fn state_handle(&self) -> SessionStateHandle {
        self.shared.clone()
    }

    /// Clone it into a Ctrl-C handler; [`ExitHandle::request`] ends the session cleanly.
    pub fn exit_handle(&self) -> ExitHandle {
        self.exit.clone()
    }

    /// Attach every action set of the session at once: OpenXR allows one
    /// `xrAttachSessionActionSets` per session, so the renderer's sets and the gaze set
    /// ([`super::GazeActions::action_set`]) go in together.
    /// An empty list attaches nothing (OpenXR refuses a count of 0), so a later call still can.
    pub fn attach_action_sets(&mut self, sets: &[&xr::ActionSet]) -> Result<(), HalError> {
        if sets.is_empty() {
            return Ok(());
        }
        if self.attached.is_some() {
            return Err(fail("action sets are already attached to this session (OpenXR allows one attach per session): pass all of them in one call"));
        }
        call(
            "xrAttachSessionActionSets",
            self.session.attach_action_sets(sets),
        )?;
        self.attached = Some(sets.iter().map(|&s| s.clone()).collect());
        Ok(())
    }

    /// Whether `set` went into this session's one attach.
    pub fn is_attached(&self, set: &xr::ActionSet) -> bool {
        self.attached_sets()
            .iter()
            .any(|s| s.as_raw() == set.as_raw())
    }

    /// Every set of the one attach (empty before it).
    pub fn attached_sets(&self) -> &[xr::ActionSet] {
        self.attached.as_deref().unwrap_or(&[])
    }

    /// One `xrSyncActions` for every attached set. Sets left out of a sync become inactive, so
    /// the renderer and the gaze source must not sync separately: the renderer calls this once
    /// per frame when it reads its own actions (before the gaze source's `begin_frame`), else the
    /// gaze source makes the same full sync itself.
    pub fn sync_actions(&mut self) -> Result<(), HalError> {
        if !self.status.running {
            return Ok(());
        }
        sync_sets(&self.session, self.attached_sets())?;
        self.status.syncs += 1;
        self.shared.set(self.status);
        Ok(())
    }

    /// Drain the event queue and act on session state *changes*: READY → `xrBeginSession`,
    /// STOPPING → `xrEndSession`, EXITING / LOSS_PENDING / instance loss → [`SessionEnd`].
    /// Also sends `xrRequestExitSession` once after [`ExitHandle::request`].
    pub fn poll_events(&mut self) -> Result<SessionStatus, HalError> {
        self.poll_events_with(|_| {})
    }

    /// [`Self::poll_events`], handing every event it does not consume itself (interaction
    /// profile changes, reference space changes, other sessions' states …) to `other`.
    pub fn poll_events_with(
        &mut self,
        mut other: impl FnMut(&xr::Event<'_>),
    ) -> Result<SessionStatus, HalError> {
        self.send_exit_request()?;
        let mut buffer = xr::EventDataBuffer::new();
        while self.status.end.is_none() {
            let Some(event) = call("xrPollEvent", self.instance.poll_event(&mut buffer))? else {
                break;
            };
            match event {
                xr::Event::SessionStateChanged(e) if e.session() == self.session.as_raw() => {
                    self.on_state(e.state())?
                }
                xr::Event::InstanceLossPending(_) => self.finish(SessionEnd::InstanceLossPending),
                ref e => other(e),
            }
        }
        self.shared.set(self.status);
        Ok(self.status)
    }

    fn on_state(&mut self, state: xr::SessionState) -> Result<(), HalError> {
        if state == self.status.state {
            return Ok(());
        }
        self.status.state = state;
        match state {
            xr::SessionState::READY => self.begin()?,
            xr::SessionState::STOPPING => self.end()?,
            xr::SessionState::EXITING => self.finish(SessionEnd::Exiting),
            xr::SessionState::LOSS_PENDING => self.finish(SessionEnd::LossPending),
            _ => {}
        }
        self.shared.set(self.status);
        Ok(())
    }

    fn begin(&mut self) -> Result<(), HalError> {
        call("xrBeginSession", self.session.begin(VIEW_TYPE))?;
        self.status.running = true;
        self.status.begins += 1;
        Ok(())
    }

    fn end(&mut self) -> Result<(), HalError> {
        call("xrEndSession", self.session.end())?;
        self.status.running = false;
        self.status.ends += 1;
        Ok(())
    }

    fn finish(&mut self, why: SessionEnd) {
        self.status.end = Some(why);
        self.status.running = false;
    }

    fn send_exit_request(&mut self) -> Result<(), HalError> {
        if self.exit_sent || !self.exit.requested() || self.status.end.is_some() {
            return Ok(());
        }
        self.exit_sent = true;
        if !self.status.running {
            // Nothing to stop: the session never began (or already stopped).
            self.finish(SessionEnd::Exiting);
            return Ok(());
        }
        call("xrRequestExitSession", self.session.request_exit())
    }

    /// The runtime's clock now (display times of headless sessions, which have no frame loop).
    pub fn now(&self) -> Result<XrTime, HalError> {
        if !self.has_timespec {
            return Err(fail(
                "the runtime lacks XR_KHR_convert_timespec_time: no clock outside the frame loop",
            ));
        }
        call("xrConvertTimespecTimeToTimeKHR", self.instance.now()).map(|t| t.as_nanos())
    }

    /// `xrWaitFrame`: blocks until the runtime wants the next frame; its
    /// `predicted_display_time` is what `begin_frame` of the gaze source and `locate_views` take.
    pub fn wait_frame(&mut self) -> Result<xr::FrameState, HalError> {
        if self.headless {
            // Monado answers shouldRender = false without a usable time, and xrBeginFrame fails.
            return Err(fail(
                "a headless session has no frame loop: take display times from now()",
            ));
        }
        call("xrWaitFrame", self.waiter.wait())
    }

    /// `xrBeginFrame`.
    pub fn begin_frame(&mut self) -> Result<(), HalError> {
        call("xrBeginFrame", self.stream.begin())
    }

    /// `xrEndFrame` with the renderer's layers (opaque blending).
    pub fn end_frame(
        &mut self,
        display_time: XrTime,
        layers: &[&xr::CompositionLayerBase<'_, G>],
    ) -> Result<(), HalError> {
        call(
            "xrEndFrame",
            self.stream.end(
                xr::Time::from_nanos(display_time),
                xr::EnvironmentBlendMode::OPAQUE,
                layers,
            ),
        )
    }

    /// `xrLocateViews` (primary stereo) in `space`: per-eye pose and FOV for `display_time`.
    pub fn locate_views(
        &self,
        display_time: XrTime,
        space: &xr::Space,
    ) -> Result<(xr::ViewStateFlags, Vec<xr::View>), HalError> {
        call(
            "xrLocateViews",
            self.session
                .locate_views(VIEW_TYPE, xr::Time::from_nanos(display_time), space),
        )
    }

    pub fn create_reference_space(
        &self,
        ty: xr::ReferenceSpaceType,
    ) -> Result<xr::Space, HalError> {
        call(
            "xrCreateReferenceSpace",
            self.session.create_reference_space(ty, xr::Posef::IDENTITY),
        )
    }

    /// `base` (the headset TOML) overwritten with what the runtime reports: name and id,
    /// recommended per-eye size, per-eye FOV and eye offsets (`xrLocateViews` now, in VIEW
    /// space), refresh rate (`XR_FB_display_refresh_rate`). Tracker rate, latency, accuracy and
    /// precision are not reported by OpenXR and stay the TOML's.
    pub fn describe(
        &self,
        base: &HmdDescription,
        eye_gaze: bool,
    ) -> Result<(HmdDescription, RuntimeFigures), HalError> {
        let mut hmd = base.clone();
        let mut figures = RuntimeFigures::default();
        let props = call(
            "xrGetSystemProperties",
            self.instance.system_properties(self.system),
        )?;
        hmd.id = runtime_id(&props.system_name);
        hmd.display_name = format!("{} (OpenXR)", props.system_name);
        figures.name = true;
        let views = call(
            "xrEnumerateViewConfigurationViews",
            self.instance
                .enumerate_view_configuration_views(self.system, VIEW_TYPE),
        )?;
        for (eye, view) in hmd.eyes.iter_mut().zip(&views) {
            eye.recommended_width = view.recommended_image_rect_width.max(1);
            eye.recommended_height = view.recommended_image_rect_height.max(1);
            figures.recommended_size = true;
        }
        self.describe_views(&mut hmd, &mut figures)?;
        if let Some(hz) = self.refresh_rate() {
            hmd.refresh_hz = hz;
            figures.refresh = true;
        }
        hmd.capabilities.eye_gaze = eye_gaze;
        Ok((hmd, figures))
    }

    fn describe_views(
        &self,
        hmd: &mut HmdDescription,
        figures: &mut RuntimeFigures,
    ) -> Result<(), HalError> {
        let Ok(t) = self.now() else { return Ok(()) };
        let view_space = self.create_reference_space(xr::ReferenceSpaceType::VIEW)?;
        let (flags, views) = self.locate_views(t, &view_space)?;
        if apply_views(hmd, flags, &views) {
            figures.fov = true;
            figures.offsets = flags.contains(xr::ViewStateFlags::POSITION_VALID);
        }
        Ok(())
    }

    /// The display's refresh rate; `None` for headless sessions (no display) and for values no
    /// display has (a runtime that leaves the output unwritten).
    fn refresh_rate(&self) -> Option<f32> {
        if !self.has_refresh_rate || self.headless {
            return None;
        }
        self.session
            .get_display_refresh_rate()
            .ok()
            .filter(|hz| (1.0..=1000.0).contains(hz))
    }
}

/// `xrSyncActions` over `sets` (all of a session's attached sets). Not focused is a success code
/// (`XR_SESSION_NOT_FOCUSED`): actions stay inactive.
pub(crate) fn sync_sets<G>(
    session: &xr::Session<G>,
    sets: &[xr::ActionSet],
) -> Result<(), HalError> {
    if sets.is_empty() {
        return Ok(());
    }
    let active: Vec<xr::ActiveActionSet<'_>> = sets.iter().map(xr::ActiveActionSet::new).collect();
    call("xrSyncActions", session.sync_actions(&active))
}

/// Per-eye FOV (and offsets when the position is valid) from located views; false when the
/// views are not usable (orientation invalid, not two of them).
pub(crate) fn apply_views(
    hmd: &mut HmdDescription,
    flags: xr::ViewStateFlags,
    views: &[xr::View],
) -> bool {
    if !flags.contains(xr::ViewStateFlags::ORIENTATION_VALID) || views.len() != 2 {
        return false;
    }
    for (eye, v) in hmd.eyes.iter_mut().zip(views) {
        eye.fov = Fov {
            angle_left: v.fov.angle_left,
            angle_right: v.fov.angle_right,
            angle_down: v.fov.angle_down,
            angle_up: v.fov.angle_up,
        };
        if flags.contains(xr::ViewStateFlags::POSITION_VALID) {
            let p = v.pose.position;
            eye.offset = Vec3::new(p.x, p.y, p.z);
        }
    }
    true
}

/// A profile id (`[a-z0-9_-]+`) from the runtime's system name: "openxr-" + the name
/// lowercased, every run of other characters as one '-'.
fn runtime_id(system_name: &str) -> String {
    let mut id = String::from("openxr-");
    for c in system_name.chars().map(|c| c.to_ascii_lowercase()) {
        let c = if c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_' {
            c
        } else {
            '-'
        };
        if c != '-' || !id.ends_with('-') {
            id.push(c);
        }
    }
    id.trim_end_matches('-').to_string()
}
