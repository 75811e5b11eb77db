//! The OpenXR backend against a real runtime: Monado built by `scripts/build-monado` with
//! fovea's simulated eye tracker (scripts/monado/0002-simulated-eye-tracker.patch), whose gaze is
//! a known function of CLOCK_MONOTONIC time (`expected` below mirrors the patch's formula).
//!
//! Without a runtime these tests print why and pass, unless FOVEA_REQUIRE_OPENXR is set
//! (scripts/test sets it), in which case they fail. One runtime instance at a time: every test
//! holds `LOCK` (Monado runs in-process, and some tests switch environment variables).
#![cfg(feature = "openxr")]

use fovea_hal::openxr::{
    xr, GazeActions, OpenXrGaze, OpenXrRuntime, SessionEnd, SessionOwner, VulkanBinding,
    STORAGE_FORMATS,
};
use fovea_hal::{
    GazeOrigin, GazeSource, HmdDescription, InvalidGazePolicy, SampleTimeKind, XrTime,
};
use glam::Vec3;
use std::io::Write;
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

static LOCK: Mutex<()> = Mutex::new(());

const MS: i64 = 1_000_000;
const PERIOD: i64 = 10 * MS; // the simulated tracker's 100 Hz
const CYCLE: i64 = 5_000 * MS; // blink and degraded windows repeat every 5 s

/// The patch's gaze at monotonic measurement time `s`: (direction, valid, tracked).
fn expected(s: i64) -> (Vec3, bool, bool) {
    let phase = |p: i64| (s % p) as f64 / p as f64;
    let az = 20f64.to_radians() * (std::f64::consts::TAU * phase(2_000 * MS)).sin();
    let el = 10f64.to_radians() * (std::f64::consts::TAU * phase(3_000 * MS)).sin();
    let in_cycle = s % CYCLE;
    let blink = (4_000 * MS..4_200 * MS).contains(&in_cycle);
    let degraded = (3_000 * MS..3_500 * MS).contains(&in_cycle);
    let dir = Vec3::new(
        (az.sin() * el.cos()) as f32,
        el.sin() as f32,
        (-az.cos() * el.cos()) as f32,
    );
    (dir, !blink, !blink && !degraded)
}

/// Start of the next 5-s cycle on the monotonic clock, plus `offset_ms` (a tick time). The next
/// one, because the current one may have begun before the instance (negative XrTime).
fn cycle_time(rt: &OpenXrRuntime, offset_ms: i64) -> i64 {
    let now = rt.time_to_monotonic(rt.now().unwrap()).unwrap();
    now - now % CYCLE + CYCLE + offset_ms * MS
}

