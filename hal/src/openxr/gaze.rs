//! Gaze from `XR_EXT_eye_gaze_interaction` on a session someone else owns (the renderer's
//! [`SessionOwner`]) or on a headless one of its own.
//!
//! Pose action on `/user/eyes_ext/input/gaze_ext/pose` → action space → located in VIEW space at
//! the requested time through a raw `xrLocateSpace`, because the crate's `Space::locate` cannot
//! chain `XrEyeGazeSampleTimeEXT` (the real sample time).

use super::session::{apply_views, sync_sets};
use super::{call, fail, OpenXrRuntime, RuntimeFigures, SessionOwner, SessionStateHandle};
use crate::error::HalError;
use crate::hmd::HmdDescription;
use crate::sample::{EyeState, GazeRay, GazeSample, SampleTimeKind, XrTime};
use crate::source::GazeSource;
use glam::{Quat, Vec3};
use openxr as xr;
use std::collections::VecDeque;
use std::ptr;

const EYE_GAZE_PROFILE: &str = "/interaction_profiles/ext/eye_gaze_interaction";
const EYE_GAZE_POSE: &str = "/user/eyes_ext/input/gaze_ext/pose";

/// The gaze action set, created before the session's one attach so the renderer can attach it
/// together with its own sets ([`SessionOwner::attach_action_sets`]). Without an eye tracker it
/// holds no action set and the gaze source reports "no eye tracker".
pub struct GazeActions {
    actions: Option<(xr::ActionSet, xr::Action<xr::Posef>)>,
    missing: Option<String>,
}

impl GazeActions {
    pub fn new(rt: &OpenXrRuntime) -> Result<Self, HalError> {
        if let Some(why) = rt.missing_eye_tracker() {
            return Ok(GazeActions {
                actions: None,
                missing: Some(why),
            });
        }
        let instance = &rt.instance;
        let set = call(
            "xrCreateActionSet",
            instance.create_action_set("fovea_gaze", "fovea gaze", 0),
        )?;
        let action = call(
            "xrCreateAction",
            set.create_action::<xr::Posef>("gaze", "Eye gaze", &[]),
        )?;
        let profile = call("xrStringToPath", instance.string_to_path(EYE_GAZE_PROFILE))?;
        let pose = call("xrStringToPath", instance.string_to_path(EYE_GAZE_POSE))?;
        call(
            "xrSuggestInteractionProfileBindings(eye gaze)",
            instance
                .suggest_interaction_profile_bindings(profile, &[xr::Binding::new(&action, pose)]),
        )?;
        Ok(GazeActions {
            actions: Some((set, action)),
            missing: None,
        })
    }

    /// The set to attach, `None` without an eye tracker.
    pub fn action_set(&self) -> Option<&xr::ActionSet> {
        self.actions.as_ref().map(|(set, _)| set)
    }
}

/// Located gaze: its space, and every set of the session's one attach (synced together).
struct Tracker {
    attached: Vec<xr::ActionSet>,
    gaze_space: xr::Space,
}

/// Gaze source on an OpenXR session. It never polls events: it reads the owner's state through a
/// [`SessionStateHandle`]. A headless source made by [`OpenXrGaze::headless`] owns its session
/// and polls that owner in `begin_frame`.
pub struct OpenXrGaze {
    hmd: HmdDescription,
    figures: RuntimeFigures,
    instance: xr::Instance,
    session: xr::Session<xr::AnyGraphics>,
    view_space: xr::Space,
    tracker: Option<Tracker>,
    missing: Option<String>,
    state: SessionStateHandle,
    has_timespec: bool,
    own: Option<SessionOwner<xr::Headless>>,
    numbers: Sequencer,
    last: GazeSample,
    /// The owner's sync count at the last `begin_frame`.
    owner_syncs: u64,
    /// `xrSyncActions` calls this source made itself (frames where the owner did not sync).
    syncs: u64,
}

