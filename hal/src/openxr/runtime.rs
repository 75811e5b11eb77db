//! The OpenXR instance and HMD system: which extensions are on, eye-gaze support, the clock.

use super::{call, check, fail};
use crate::error::HalError;
use crate::sample::XrTime;
use openxr as xr;
use std::ptr;

/// A loaded runtime: instance, HMD system and what it offers. One per process is the norm; the
/// session owner and the gaze source both borrow it.
pub struct OpenXrRuntime {
    pub instance: xr::Instance,
    pub system: xr::SystemId,
    /// `XR_EXT_eye_gaze_interaction` is enabled (the runtime offers it).
    pub has_eye_gaze_extension: bool,
    /// The system reports `supportsEyeGazeInteraction` (an eye tracker is present and usable).
    pub supports_eye_gaze: bool,
    pub has_vulkan2: bool,
    pub has_headless: bool,
    pub has_timespec: bool,
    pub has_refresh_rate: bool,
    /// `xrGetInstanceProperties`' runtime name, e.g. "Monado(XRT) by Collabora et al …".
    pub runtime_name: String,
}

impl OpenXrRuntime {
    /// Open the loader and create an instance with every extension fovea can use that the
    /// runtime offers: `XR_KHR_vulkan_enable2`, `XR_EXT_eye_gaze_interaction`, `XR_MND_headless`,
    /// `XR_KHR_convert_timespec_time`, `XR_FB_display_refresh_rate`. None is required: a
    /// runtime without eye gaze gives a gaze source that reports "no eye tracker".
    pub fn create(application_name: &str) -> Result<Self, HalError> {
        check_runtime_manifest()?;
        // SAFETY: loads the system OpenXR loader, which must follow the OpenXR specification.
        let entry = unsafe { xr::Entry::load(&()) }.map_err(|e| {
            fail(format!("cannot load the OpenXR loader (libopenxr_loader.so.1; Debian: libopenxr-loader1): {e}"))
        })?;
        let available = entry.enumerate_extensions().map_err(|e| {
            fail(format!("no OpenXR runtime is installed or active (XR_RUNTIME_JSON / active_runtime.json): {e}"))
        })?;
        let wanted = wanted_extensions(&available);
        let instance = call(
            "xrCreateInstance",
            entry.create_instance(&app_info(application_name), &wanted, &[], &()),
        )?;
        let system = call(
            "xrGetSystem(HEAD_MOUNTED_DISPLAY)",
            instance.system(xr::FormFactor::HEAD_MOUNTED_DISPLAY),
        )?;
        let supports_eye_gaze =
            wanted.ext_eye_gaze_interaction && query_eye_gaze_support(&instance, system)?;
        let runtime_name = instance
            .properties()
            .map(|p| p.runtime_name)
            .unwrap_or_default();
        Ok(OpenXrRuntime {
            instance,
            system,
            has_eye_gaze_extension: wanted.ext_eye_gaze_interaction,
            supports_eye_gaze,
            has_vulkan2: wanted.khr_vulkan_enable2,
            has_headless: wanted.mnd_headless,
            has_timespec: wanted.khr_convert_timespec_time,
            has_refresh_rate: wanted.fb_display_refresh_rate,
            runtime_name,
        })
    }

    /// Why there is no eye tracker, or `None` when there is one (one line, for a notice).
    pub fn missing_eye_tracker(&self) -> Option<String> {
        if !self.has_eye_gaze_extension {
            return Some("the OpenXR runtime does not offer XR_EXT_eye_gaze_interaction".into());
        }
        if !self.supports_eye_gaze {
            return Some(
                "the OpenXR system reports supportsEyeGazeInteraction = false (no eye tracker, no permission, or uncalibrated)"
                    .into(),
            );
        }
        None
    }

    /// The runtime's clock now (`XR_KHR_convert_timespec_time`).
    pub fn now(&self) -> Result<XrTime, HalError> {
        self.monotonic_to_time(monotonic_now_ns())
    }

    /// CLOCK_MONOTONIC nanoseconds → `XrTime` (`xrConvertTimespecTimeToTimeKHR`).
    pub fn monotonic_to_time(&self, monotonic_ns: i64) -> Result<XrTime, HalError> {
        let ext = self.timespec_ext()?;
        let ts = libc::timespec {
            tv_sec: monotonic_ns.div_euclid(1_000_000_000),
            tv_nsec: monotonic_ns.rem_euclid(1_000_000_000),
        };
        let mut out = xr::Time::from_nanos(0);
        // SAFETY: valid instance; both pointers point to live locals.
        check("xrConvertTimespecTimeToTimeKHR", unsafe {
            (ext.convert_timespec_time_to_time)(self.instance.as_raw(), &ts, &mut out)
        })?;
        Ok(out.as_nanos())
    }

