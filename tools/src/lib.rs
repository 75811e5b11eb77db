//! Library side of the `fovea` tools: everything the binary glues together (scene resolution,
//! output writers, camera paths, commands), kept here so integration tests can call it.

pub mod binocular;
pub mod commands;
pub mod cpu_time;
pub mod density;
pub mod flip;
pub mod interrupt;
pub mod metrics;
pub mod output;
pub mod plot;
pub mod reference_sum;
pub mod render_profile;
pub mod replay;
pub mod sweep;
pub mod viewer;
pub mod xr;
