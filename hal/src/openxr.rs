//! OpenXR backend (cargo feature `openxr`): gaze from `XR_EXT_eye_gaze_interaction`.
//!
//! Pose action on `/user/eyes_ext/input/gaze_ext/pose` → action space → located in VIEW space at
//! the requested time through a raw `xrLocateSpace` call, because the crate's `Space::locate`
//! cannot chain `XrEyeGazeSampleTimeEXT` (the real sample time). Support is read from
//! `XrSystemEyeGazeInteractionPropertiesEXT` chained onto `xrGetSystemProperties`. Per-eye FOV and
//! offsets come from `xrLocateViews` every frame.
//!
//! The loader is opened at run time (`loaded` mode), so binaries run on machines without it and
//! report a clear error instead. API version 1.0 is requested (Debian 12 ships loader 1.0.20).
//! Only compiled here: no runtime with an eye tracker was available (see hal/README.md).

use crate::error::HalError;
use crate::hmd::{Fov, HmdDescription};
use crate::sample::{EyeState, GazeRay, GazeSample, SampleTimeKind, XrTime};
use crate::source::GazeSource;
use glam::{Quat, Vec3};
use openxr as xr;
use std::ptr;

const BACKEND: &str = "openxr";
const EYE_GAZE_PROFILE: &str = "/interaction_profiles/ext/eye_gaze_interaction";
const EYE_GAZE_POSE: &str = "/user/eyes_ext/input/gaze_ext/pose";

fn fail(reason: impl Into<String>) -> HalError {
    HalError::Backend { backend: BACKEND, reason: reason.into() }
}

fn call<T>(what: &str, r: Result<T, xr::sys::Result>) -> Result<T, HalError> {
    r.map_err(|e| fail(format!("{what} failed: {e}")))
}

/// A loaded runtime: instance, HMD system and what it supports.
pub struct OpenXrRuntime {
    pub instance: xr::Instance,
    pub system: xr::SystemId,
    pub supports_eye_gaze: bool,
    pub has_headless: bool,
    pub has_timespec: bool,
}

impl OpenXrRuntime {
    /// Open the loader, create an instance with eye-gaze (+ headless / timespec when offered).
    pub fn create(application_name: &str) -> Result<Self, HalError> {
        // SAFETY: loads the system OpenXR loader, which must follow the OpenXR specification.
        let entry = unsafe { xr::Entry::load(&()) }.map_err(|e| {
            fail(format!("cannot load the OpenXR loader (libopenxr_loader.so.1; Debian: libopenxr-loader1): {e}"))
        })?;
        let available = entry.enumerate_extensions().map_err(|e| {
            fail(format!("no OpenXR runtime is installed or active (XR_RUNTIME_JSON / active_runtime.json): {e}"))
        })?;
        if !available.ext_eye_gaze_interaction {
            return Err(fail("the active OpenXR runtime does not offer XR_EXT_eye_gaze_interaction"));
        }
        let mut wanted = xr::ExtensionSet::default();
        wanted.ext_eye_gaze_interaction = true;
        wanted.mnd_headless = available.mnd_headless;
        wanted.khr_convert_timespec_time = available.khr_convert_timespec_time;
        let name: String = application_name.chars().take(100).collect();
        let app = xr::ApplicationInfo {
            application_name: &name,
            application_version: 0,
            engine_name: "fovea",
            engine_version: 0,
            api_version: xr::Version::new(1, 0, 0),
        };
        let instance = call("xrCreateInstance", entry.create_instance(&app, &wanted, &[], &()))?;
        let system = call("xrGetSystem(HEAD_MOUNTED_DISPLAY)", instance.system(xr::FormFactor::HEAD_MOUNTED_DISPLAY))?;
        let supports_eye_gaze = query_eye_gaze_support(&instance, system)?;
        Ok(OpenXrRuntime {
            instance,
            system,
            supports_eye_gaze,
            has_headless: available.mnd_headless,
            has_timespec: available.khr_convert_timespec_time,
        })
    }

    /// `base` with the runtime's name and recommended per-eye image sizes.
    pub fn describe(&self, base: &HmdDescription) -> Result<HmdDescription, HalError> {
        let props = call("xrGetSystemProperties", self.instance.system_properties(self.system))?;
        let views = call(
            "xrEnumerateViewConfigurationViews",
            self.instance.enumerate_view_configuration_views(self.system, xr::ViewConfigurationType::PRIMARY_STEREO),
        )?;
        let mut hmd = base.clone();
        hmd.display_name = format!("{} (OpenXR)", props.system_name);
        for (eye, view) in hmd.eyes.iter_mut().zip(&views) {
            eye.recommended_width = view.recommended_image_rect_width.max(1);
            eye.recommended_height = view.recommended_image_rect_height.max(1);
        }
        hmd.capabilities.eye_gaze = self.supports_eye_gaze;
        Ok(hmd)
    }
}