impl OpenXrGaze {
    /// Gaze on `owner`'s session. `actions` must have been attached by `owner` (one attach per
    /// session, shared with the renderer's sets). The description is `base` merged with what the
    /// runtime reports (see [`SessionOwner::describe`]).
    pub fn new<G: xr::Graphics>(
        rt: &OpenXrRuntime,
        owner: &SessionOwner<G>,
        actions: GazeActions,
        base: &HmdDescription,
    ) -> Result<Self, HalError> {
        let session = owner.session().clone().into_any_graphics();
        let tracker = match actions.actions {
            Some((set, action)) => {
                if !owner.is_attached(&set) {
                    return Err(fail(
                        "the gaze action set is not attached to the session: pass GazeActions::action_set() to \
                         SessionOwner::attach_action_sets together with the renderer's sets",
                    ));
                }
                let gaze_space = call(
                    "xrCreateActionSpace(gaze)",
                    action.create_space(&session, xr::Path::NULL, xr::Posef::IDENTITY),
                )?;
                Some(Tracker {
                    attached: owner.attached_sets().to_vec(),
                    gaze_space,
                })
            }
            None => None,
        };
        let view_space = call(
            "xrCreateReferenceSpace(VIEW)",
            session.create_reference_space(xr::ReferenceSpaceType::VIEW, xr::Posef::IDENTITY),
        )?;
        let (hmd, figures) = owner.describe(base, tracker.is_some())?;
        Ok(OpenXrGaze {
            hmd,
            figures,
            instance: rt.instance.clone(),
            session,
            view_space,
            tracker,
            missing: actions.missing,
            state: owner.state_handle(),
            has_timespec: rt.has_timespec,
            own: None,
            numbers: Sequencer::default(),
            last: GazeSample::no_gaze(0, 0),
            owner_syncs: 0,
            syncs: 0,
        })
    }

    /// Own runtime + headless session (`XR_MND_headless`), begun and ended by this source: gaze
    /// without rendering through OpenXR.
    pub fn headless(base: &HmdDescription) -> Result<Self, HalError> {
        let rt = OpenXrRuntime::create("fovea gaze")?;
        let mut owner = SessionOwner::headless(&rt)?;
        let actions = GazeActions::new(&rt)?;
        owner.attach_action_sets(&actions.action_set().into_iter().collect::<Vec<_>>())?;
        let mut gaze = OpenXrGaze::new(&rt, &owner, actions, base)?;
        gaze.own = Some(owner);
        Ok(gaze)
    }

    /// False when the runtime has no usable eye tracker: every sample is invalid, so the
    /// invalid-gaze policy falls back to the view centre.
    pub fn has_eye_tracker(&self) -> bool {
        self.tracker.is_some()
    }

    /// One line for the user when there is no eye tracker, `None` when there is one.
    pub fn fallback_notice(&self) -> Option<String> {
        self.missing
            .as_ref()
            .map(|why| format!("no eye tracker: {why}; the fovea stays at the view centre"))
    }

    /// Which figures of `describe()` the runtime reported.
    pub fn runtime_figures(&self) -> RuntimeFigures {
        self.figures
    }

    /// How often this source called `xrSyncActions` itself (frames where the owner did not).
    pub fn own_syncs(&self) -> u64 {
        self.syncs
    }

    /// The owner of a headless source's own session (for its status and exit handle).
    pub fn own_session(&self) -> Option<&SessionOwner<xr::Headless>> {
        self.own.as_ref()
    }

    /// Display time 0 (headless sessions have no frame loop) means "now" on the runtime clock.
    fn usable_time(&self, t: XrTime) -> XrTime {
        if t != 0 || !self.has_timespec {
            return t;
        }
        self.instance.now().map(|n| n.as_nanos()).unwrap_or(t)
    }

    fn update_views(&mut self, t: XrTime) {
        let located = self.session.locate_views(
            xr::ViewConfigurationType::PRIMARY_STEREO,
            xr::Time::from_nanos(t),
            &self.view_space,
        );
        if let Ok((flags, views)) = located {
            if apply_views(&mut self.hmd, flags, &views) {
                self.figures.fov = true;
                self.figures.offsets |= flags.contains(xr::ViewStateFlags::POSITION_VALID);
            }
        }
    }

