//! Library side of the `fovea` tools: everything the binary glues together.

pub mod scenegen;