/// `XrSystemEyeGazeInteractionPropertiesEXT` chained onto `xrGetSystemProperties` (the crate has
/// no helper for it).
fn query_eye_gaze_support(instance: &xr::Instance, system: xr::SystemId) -> Result<bool, HalError> {
    let mut eye = xr::sys::SystemEyeGazeInteractionPropertiesEXT {
        ty: xr::sys::SystemEyeGazeInteractionPropertiesEXT::TYPE,
        next: ptr::null_mut(),
        supports_eye_gaze_interaction: xr::sys::FALSE,
    };
    // SAFETY: zeroed is a valid bit pattern for this plain C struct; ty/next are set before use.
    let mut props: xr::sys::SystemProperties = unsafe { std::mem::zeroed() };
    props.ty = xr::sys::SystemProperties::TYPE;
    props.next = &mut eye as *mut _ as *mut _;
    // SAFETY: valid instance and system handles; both structs outlive the call.
    let r = unsafe { (instance.fp().get_system_properties)(instance.as_raw(), system, &mut props) };
    if r.into_raw() < 0 {
        return Err(fail(format!("xrGetSystemProperties failed: {r}")));
    }
    Ok(eye.supports_eye_gaze_interaction.into())
}

/// Gaze from an OpenXR session (headless here, or the renderer's own session).
pub struct OpenXrGaze {
    hmd: HmdDescription,
    instance: xr::Instance,
    session: xr::Session<xr::AnyGraphics>,
    action_set: xr::ActionSet,
    gaze_space: xr::Space,
    view_space: xr::Space,
    has_timespec: bool,
    state: xr::SessionState,
    /// Headless sessions are begun/ended here; a renderer-owned session is the renderer's job.
    manage_session: bool,
    sequence: u64,
    last: GazeSample,
    events: xr::EventDataBuffer,
}

impl OpenXrGaze {
    /// Headless session (`XR_MND_headless`) for gaze without rendering through OpenXR.
    pub fn headless(base: &HmdDescription) -> Result<Self, HalError> {
        let rt = OpenXrRuntime::create("fovea gaze")?;
        if !rt.has_headless {
            return Err(fail("the runtime lacks XR_MND_headless; open gaze on the renderer's session instead"));
        }
        // SAFETY: headless sessions take no graphics handles.
        let (session, _waiter, _stream) =
            call("xrCreateSession(headless)", unsafe { rt.instance.create_session::<xr::Headless>(rt.system, &xr::headless::SessionCreateInfo {}) })?;
        Self::with_session(&rt, session.into_any_graphics(), base, true)
    }

    /// Use an existing session. Must run before the caller attaches its own action sets
    /// (OpenXR allows one `xrAttachSessionActionSets` per session).
    pub fn with_session(
        rt: &OpenXrRuntime,
        session: xr::Session<xr::AnyGraphics>,
        base: &HmdDescription,
        manage_session: bool,
    ) -> Result<Self, HalError> {
        if !rt.supports_eye_gaze {
            return Err(fail(
                "the runtime reports supportsEyeGazeInteraction = false (no eye tracker in the \"eyes\" role, \
                 no permission, or uncalibrated); use --gaze sim or a trace instead",
            ));
        }
        let instance = rt.instance.clone();
        let action_set = call("xrCreateActionSet", instance.create_action_set("fovea_gaze", "fovea gaze", 0))?;
        let action = call("xrCreateAction", action_set.create_action::<xr::Posef>("gaze", "Eye gaze", &[]))?;
        let profile = call("xrStringToPath", instance.string_to_path(EYE_GAZE_PROFILE))?;
        let pose = call("xrStringToPath", instance.string_to_path(EYE_GAZE_POSE))?;
        call(
            "xrSuggestInteractionProfileBindings",
            instance.suggest_interaction_profile_bindings(profile, &[xr::Binding::new(&action, pose)]),
        )?;
        call("xrAttachSessionActionSets", session.attach_action_sets(&[&action_set]))?;
        let gaze_space = call("xrCreateActionSpace", action.create_space(&session, xr::Path::NULL, xr::Posef::IDENTITY))?;
        let view_space = call(
            "xrCreateReferenceSpace(VIEW)",
            session.create_reference_space(xr::ReferenceSpaceType::VIEW, xr::Posef::IDENTITY),
        )?;
        Ok(OpenXrGaze {
            hmd: rt.describe(base)?,
            instance,
            session,
            action_set,
            gaze_space,
            view_space,
            has_timespec: rt.has_timespec,
            state: xr::SessionState::UNKNOWN,
            manage_session,
            sequence: 0,
            last: GazeSample::no_gaze(0, 0),
            events: xr::EventDataBuffer::new(),
        })
    }

