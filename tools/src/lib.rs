//! Library side of the `fovea` command line: the commands, their output folders and writers, the
//! render profiles, evaluation (metrics, density, plots), replay, sweeps, the window and the
//! headset loop, kept here so integration tests can call them. What a program embedding the
//! renderer needs lives in `fovea_stage`.

pub mod cli;
pub mod commands;
pub mod cpu_time;
pub mod eval;
pub mod interrupt;
pub mod output;
pub mod reference_sum;
pub mod render_profile;
pub mod replay;
pub mod sweep;
pub mod viewer;
pub mod xr;
