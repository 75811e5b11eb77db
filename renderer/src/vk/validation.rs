//! Validation-layer messages: counted by severity so tests can fail on any warning or error.

use ash::vk;
use std::ffi::CStr;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Mutex;

/// Counts of validation/debug messages by severity, plus the text of the worst ones.
#[derive(Default)]
pub struct ValidationCounter {
    pub errors: AtomicU32,
    pub warnings: AtomicU32,
    pub infos: AtomicU32,
    messages: Mutex<Vec<String>>,
}

impl ValidationCounter {
    /// Warnings plus errors: what a clean run must keep at zero.
    pub fn problems(&self) -> u32 {
        self.errors.load(Ordering::SeqCst) + self.warnings.load(Ordering::SeqCst)
    }

    /// The warning/error texts seen so far (for test failure messages).
    pub fn messages(&self) -> Vec<String> {
        self.messages.lock().map(|m| m.clone()).unwrap_or_default()
    }

    fn record(&self, severity: vk::DebugUtilsMessageSeverityFlagsEXT, text: String) {
        if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
            self.errors.fetch_add(1, Ordering::SeqCst);
        } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING) {
            self.warnings.fetch_add(1, Ordering::SeqCst);
        } else {
            self.infos.fetch_add(1, Ordering::SeqCst);
            return;
        }
        eprintln!("[vulkan validation] {text}");
        if let Ok(mut m) = self.messages.lock() {
            m.push(text);
        }
    }
}

/// Message ids we deliberately ignore, each with its reason. Empty: nothing is suppressed.
const SUPPRESSED_VUIDS: &[(&str, &str)] = &[];

pub unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut std::ffi::c_void,
) -> vk::Bool32 {
    if data.is_null() || user.is_null() {
        return vk::FALSE;
    }
    let data = &*data;
    let id = if data.p_message_id_name.is_null() {
        String::new()
    } else {
        CStr::from_ptr(data.p_message_id_name)
            .to_string_lossy()
            .into_owned()
    };
    if SUPPRESSED_VUIDS.iter().any(|(vuid, _why)| id == *vuid) {
        return vk::FALSE;
    }
    let message = if data.p_message.is_null() {
        String::new()
    } else {
        CStr::from_ptr(data.p_message)
            .to_string_lossy()
            .into_owned()
    };
    let counter = &*(user as *const ValidationCounter);
    counter.record(severity, format!("{id}: {message}"));
    vk::FALSE
}