    fn poll_events(&mut self) -> Result<(), HalError> {
        while let Some(event) = call("xrPollEvent", self.instance.poll_event(&mut self.events))? {
            match event {
                xr::Event::SessionStateChanged(e) => self.state = e.state(),
                xr::Event::InstanceLossPending(_) => return Err(fail("the OpenXR runtime is going away (instance loss pending)")),
                _ => {}
            }
            if !self.manage_session {
                continue;
            }
            match self.state {
                xr::SessionState::READY => {
                    call("xrBeginSession", self.session.begin(xr::ViewConfigurationType::PRIMARY_STEREO))?;
                }
                xr::SessionState::STOPPING => {
                    call("xrEndSession", self.session.end())?;
                }
                xr::SessionState::EXITING | xr::SessionState::LOSS_PENDING => {
                    return Err(fail(format!("the OpenXR session ended ({:?})", self.state)));
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// Headless runtimes may give no display time: fall back to the instance clock.
    fn usable_time(&self, t: XrTime) -> XrTime {
        if t > 0 || !self.has_timespec {
            return t;
        }
        self.instance.now().map(|n| n.as_nanos()).unwrap_or(t)
    }

    fn update_views(&mut self, t: XrTime) {
        let located = self.session.locate_views(xr::ViewConfigurationType::PRIMARY_STEREO, xr::Time::from_nanos(t), &self.view_space);
        let Ok((flags, views)) = located else { return };
        if !flags.contains(xr::ViewStateFlags::ORIENTATION_VALID) {
            return;
        }
        for (eye, v) in self.hmd.eyes.iter_mut().zip(&views) {
            eye.fov = Fov { angle_left: v.fov.angle_left, angle_right: v.fov.angle_right, angle_down: v.fov.angle_down, angle_up: v.fov.angle_up };
            if flags.contains(xr::ViewStateFlags::POSITION_VALID) {
                let p = v.pose.position;
                eye.offset = Vec3::new(p.x, p.y, p.z);
            }
        }
    }

    fn locate_gaze(&mut self, t: XrTime) -> GazeSample {
        let focused = self.state == xr::SessionState::FOCUSED;
        if !focused {
            return GazeSample::no_gaze(t, self.sequence);
        }
        let mut sample_time = xr::sys::EyeGazeSampleTimeEXT { ty: xr::sys::EyeGazeSampleTimeEXT::TYPE, next: ptr::null_mut(), time: xr::Time::from_nanos(0) };
        let mut loc = xr::sys::SpaceLocation {
            ty: xr::sys::SpaceLocation::TYPE,
            next: &mut sample_time as *mut _ as *mut _,
            location_flags: xr::SpaceLocationFlags::EMPTY,
            pose: xr::Posef::IDENTITY,
        };
        // SAFETY: both spaces belong to this session; `loc` and its chained struct outlive the call.
        let r = unsafe {
            (self.instance.fp().locate_space)(self.gaze_space.as_raw(), self.view_space.as_raw(), xr::Time::from_nanos(t), &mut loc)
        };
        if r.into_raw() < 0 {
            return GazeSample::no_gaze(t, self.sequence);
        }
        let flags = loc.location_flags;
        let valid = flags.contains(xr::SpaceLocationFlags::ORIENTATION_VALID);
        let measured = sample_time.time.as_nanos();
        let (time, time_kind) = match measured {
            0 => (t, SampleTimeKind::Unknown),
            m if m == t => (m, SampleTimeKind::Interpolated),
            m => (m, SampleTimeKind::Measured),
        };
        if time != self.last.time {
            self.sequence += 1;
        }
        if !valid {
            return GazeSample { time, time_kind, ..GazeSample::no_gaze(t, self.sequence) };
        }
        let o = loc.pose.orientation;
        let direction = (Quat::from_xyzw(o.x, o.y, o.z, o.w).normalize() * Vec3::NEG_Z).normalize();
        let origin = if flags.contains(xr::SpaceLocationFlags::POSITION_VALID) {
            Vec3::new(loc.pose.position.x, loc.pose.position.y, loc.pose.position.z)
        } else {
            Vec3::ZERO
        };
        GazeSample {
            time,
            time_kind,
            sequence: self.sequence,
            gaze: GazeRay { origin, direction },
            eyes: None,
            valid: true,
            tracked: flags.contains(xr::SpaceLocationFlags::ORIENTATION_TRACKED),
            // The extension reports no lid state: "open" is implied by a valid pose.
            eye_state: [EyeState::Open; 2],
            confidence: None,
            convergence_distance: None,
        }
    }
}

impl GazeSource for OpenXrGaze {
    fn describe(&self) -> &HmdDescription {
        &self.hmd
    }

    fn begin_frame(&mut self, predicted_display_time: XrTime) -> Result<(), HalError> {
        self.poll_events()?;
        let t = self.usable_time(predicted_display_time);
        if self.state == xr::SessionState::FOCUSED {
            call("xrSyncActions", self.session.sync_actions(&[xr::ActiveActionSet::new(&self.action_set)]))?;
        }
        if t > 0 {
            self.update_views(t);
        }
        Ok(())
    }

    fn sample_at(&mut self, t: XrTime) -> GazeSample {
        let t = self.usable_time(t);
        let s = self.locate_gaze(t);
        if s.time >= self.last.time {
            self.last = s;
        }
        s
    }

    fn latest(&self) -> GazeSample {
        self.last
    }
}
