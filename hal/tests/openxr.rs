//! Without an OpenXR runtime (this machine, CI) the backend must fail with a clear error, not panic.
#![cfg(feature = "openxr")]

use fovea_hal::openxr::{OpenXrGaze, OpenXrRuntime};
use fovea_hal::HmdDescription;

#[test]
fn missing_runtime_is_a_clear_error() {
    if std::env::var_os("XR_RUNTIME_JSON").is_some() {
        return; // a runtime is configured: nothing to check here
    }
    match OpenXrRuntime::create("fovea test") {
        Ok(rt) => eprintln!("a runtime is installed (eye gaze supported: {})", rt.supports_eye_gaze),
        Err(e) => {
            let msg = e.to_string();
            eprintln!("{msg}");
            assert!(msg.starts_with("openxr: ") && (msg.contains("loader") || msg.contains("runtime")), "{msg}");
        }
    }
    if let Err(e) = OpenXrGaze::headless(&HmdDescription::fove0()) {
        assert!(e.to_string().starts_with("openxr: "));
    }
}