    /// One raw `xrLocateSpace` with `XrEyeGazeSampleTimeEXT` chained.
    fn locate_raw(&self, tracker: &Tracker, t: XrTime) -> Option<(xr::sys::SpaceLocation, XrTime)> {
        let mut sample_time = xr::sys::EyeGazeSampleTimeEXT {
            ty: xr::sys::EyeGazeSampleTimeEXT::TYPE,
            next: ptr::null_mut(),
            time: xr::Time::from_nanos(0),
        };
        let mut loc = xr::sys::SpaceLocation {
            ty: xr::sys::SpaceLocation::TYPE,
            next: &mut sample_time as *mut _ as *mut _,
            location_flags: xr::SpaceLocationFlags::EMPTY,
            pose: xr::Posef::IDENTITY,
        };
        // SAFETY: both spaces belong to this session; `loc` and its chained struct outlive the call.
        let r = unsafe {
            (self.instance.fp().locate_space)(
                tracker.gaze_space.as_raw(),
                self.view_space.as_raw(),
                xr::Time::from_nanos(t),
                &mut loc,
            )
        };
        (r.into_raw() >= 0).then_some((loc, sample_time.time.as_nanos()))
    }

    fn locate_gaze(&mut self, t: XrTime) -> GazeSample {
        let Some(tracker) = self.tracker.as_ref().filter(|_| self.state.get().focused()) else {
            return GazeSample::no_gaze(t, self.numbers.current());
        };
        let Some((loc, measured)) = self.locate_raw(tracker, t) else {
            return GazeSample::no_gaze(t, self.numbers.current());
        };
        let flags = loc.location_flags;
        if !flags.contains(xr::SpaceLocationFlags::ORIENTATION_VALID) {
            // Blink or lost tracking: no measurement, so no new number.
            return GazeSample::no_gaze(t, self.numbers.current());
        }
        let (time, time_kind) = label_time(t, measured);
        let o = loc.pose.orientation;
        let direction = (Quat::from_xyzw(o.x, o.y, o.z, o.w).normalize() * Vec3::NEG_Z).normalize();
        let origin = if flags.contains(xr::SpaceLocationFlags::POSITION_VALID) {
            Vec3::new(
                loc.pose.position.x,
                loc.pose.position.y,
                loc.pose.position.z,
            )
        } else {
            Vec3::ZERO
        };
        let sequence = self.numbers.number(measured, direction);
        GazeSample {
            time,
            time_kind,
            sequence,
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

    fn remember(&mut self, s: GazeSample) {
        if s.time >= self.last.time {
            self.last = s;
        }
    }

    /// Sync all attached sets unless the owner already did since the last frame.
    fn sync(&mut self) -> Result<(), HalError> {
        let status = self.state.get();
        let owner_synced = status.syncs != self.owner_syncs;
        self.owner_syncs = status.syncs;
        let Some(tracker) = self
            .tracker
            .as_ref()
            .filter(|_| status.running && !owner_synced)
        else {
            return Ok(());
        };
        sync_sets(&self.session, &tracker.attached)?;
        self.syncs += 1;
        Ok(())
    }
}

/// How a located sample's time is labelled: the runtime's sample time when it gives one (a
/// measurement at exactly the query time is still a measurement), else the query time, unknown.
pub(crate) fn label_time(query: XrTime, measured: XrTime) -> (XrTime, SampleTimeKind) {
    if measured > 0 {
        (measured, SampleTimeKind::Measured)
    } else {
        (query, SampleTimeKind::Unknown)
    }
}

/// Sequence numbers for tracker measurements: the same measurement always gets the same number,
/// numbers grow with measurement time, and invalid samples carry the current number without
/// taking a new one. Measurements are identified by their sample time; without one (runtime
/// reports 0) by the direction's bits.
#[derive(Default)]
pub(crate) struct Sequencer {
    /// (measurement time, number), ascending in both; the last `HISTORY` measurements.
    seen: VecDeque<(XrTime, u64)>,
    /// For runtimes without sample times: the last direction and its number.
    untimed: Option<([u32; 3], u64)>,
    newest: u64,
}

const HISTORY: usize = 512;

impl Sequencer {
    /// The newest number handed out (0 before any measurement).
    pub(crate) fn current(&self) -> u64 {
        self.newest
    }

    pub(crate) fn number(&mut self, measured: XrTime, direction: Vec3) -> u64 {
        if measured <= 0 {
            return self.number_untimed(direction);
        }
        let at = self.seen.partition_point(|&(t, _)| t < measured);
        if let Some(&(t, n)) = self.seen.get(at) {
            if t == measured {
                return n;
            }
        }
        if at == self.seen.len() {
            self.newest += 1;
            self.seen.push_back((measured, self.newest));
            if self.seen.len() > HISTORY {
                self.seen.pop_front();
            }
            return self.newest;
        }
        // An older measurement seen only now: numbers are taken, so it shares its predecessor's
        // (keeps the order; remembered so it stays the same on the next query).
        let n = if at == 0 {
            self.seen[0].1
        } else {
            self.seen[at - 1].1
        };
        self.seen.insert(at, (measured, n));
        if self.seen.len() > HISTORY {
            self.seen.pop_front();
        }
        n
    }

    fn number_untimed(&mut self, direction: Vec3) -> u64 {
        let bits = direction.to_array().map(f32::to_bits);
        match self.untimed {
            Some((b, n)) if b == bits => n,
            _ => {
                self.newest += 1;
                self.untimed = Some((bits, self.newest));
                self.newest
            }
        }
    }
}

impl GazeSource for OpenXrGaze {
    fn describe(&self) -> &HmdDescription {
        &self.hmd
    }

    /// Polls the own session (headless source only), syncs the gaze action set, refreshes the
    /// per-eye views and `latest()` for `predicted_display_time`.
    fn begin_frame(&mut self, predicted_display_time: XrTime) -> Result<(), HalError> {
        if let Some(owner) = self.own.as_mut() {
            let status = owner.poll_events()?;
            if let Some(end) = status.end {
                return Err(fail(format!("the headless OpenXR session ended ({end:?})")));
            }
        }
        self.sync()?;
        let t = self.usable_time(predicted_display_time);
        if t != 0 {
            self.update_views(t);
            let s = self.locate_gaze(t);
            self.remember(s);
        }
        Ok(())
    }

    fn sample_at(&mut self, t: XrTime) -> GazeSample {
        let t = self.usable_time(t);
        let s = self.locate_gaze(t);
        self.remember(s);
        s
    }

    fn latest(&self) -> GazeSample {
        self.last
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_time_sample_is_measured() {
        assert_eq!(label_time(1000, 1000), (1000, SampleTimeKind::Measured));
        assert_eq!(label_time(1000, 990), (990, SampleTimeKind::Measured));
        assert_eq!(label_time(1000, 0), (1000, SampleTimeKind::Unknown));
    }

    #[test]
    fn numbers_are_stable_and_monotone() {
        let d = Vec3::NEG_Z;
        let mut s = Sequencer::default();
        assert_eq!(s.current(), 0);
        let a = s.number(100, d);
        let b = s.number(200, d);
        let c = s.number(300, d);
        assert!(a < b && b < c);
        assert_eq!(
            (s.number(100, d), s.number(200, d), s.number(300, d)),
            (a, b, c),
            "same measurement, same number"
        );
        let late = s.number(150, d);
        assert!(
            a <= late && late <= b,
            "an older measurement seen late keeps the order: {a} ≤ {late} ≤ {b}"
        );
        assert_eq!(s.number(150, d), late);
        assert_eq!(s.current(), c, "older measurements take no new number");
    }

    #[test]
    fn untimed_measurements_are_told_apart_by_direction() {
        let mut s = Sequencer::default();
        let a = s.number(0, Vec3::NEG_Z);
        assert_eq!(s.number(0, Vec3::NEG_Z), a);
        assert_eq!(s.number(0, Vec3::new(0.0, 0.6, -0.8)), a + 1);
    }
}