    /// `XrTime` → CLOCK_MONOTONIC nanoseconds (`xrConvertTimeToTimespecTimeKHR`).
    pub fn time_to_monotonic(&self, time: XrTime) -> Result<i64, HalError> {
        let ext = self.timespec_ext()?;
        let mut ts = libc::timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        // SAFETY: valid instance; `ts` outlives the call.
        check("xrConvertTimeToTimespecTimeKHR", unsafe {
            (ext.convert_time_to_timespec_time)(
                self.instance.as_raw(),
                xr::Time::from_nanos(time),
                &mut ts,
            )
        })?;
        Ok(ts.tv_sec * 1_000_000_000 + ts.tv_nsec)
    }

    fn timespec_ext(&self) -> Result<&xr::raw::ConvertTimespecTimeKHR, HalError> {
        self.instance
            .exts()
            .khr_convert_timespec_time
            .as_ref()
            .ok_or_else(|| {
                fail("the runtime lacks XR_KHR_convert_timespec_time: no way to read its clock")
            })
    }
}

/// The largest runtime manifest fovea lets the loader read (real ones are under 1 KiB).
pub const MAX_RUNTIME_MANIFEST_BYTES: u64 = 64 << 10;

/// The runtime manifest the loader is about to read (`XR_RUNTIME_JSON`, else the first
/// `openxr/1/active_runtime.json` of the XDG config folders and /etc), checked as a regular file
/// of at most [`MAX_RUNTIME_MANIFEST_BYTES`]: the loader reads it whole and blocks on a FIFO
/// (`/dev/zero` took 13.7 GB). Only its metadata is read here, so nothing blocks.
pub fn check_runtime_manifest() -> Result<(), HalError> {
    use std::path::PathBuf;
    let env = |k: &str| std::env::var_os(k).filter(|v| !v.is_empty());
    let (candidates, named): (Vec<PathBuf>, &str) = match env("XR_RUNTIME_JSON") {
        Some(p) => (vec![PathBuf::from(p)], "XR_RUNTIME_JSON"),
        None => {
            let mut dirs: Vec<PathBuf> = Vec::new();
            if let Some(c) = env("XDG_CONFIG_HOME") {
                dirs.push(c.into());
            } else if let Some(h) = env("HOME") {
                dirs.push(PathBuf::from(h).join(".config"));
            }
            let xdg = env("XDG_CONFIG_DIRS").unwrap_or_else(|| "/etc/xdg".into());
            dirs.extend(std::env::split_paths(&xdg));
            dirs.push("/etc".into());
            let files = dirs
                .into_iter()
                .map(|d| d.join("openxr/1/active_runtime.json"))
                .filter(|p| std::fs::symlink_metadata(p).is_ok())
                .take(1)
                .collect();
            (files, "the active OpenXR runtime")
        }
    };
    for path in candidates {
        let meta = std::fs::metadata(&path)
            .map_err(|e| fail(format!("{named} {}: {e}", path.display())))?;
        if !meta.is_file() {
            return Err(fail(format!(
                "{named} {}: it is {}, not a regular file (the OpenXR loader would block on it or read without end)",
                path.display(),
                crate::file::file_kind(&meta.file_type())
            )));
        }
        if meta.len() > MAX_RUNTIME_MANIFEST_BYTES {
            return Err(fail(format!(
                "{named} {}: {} bytes, more than the {MAX_RUNTIME_MANIFEST_BYTES}-byte limit for a runtime manifest",
                path.display(),
                meta.len()
            )));
        }
    }
    Ok(())
}

fn wanted_extensions(available: &xr::ExtensionSet) -> xr::ExtensionSet {
    let mut wanted = xr::ExtensionSet::default();
    wanted.khr_vulkan_enable2 = available.khr_vulkan_enable2;
    wanted.ext_eye_gaze_interaction = available.ext_eye_gaze_interaction;
    wanted.mnd_headless = available.mnd_headless;
    wanted.khr_convert_timespec_time = available.khr_convert_timespec_time;
    wanted.fb_display_refresh_rate = available.fb_display_refresh_rate;
    wanted
}

fn app_info(application_name: &str) -> xr::ApplicationInfo<'_> {
    // OpenXR caps the name at 128 bytes; 100 characters of UTF-8 may exceed that, so cut by bytes.
    let mut end = application_name.len().min(100);
    while !application_name.is_char_boundary(end) {
        end -= 1;
    }
    xr::ApplicationInfo {
        application_name: &application_name[..end],
        application_version: 0,
        engine_name: "fovea",
        engine_version: 0,
        // Debian 12 ships loader 1.0.20, which refuses 1.1.
        api_version: xr::Version::new(1, 0, 0),
    }
}

fn monotonic_now_ns() -> i64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid out pointer; CLOCK_MONOTONIC always exists on Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    ts.tv_sec * 1_000_000_000 + ts.tv_nsec
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
    check("xrGetSystemProperties", unsafe {
        (instance.fp().get_system_properties)(instance.as_raw(), system, &mut props)
    })?;
    Ok(eye.supports_eye_gaze_interaction.into())
}