/// Sleep until the next `span_ms` of real time hold no blink, so live-gaze counts do not depend
/// on when the test happens to run.
fn wait_clear_of_blink(rt: &OpenXrRuntime, span_ms: i64) {
    let blink = 4_000 * MS..4_200 * MS;
    loop {
        let now = rt.time_to_monotonic(rt.now().unwrap()).unwrap() % CYCLE;
        let end = now + span_ms * MS;
        let hits = |b: i64| now < b + blink.end && blink.start + b < end;
        if !hits(0) && !hits(-CYCLE) && !hits(CYCLE) {
            return;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn xr_time(rt: &OpenXrRuntime, monotonic: i64) -> XrTime {
    rt.monotonic_to_time(monotonic).unwrap()
}

/// atan2(|a×b|, a·b) in f64: acos of an f32 dot product cannot resolve angles below ~0.02°.
fn angle_deg(a: Vec3, b: Vec3) -> f32 {
    let (a, b) = (a.as_dvec3(), b.as_dvec3());
    a.cross(b).length().atan2(a.dot(b)).to_degrees() as f32
}

/// The lock, with Monado's test settings, when a runtime is configured; `None` (after saying
/// why) when there is none and none is required.
fn runtime_env() -> Option<MutexGuard<'static, ()>> {
    let guard = LOCK.lock().unwrap_or_else(|p| p.into_inner());
    let json = std::env::var_os("XR_RUNTIME_JSON");
    let present = json
        .as_ref()
        .is_some_and(|p| std::path::Path::new(p).is_file());
    if !present {
        let why = match json {
            Some(p) => format!("XR_RUNTIME_JSON={} does not exist", p.to_string_lossy()),
            None => "XR_RUNTIME_JSON is not set".into(),
        };
        assert!(
            std::env::var_os("FOVEA_REQUIRE_OPENXR").is_none(),
            "FOVEA_REQUIRE_OPENXR is set but there is no runtime: {why} (eval \"$(scripts/build-monado --print-env)\")"
        );
        // Straight to stderr: the harness captures eprintln!, and a skip should be seen.
        let _ = writeln!(
            std::io::stderr(),
            "skipped: no OpenXR runtime ({why}); scripts/test builds Monado and runs these tests"
        );
        return None;
    }
    // No display here; the simulated builder is the one with the eye tracker.
    std::env::set_var("XRT_COMPOSITOR_NULL", "1");
    std::env::set_var("SIMULATED_ENABLE", "1");
    std::env::set_var("SIMULATED_EYE_TRACKER", "on");
    if std::env::var_os("XRT_LOG").is_none() {
        std::env::set_var("XRT_LOG", "warning"); // Monado's info log is pages per instance
    }
    Some(guard)
}

/// Poll `owner` until `done(status)` or 5 s pass.
fn poll_until<G: xr::Graphics>(
    owner: &mut SessionOwner<G>,
    mut on_event: impl FnMut(&xr::Event<'_>),
    done: impl Fn(&fovea_hal::openxr::SessionStatus) -> bool,
) -> fovea_hal::openxr::SessionStatus {
    let deadline = Instant::now() + Duration::from_secs(5);
    loop {
        let status = owner.poll_events_with(&mut on_event).expect("poll_events");
        if done(&status) || Instant::now() > deadline {
            return status;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// A "renderer-owned" headless session with the gaze set attached, polled until focused.
fn focused_owner(rt: &OpenXrRuntime) -> (SessionOwner<xr::Headless>, OpenXrGaze) {
    let mut owner = SessionOwner::headless(rt).expect("headless session");
    let actions = GazeActions::new(rt).unwrap();
    owner
        .attach_action_sets(&actions.action_set().into_iter().collect::<Vec<_>>())
        .unwrap();
    let gaze = OpenXrGaze::new(rt, &owner, actions, &HmdDescription::fove0()).unwrap();
    let status = poll_until(&mut owner, |_| {}, |s| s.focused());
    assert!(
        status.focused(),
        "the session never got focused: {status:?}"
    );
    (owner, gaze)
}

#[test]
fn missing_runtime_is_a_clear_error() {
    let _lock = LOCK.lock().unwrap_or_else(|p| p.into_inner());
    let saved = std::env::var_os("XR_RUNTIME_JSON");
    std::env::set_var("XR_RUNTIME_JSON", "/nonexistent/fovea-no-runtime.json");
    let err = OpenXrRuntime::create("fovea test")
        .err()
        .map(|e| e.to_string());
    let headless = OpenXrGaze::headless(&HmdDescription::fove0())
        .err()
        .map(|e| e.to_string());
    match saved {
        Some(v) => std::env::set_var("XR_RUNTIME_JSON", v),
        None => std::env::remove_var("XR_RUNTIME_JSON"),
    }
    for msg in [err, headless] {
        let msg = msg.expect("a missing runtime must be an error");
        assert!(
            msg.starts_with("openxr: ") && (msg.contains("loader") || msg.contains("runtime")),
            "{msg}"
        );
    }
}

/// Begin/end run on state changes only: run after every event, the InteractionProfileChanged
/// Monado queues after READY would call xrBeginSession twice (XR_ERROR_SESSION_RUNNING).
#[test]
fn begin_runs_once_with_interaction_profile_changed_queued() {
    let Some(_env) = runtime_env() else { return };
    let rt = OpenXrRuntime::create("fovea test").unwrap();
    let mut owner = SessionOwner::headless(&rt).unwrap();
    let actions = GazeActions::new(&rt).unwrap();
    owner
        .attach_action_sets(&actions.action_set().into_iter().collect::<Vec<_>>())
        .unwrap();
    let mut profile_changes = 0;
    let mut count = |e: &xr::Event<'_>| {
        if matches!(e, xr::Event::InteractionProfileChanged(_)) {
            profile_changes += 1;
        }
    };
    let status = poll_until(&mut owner, &mut count, |s| s.focused());
    for _ in 0..20 {
        owner.poll_events_with(&mut count).unwrap();
    }
    let status2 = owner.status();
    let no_frames = owner.wait_frame().unwrap_err().to_string();
    assert!(no_frames.contains("no frame loop"), "{no_frames}");
    assert!(
        status.focused() && status2.running,
        "{status:?} {status2:?}"
    );
    assert!(
        profile_changes >= 1,
        "the runtime queued no InteractionProfileChanged: the test proves nothing"
    );
    assert_eq!(
        (status2.begins, status2.ends),
        (1, 0),
        "xrBeginSession must run exactly once"
    );
}

/// A self-managed (headless) source's begin_frame succeeds from the first frame on (a second
/// xrBeginSession would fail with SESSION_RUNNING).
#[test]
fn headless_source_begin_frame_succeeds_every_frame() {
    let Some(_env) = runtime_env() else { return };
    let mut gaze = OpenXrGaze::headless(&HmdDescription::fove0()).unwrap();
    let deadline = Instant::now() + Duration::from_secs(5);
    let mut valid = 0;
    let mut frames = 0;
    while Instant::now() < deadline && valid < 20 {
        gaze.begin_frame(0)
            .unwrap_or_else(|e| panic!("begin_frame {frames}: {e}"));
        valid += gaze.sample_at(0).valid as usize;
        frames += 1;
        std::thread::sleep(Duration::from_millis(10));
    }
    let status = gaze.own_session().unwrap().status();
    assert_eq!(status.begins, 1, "{status:?}");
    assert!(valid >= 20, "only {valid} valid samples in {frames} frames");
}

/// A source on a renderer-owned session reads the owner's state instead of polling the event
/// queue itself (which would swallow the renderer's events, or never see FOCUSED: 100/100
/// invalid).
#[test]
fn renderer_owned_session_gives_valid_gaze_with_state_passed_in() {
    let Some(_env) = runtime_env() else { return };
    let rt = OpenXrRuntime::create("fovea test").unwrap();
    let mut owner = SessionOwner::headless(&rt).unwrap();
    let actions = GazeActions::new(&rt).unwrap();
    owner
        .attach_action_sets(&actions.action_set().into_iter().collect::<Vec<_>>())
        .unwrap();
    let mut gaze = OpenXrGaze::new(&rt, &owner, actions, &HmdDescription::fove0()).unwrap();
    // The source runs first: it must not eat the renderer's state events.
    for _ in 0..5 {
        gaze.begin_frame(rt.now().unwrap()).unwrap();
    }
    let status = poll_until(&mut owner, |_| {}, |s| s.focused());
    assert!(
        status.focused() && status.begins == 1,
        "the owner missed its state events: {status:?}"
    );
    wait_clear_of_blink(&rt, 1_000);
    let (mut valid, mut expected_valid) = (0, 0);
    for _ in 0..100 {
        owner.poll_events().unwrap();
        let t = rt.now().unwrap();
        gaze.begin_frame(t).unwrap();
        let s = gaze.sample_at(t);
        valid += s.valid as usize;
        let mono = rt.time_to_monotonic(t).unwrap();
        expected_valid += expected(mono - mono % PERIOD).1 as usize;
        std::thread::sleep(Duration::from_millis(2));
    }
    assert!(
        gaze.own_syncs() >= 100,
        "xrSyncActions ran {} times in 100 frames",
        gaze.own_syncs()
    );
    assert!(
        expected_valid >= 90 && valid == expected_valid,
        "{valid} valid samples, expected {expected_valid}"
    );
}

/// Action sets attach once per session: the renderer's set and the gaze set go in one attach,
/// and one full sync per frame (the owner's) serves both.
#[test]
fn renderer_and_gaze_share_one_attach_and_one_sync() {
    let Some(_env) = runtime_env() else { return };
    let rt = OpenXrRuntime::create("fovea test").unwrap();
    let mut owner = SessionOwner::headless(&rt).unwrap();
    let renderer_set = rt
        .instance
        .create_action_set("renderer", "renderer", 0)
        .unwrap();
    let _button = renderer_set
        .create_action::<bool>("exit", "Exit", &[])
        .unwrap();
    let actions = GazeActions::new(&rt).unwrap();
    let mut sets = vec![&renderer_set];
    sets.extend(actions.action_set());
    owner.attach_action_sets(&sets).unwrap();
    let again = owner
        .attach_action_sets(&[&renderer_set])
        .unwrap_err()
        .to_string();
    assert!(again.contains("one attach per session"), "{again}");
    let mut gaze = OpenXrGaze::new(&rt, &owner, actions, &HmdDescription::fove0()).unwrap();
    assert!(poll_until(&mut owner, |_| {}, |s| s.focused()).focused());
    wait_clear_of_blink(&rt, 500);
    let mut valid = 0;
    for _ in 0..20 {
        owner.poll_events().unwrap();
        owner.sync_actions().unwrap();
        let t = rt.now().unwrap();
        gaze.begin_frame(t).unwrap();
        valid += gaze.latest().valid as usize;
        std::thread::sleep(Duration::from_millis(2));
    }
    assert_eq!(
        (owner.status().syncs, gaze.own_syncs()),
        (20, 0),
        "one sync per frame, the owner's"
    );
    assert_eq!(
        valid, 20,
        "gaze valid in {valid} of 20 frames after the owner's syncs"
    );
}

/// A gaze set the owner never attached is refused with the fix in the message.
#[test]
fn gaze_set_must_be_in_the_owners_attach() {
    let Some(_env) = runtime_env() else { return };
    let rt = OpenXrRuntime::create("fovea test").unwrap();
    let owner = SessionOwner::headless(&rt).unwrap();
    let actions = GazeActions::new(&rt).unwrap();
    let err = OpenXrGaze::new(&rt, &owner, actions, &HmdDescription::fove0())
        .err()
        .expect("unattached gaze set")
        .to_string();
    assert!(err.contains("attach_action_sets"), "{err}");
}

/// XR_KHR_vulkan_enable2: the renderer's Vulkan instance and device are created through the
/// runtime, a Vulkan session runs frames, and gaze works on it.
#[test]
fn vulkan_session_through_the_runtime() {
    let Some(_env) = runtime_env() else { return };
    let rt = OpenXrRuntime::create("fovea test").unwrap();
    assert!(
        rt.has_vulkan2 && rt.instance.exts().khr_vulkan_enable2.is_some(),
        "XR_KHR_vulkan_enable2 is not enabled"
    );
    let vk = vulkan::Objects::create(&rt);
    // SAFETY: the handles were created through this runtime and outlive the owner (dropped first).
    let mut owner = unsafe { SessionOwner::vulkan(&rt, vk.binding) }.expect("Vulkan session");
    let actions = GazeActions::new(&rt).unwrap();
    owner
        .attach_action_sets(&actions.action_set().into_iter().collect::<Vec<_>>())
        .unwrap();
    let mut gaze = OpenXrGaze::new(&rt, &owner, actions, &HmdDescription::fove0()).unwrap();
    let figures = gaze.runtime_figures();
    let hz = gaze.describe().refresh_hz;
    eprintln!("Vulkan session: {figures:?}, {hz} Hz");
    assert!(figures.refresh == rt.has_refresh_rate, "{figures:?}");
    if figures.refresh {
        assert_eq!(hz, owner.session().get_display_refresh_rate().unwrap());
    }
    let stage = owner
        .create_reference_space(xr::ReferenceSpaceType::LOCAL)
        .unwrap();
    let format = *owner
        .swapchain_formats()
        .unwrap()
        .iter()
        .find(|f| STORAGE_FORMATS.contains(f))
        .expect("a UNORM storage format");
    let size = gaze
        .describe()
        .eyes
        .map(|e| (e.recommended_width, e.recommended_height));
    let mut swapchains: Vec<_> = size
        .iter()
        .map(|&(w, h)| owner.create_storage_swapchain(format, w, h).unwrap())
        .collect();
    assert!(swapchains
        .iter()
        .all(|s| !s.enumerate_images().unwrap().is_empty()));
    wait_clear_of_blink(&rt, 2_000);
    let mut last_time = 0;
    let (mut frames, mut valid, mut focused) = (0, 0, 0);
    let deadline = Instant::now() + Duration::from_secs(10);
    while frames < 8 && Instant::now() < deadline {
        let status = owner.poll_events().unwrap();
        if !status.running {
            std::thread::sleep(Duration::from_millis(5));
            continue;
        }
        let frame = owner.wait_frame().unwrap();
        owner.begin_frame().unwrap();
        let t = frame.predicted_display_time.as_nanos();
        assert!(
            t > last_time,
            "predicted display times must increase: {last_time} then {t}"
        );
        last_time = t;
        gaze.begin_frame(t).unwrap();
        valid += gaze.latest().valid as usize;
        focused += status.focused() as usize; // the first frames run before FOCUSED
        let (flags, views) = owner.locate_views(t, &stage).unwrap();
        assert!(flags.contains(xr::ViewStateFlags::ORIENTATION_VALID) && views.len() == 2);
        // Per swapchain: acquire → wait → (render) → release; one projection view per located view.
        for sc in &mut swapchains {
            sc.acquire_image().unwrap();
            sc.wait_image(xr::Duration::INFINITE).unwrap();
            sc.release_image().unwrap();
        }
        let projection: Vec<_> = views
            .iter()
            .zip(&swapchains)
            .zip(size)
            .map(|((v, sc), (w, h))| {
                let rect = xr::Rect2Di {
                    offset: xr::Offset2Di { x: 0, y: 0 },
                    extent: xr::Extent2Di {
                        width: w as i32,
                        height: h as i32,
                    },
                };
                xr::CompositionLayerProjectionView::new()
                    .pose(v.pose)
                    .fov(v.fov)
                    .sub_image(xr::SwapchainSubImage::new().swapchain(sc).image_rect(rect))
            })
            .collect();
        let layer = xr::CompositionLayerProjection::new()
            .space(&stage)
            .views(&projection);
        owner.end_frame(t, &[&layer]).unwrap();
        frames += 1;
    }
    assert_eq!(
        frames,
        8,
        "the Vulkan session did not run 8 frames in 10 s: {:?}",
        owner.status()
    );
    assert!(
        focused >= 5 && valid == focused,
        "gaze valid in {valid} of 8 Vulkan frames, {focused} of them focused"
    );
    drop((gaze, swapchains, stage, owner));
    vk.destroy();
}

/// A runtime without XR_EXT_eye_gaze_interaction support is accepted (gaze at the centre).
#[test]
fn runtime_without_eye_tracker_runs_with_centre_fallback() {
    let Some(_env) = runtime_env() else { return };
    std::env::set_var("SIMULATED_EYE_TRACKER", "off");
    let rt = OpenXrRuntime::create("fovea test").expect("a runtime without eye gaze is accepted");
    assert!(!rt.supports_eye_gaze && rt.missing_eye_tracker().is_some());
    assert!(GazeActions::new(&rt).unwrap().action_set().is_none());
    drop(rt);
    let mut gaze =
        OpenXrGaze::headless(&HmdDescription::fove0()).expect("headless gaze without a tracker");
    std::env::set_var("SIMULATED_EYE_TRACKER", "on");
    assert!(!gaze.has_eye_tracker() && !gaze.describe().capabilities.eye_gaze);
    let notice = gaze.fallback_notice().expect("a notice for the user");
    assert!(
        !notice.contains('\n') && notice.contains("no eye tracker"),
        "{notice}"
    );
    let mut policy = InvalidGazePolicy::new(250.0);
    let deadline = Instant::now() + Duration::from_secs(2);
    while !gaze.own_session().unwrap().status().focused() && Instant::now() < deadline {
        gaze.begin_frame(0).unwrap();
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(
        gaze.own_session().unwrap().status().focused(),
        "the session runs without an eye tracker"
    );
    for _ in 0..10 {
        gaze.begin_frame(0).unwrap();
        let s = gaze.sample_at(0);
        let r = policy.resolve(&s, s.time);
        assert!(
            !s.valid && r.source == GazeOrigin::Centre && r.direction == Vec3::NEG_Z,
            "{s:?} {r:?}"
        );
    }
}

/// A sample measured exactly at the query time is labelled `Measured`, not `Interpolated`.
#[test]
fn sample_at_a_measurement_time_is_measured() {
    let Some(_env) = runtime_env() else { return };
    let rt = OpenXrRuntime::create("fovea test").unwrap();
    let (_owner, mut gaze) = focused_owner(&rt);
    gaze.begin_frame(rt.now().unwrap()).unwrap();
    let tick = cycle_time(&rt, 1_000); // nominal part of the cycle
    let exact = gaze.sample_at(xr_time(&rt, tick));
    assert!(exact.valid, "{exact:?}");
    assert_eq!(
        (exact.time, exact.time_kind),
        (xr_time(&rt, tick), SampleTimeKind::Measured)
    );
    let between = gaze.sample_at(xr_time(&rt, tick + 3 * MS));
    assert_eq!(
        (between.time, between.time_kind),
        (xr_time(&rt, tick), SampleTimeKind::Measured),
        "newest measurement before the query"
    );
}

/// Sequence numbers never go backwards for older queries, stay the same for the same
/// measurement, and invalid samples do not bump them.
#[test]
fn sequence_numbers_are_stable_monotone_and_skip_invalid() {
    let Some(_env) = runtime_env() else { return };
    let rt = OpenXrRuntime::create("fovea test").unwrap();
    let (_owner, mut gaze) = focused_owner(&rt);
    gaze.begin_frame(rt.now().unwrap()).unwrap();
    let at = |ms: i64| xr_time(&rt, cycle_time(&rt, ms));
    let (t1, t2, t3) = (at(1_000), at(1_010), at(1_020));
    let n: Vec<u64> = [t1, t2, t3]
        .iter()
        .map(|&t| gaze.sample_at(t).sequence)
        .collect();
    assert!(n[0] < n[1] && n[1] < n[2], "{n:?}");
    assert_eq!(
        gaze.sample_at(t1).sequence,
        n[0],
        "older query, same measurement"
    );
    assert_eq!(
        gaze.sample_at(t2 + 4 * MS).sequence,
        n[1],
        "same measurement later in its period"
    );
    let blink = gaze.sample_at(at(4_100));
    assert!(
        !blink.valid && blink.sequence == n[2],
        "invalid samples carry the current number: {blink:?}"
    );
    let next = gaze.sample_at(at(4_500));
    assert_eq!(next.sequence, n[2] + 1, "the blink took no number");
    let late = gaze.sample_at(at(1_015));
    assert!(
        late.sequence >= n[1] && late.sequence <= n[2],
        "an older measurement keeps the order: {}",
        late.sequence
    );
}

/// The description (id, refresh, FOV) comes from the runtime before the first frame, not from
/// the fove0 fallback.
#[test]
fn describe_comes_from_the_runtime_before_any_frame() {
    let Some(_env) = runtime_env() else { return };
    let rt = OpenXrRuntime::create("fovea test").unwrap();
    let mut owner = SessionOwner::headless(&rt).unwrap();
    let actions = GazeActions::new(&rt).unwrap();
    owner
        .attach_action_sets(&actions.action_set().into_iter().collect::<Vec<_>>())
        .unwrap();
    let base = HmdDescription::fove0();
    let gaze = OpenXrGaze::new(&rt, &owner, actions, &base).unwrap();
    let hmd = gaze.describe();
    let figures = gaze.runtime_figures();
    let deg = |f: fovea_hal::Fov| {
        [f.angle_left, f.angle_right, f.angle_down, f.angle_up].map(f32::to_degrees)
    };
    eprintln!(
        "runtime: {} | {} {}×{} FOV {:?} offsets {:?} {} Hz | {figures:?}",
        rt.runtime_name,
        hmd.id,
        hmd.eyes[0].recommended_width,
        hmd.eyes[0].recommended_height,
        deg(hmd.eyes[0].fov),
        hmd.eyes.map(|e| e.offset.x),
        hmd.refresh_hz
    );
    let props = rt.instance.system_properties(rt.system).unwrap();
    assert!(
        hmd.id.starts_with("openxr-") && hmd.id != base.id,
        "id {}",
        hmd.id
    );
    assert!(
        hmd.display_name.contains(&props.system_name),
        "{}",
        hmd.display_name
    );
    let views = rt
        .instance
        .enumerate_view_configuration_views(rt.system, xr::ViewConfigurationType::PRIMARY_STEREO)
        .unwrap();
    for (eye, v) in hmd.eyes.iter().zip(&views) {
        assert_eq!(
            (eye.recommended_width, eye.recommended_height),
            (
                v.recommended_image_rect_width,
                v.recommended_image_rect_height
            )
        );
    }
    let view_space = owner
        .create_reference_space(xr::ReferenceSpaceType::VIEW)
        .unwrap();
    let (_, located) = owner.locate_views(rt.now().unwrap(), &view_space).unwrap();
    for (eye, v) in hmd.eyes.iter().zip(&located) {
        assert_eq!(
            (
                eye.fov.angle_left,
                eye.fov.angle_right,
                eye.fov.angle_down,
                eye.fov.angle_up
            ),
            (
                v.fov.angle_left,
                v.fov.angle_right,
                v.fov.angle_down,
                v.fov.angle_up
            )
        );
    }
    assert!(
        figures.name && figures.recommended_size && figures.fov,
        "{figures:?}"
    );
    assert_ne!(hmd.eyes[0].fov, base.eyes[0].fov, "FOV still the TOML's");
    // A headless session has no display: the refresh rate stays the TOML's (the Vulkan test
    // checks the runtime's).
    assert!(
        !figures.refresh && hmd.refresh_hz == base.refresh_hz,
        "{} Hz",
        hmd.refresh_hz
    );
    assert_eq!(
        hmd.tracker, base.tracker,
        "tracker figures are the TOML's (OpenXR reports none)"
    );
    assert!(hmd.capabilities.eye_gaze);
}

/// latest() is refreshed by begin_frame, not only by sample_at.
#[test]
fn latest_is_refreshed_by_begin_frame() {
    let Some(_env) = runtime_env() else { return };
    let rt = OpenXrRuntime::create("fovea test").unwrap();
    let (_owner, mut gaze) = focused_owner(&rt);
    let first = cycle_time(&rt, 1_000);
    gaze.begin_frame(xr_time(&rt, first + 5 * MS)).unwrap();
    let a = gaze.latest();
    assert!(a.valid && a.time == xr_time(&rt, first), "{a:?}");
    gaze.begin_frame(xr_time(&rt, first + 105 * MS)).unwrap();
    let b = gaze.latest();
    assert!(
        b.valid && b.time == xr_time(&rt, first + 100 * MS) && b.sequence > a.sequence,
        "{b:?}"
    );
}

/// End to end: the gaze over one whole 5-s cycle matches the patch's pattern, blinks are invalid
/// (and the policy holds, then centres), degraded samples are valid but untracked.
#[test]
fn gaze_follows_the_simulated_pattern_with_blinks_and_degraded_samples() {
    let Some(_env) = runtime_env() else { return };
    let rt = OpenXrRuntime::create("fovea test").unwrap();
    let (_owner, mut gaze) = focused_owner(&rt);
    gaze.begin_frame(rt.now().unwrap()).unwrap();
    let start = cycle_time(&rt, 0);
    let mut policy = InvalidGazePolicy::new(100.0);
    let (mut worst, mut blinks, mut degraded, mut held, mut centred) = (0f32, 0, 0, 0, 0);
    for i in 0..(CYCLE / (7 * MS)) {
        let query = start + i * 7 * MS; // 7 ms steps: every phase of the 10-ms period
        let s_mono = query - query % PERIOD;
        let (dir, valid, tracked) = expected(s_mono);
        let t = xr_time(&rt, query);
        let s = gaze.sample_at(t);
        let r = policy.resolve(&s, t);
        assert_eq!(
            (s.valid, s.tracked),
            (valid, tracked),
            "at {} ms of the cycle",
            (query - start) / MS
        );
        if !valid {
            blinks += 1;
            match r.source {
                GazeOrigin::Held => held += 1,
                GazeOrigin::Centre => centred += 1,
                GazeOrigin::Live => panic!("an invalid sample resolved live"),
            }
            continue;
        }
        degraded += (!tracked) as usize;
        assert_eq!(
            (s.time, s.time_kind),
            (xr_time(&rt, s_mono), SampleTimeKind::Measured)
        );
        assert_eq!(r.source, GazeOrigin::Live);
        worst = worst.max(angle_deg(s.gaze.direction, dir));
    }
    eprintln!("worst angle {worst:.5}°, {blinks} blink samples ({held} held, {centred} centred), {degraded} degraded");
    assert!(worst < 0.01, "gaze off the pattern by {worst}°");
    assert!(blinks > 20 && held > 5 && centred > 5 && degraded > 50);
}

/// Ctrl-C path: an exit request ends the session through STOPPING → EXITING.
#[test]
fn exit_request_ends_the_session_cleanly() {
    let Some(_env) = runtime_env() else { return };
    let rt = OpenXrRuntime::create("fovea test").unwrap();
    let (mut owner, _gaze) = focused_owner(&rt);
    owner.exit_handle().request();
    let status = poll_until(&mut owner, |_| {}, |s| s.end.is_some());
    assert_eq!(status.end, Some(SessionEnd::Exiting), "{status:?}");
    assert_eq!(
        (status.begins, status.ends, status.running),
        (1, 1, false),
        "{status:?}"
    );
}

/// Vulkan instance and device created through the runtime (what the renderer will do with its
/// own create-infos).
mod vulkan {
    use super::*;
    use ash::vk::{self, Handle};
    use std::ffi::c_void;

    pub struct Objects {
        _entry: ash::Entry,
        instance: ash::Instance,
        device: ash::Device,
        pub binding: VulkanBinding,
    }

    impl Objects {
        pub fn create(rt: &OpenXrRuntime) -> Objects {
            // SAFETY: loads the system Vulkan loader.
            let entry = unsafe { ash::Entry::load() }.expect("Vulkan loader (libvulkan1)");
            // SAFETY: same signature; OpenXR's binding types the Vulkan pointers as void.
            let gipa: xr::sys::platform::VkGetInstanceProcAddr =
                unsafe { std::mem::transmute(entry.static_fn().get_instance_proc_addr) };
            let req = rt.vulkan_requirements().unwrap();
            let min = req.min_api_version_supported;
            let version = if (min.major(), min.minor()) > (1, 1) {
                vk::make_api_version(0, u32::from(min.major()), u32::from(min.minor()), 0)
            } else {
                vk::API_VERSION_1_1
            };
            let app = vk::ApplicationInfo::default().api_version(version);
            let ci = vk::InstanceCreateInfo::default().application_info(&app);
            // SAFETY: `ci` and `app` live across the call.
            let raw = unsafe { rt.create_vulkan_instance(gipa, &ci as *const _ as *const c_void) }
                .unwrap();
            // SAFETY: a live instance from the runtime.
            let instance = unsafe {
                ash::Instance::load(entry.static_fn(), vk::Instance::from_raw(raw as u64))
            };
            let physical = unsafe { rt.vulkan_physical_device(raw) }.unwrap();
            let pd = vk::PhysicalDevice::from_raw(physical as u64);
            let families = unsafe { instance.get_physical_device_queue_family_properties(pd) };
            let family = families
                .iter()
                .position(|f| f.queue_flags.contains(vk::QueueFlags::GRAPHICS))
                .expect("a graphics queue") as u32;
            let priorities = [1.0f32];
            let queues = [vk::DeviceQueueCreateInfo::default()
                .queue_family_index(family)
                .queue_priorities(&priorities)];
            let dci = vk::DeviceCreateInfo::default().queue_create_infos(&queues);
            // SAFETY: `dci` and what it points to live across the call.
            let raw_device = unsafe {
                rt.create_vulkan_device(gipa, physical, &dci as *const _ as *const c_void)
            }
            .unwrap();
            let device = unsafe {
                ash::Device::load(instance.fp_v1_0(), vk::Device::from_raw(raw_device as u64))
            };
            let binding = VulkanBinding {
                instance: raw,
                physical_device: physical,
                device: raw_device,
                queue_family_index: family,
                queue_index: 0,
            };
            Objects {
                _entry: entry,
                instance,
                device,
                binding,
            }
        }

        pub fn destroy(self) {
            // SAFETY: the session using them is gone; nothing else holds them.
            unsafe {
                self.device.destroy_device(None);
                self.instance.destroy_instance(None);
            }
        }
    }
}
