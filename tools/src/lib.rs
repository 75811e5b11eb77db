//! Library side of the `fovea` tools: everything the binary glues together (scene resolution,
//! output writers, camera paths, commands), kept here so integration tests can call it.

pub mod binocular;
pub mod camera_keys;
pub mod camera_path;
pub mod commands;
pub mod cpu_time;
pub mod decode;
pub mod density;
pub mod env_map;
pub mod flip;
pub mod gaze;
pub mod interrupt;
pub mod look;
pub mod metrics;
pub mod output;
pub mod plot;
pub mod projection;
pub mod reference_sum;
pub mod render_profile;
pub mod replay;
pub mod scenegen;
pub mod scenes;
pub mod sky_model;
pub mod sweep;
pub mod viewer;
pub mod xr;
