//! SIGINT / SIGTERM as a request to stop cleanly: the binary installs the handler for commands
//! that check it (`fovea render` finishes the frame in flight, writes its report marked
//! interrupted and exits 128 + the signal). Until the command calls [`running`] (its frame loop
//! starts), a signal ends the process at once with 128 + the signal, as without a handler: start-up
//! (loading a scene, the OpenXR loader and runtime, the device) does not look at the flag, and a
//! call blocked there must not swallow the signal. A second signal while the first is pending
//! ends the process at once, so a hung run can still be stopped.
//!
//! The library never installs the handler itself: tests and other embedders keep their own
//! signal behaviour, and [`requested`] is then always `None`.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};

struct State {
    pending: Arc<AtomicBool>,
    signal: Arc<AtomicUsize>,
    /// True until [`running`]: a signal then ends the process at once.
    starting: Arc<AtomicBool>,
}

static STATE: OnceLock<State> = OnceLock::new();

/// The error a command returns after it stopped early on a signal (after writing what it had).
#[derive(Debug)]
pub struct Interrupted {
    pub signal: i32,
}

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "interrupted by {} ({}); the outputs written so far are complete",
            signal_name(self.signal),
            self.signal
        )
    }
}

impl std::error::Error for Interrupted {}

impl Interrupted {
    /// Shell convention for a process ended by a signal.
    pub fn exit_code(&self) -> u8 {
        (128 + self.signal).clamp(1, 255) as u8
    }
}

fn signal_name(signal: i32) -> &'static str {
    match signal {
        2 => "SIGINT",
        15 => "SIGTERM",
        _ => "signal",
    }
}

/// Installs the handlers (once; later calls do nothing).
#[cfg(unix)]
pub fn install() -> std::io::Result<()> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    if STATE.get().is_some() {
        return Ok(());
    }
    let state = State {
        pending: Arc::new(AtomicBool::new(false)),
        signal: Arc::new(AtomicUsize::new(0)),
        starting: Arc::new(AtomicBool::new(true)),
    };
    for sig in [SIGINT, SIGTERM] {
        signal_hook::flag::register_conditional_shutdown(
            sig,
            128 + sig,
            Arc::clone(&state.starting),
        )?;
        // Registered first, so it sees the flag as it was before this signal set it.
        signal_hook::flag::register_conditional_shutdown(
            sig,
            128 + sig,
            Arc::clone(&state.pending),
        )?;
        signal_hook::flag::register_usize(sig, Arc::clone(&state.signal), sig as usize)?;
        signal_hook::flag::register(sig, Arc::clone(&state.pending))?;
    }
    let _ = STATE.set(state);
    Ok(())
}

#[cfg(not(unix))]
pub fn install() -> std::io::Result<()> {
    Ok(())
}

/// From here on a signal asks the command to stop cleanly (it checks [`requested`]); before,
/// a signal ends the process at once.
pub fn running() {
    if let Some(state) = STATE.get() {
        state.starting.store(false, Ordering::SeqCst);
    }
}

/// The signal that asked the run to stop, if any.
pub fn requested() -> Option<Interrupted> {
    let state = STATE.get()?;
    if !state.pending.load(Ordering::SeqCst) {
        return None;
    }
    Some(Interrupted {
        signal: state.signal.load(Ordering::SeqCst) as i32,
    })
}
