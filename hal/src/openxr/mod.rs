//! OpenXR backend (cargo feature `openxr`).
//!
//! - [`OpenXrRuntime`]: loader, instance (with `XR_KHR_vulkan_enable2`, `XR_EXT_eye_gaze_interaction`,
//!   `XR_MND_headless`, `XR_KHR_convert_timespec_time`, `XR_FB_display_refresh_rate` when offered),
//!   system, clock, and Vulkan instance/device creation through the runtime.
//! - [`SessionOwner`]: the one owner of a session (headless or Vulkan): the only event loop,
//!   begin/end on state changes, the one action-set attach, frame calls, clean exit.
//! - [`OpenXrGaze`]: a [`crate::GazeSource`] that borrows the owner's state and attach.
//!
//! The loader is opened at run time (`loaded` mode), so binaries run on machines without it and
//! report a clear error instead. API version 1.0 is requested (Debian 12 ships loader 1.0.20).

mod gaze;
mod runtime;
mod session;
mod vulkan;

pub use gaze::{GazeActions, OpenXrGaze};
/// The `openxr` crate this backend is built on, so callers name the same types.
pub use openxr as xr;
pub use runtime::OpenXrRuntime;
pub use session::{
    ExitHandle, RuntimeFigures, SessionEnd, SessionOwner, SessionStateHandle, SessionStatus,
    VulkanBinding, STORAGE_FORMATS,
};

use crate::error::HalError;

const BACKEND: &str = "openxr";

pub(crate) fn fail(reason: impl Into<String>) -> HalError {
    HalError::Backend {
        backend: BACKEND,
        reason: reason.into(),
    }
}

pub(crate) fn call<T>(what: &str, r: Result<T, openxr::sys::Result>) -> Result<T, HalError> {
    r.map_err(|e| fail(format!("{what} failed: {e}")))
}

/// A raw call's result code: negative codes are errors.
pub(crate) fn check(what: &str, r: openxr::sys::Result) -> Result<(), HalError> {
    if r.into_raw() < 0 {
        Err(fail(format!("{what} failed: {r}")))
    } else {
        Ok(())
    }
}
