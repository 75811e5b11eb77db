//! What a program embedding the fovea renderer needs around it, without the command line: a
//! scene by name or path (the generated Cornell box, stress and large scenes included), lit and
//! framed the way every `fovea` command sees it (the default sun and sky, environment maps, the
//! scene's camera or one that frames it), the headset's eye rig, camera paths and keyframes,
//! gaze sources (recorded traces, the simulated tracker) timed to frames, bounded image reading,
//! and files written whole or not at all.
//!
//! `examples/render_frame.rs` renders one foveated frame with this crate and the renderer alone.

pub mod camera_keys;
pub mod camera_path;
pub mod decode;
pub mod env_map;
pub mod files;
pub mod gaze;
pub mod look;
pub mod projection;
pub mod scenegen;
pub mod scenes;
pub mod sky_model;
