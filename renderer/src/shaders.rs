//! SPIR-V of every shader, compiled from `shaders/` by build.rs.

use crate::error::{Error, Result};

include!(concat!(env!("OUT_DIR"), "/shaders.rs"));

/// The SPIR-V words of a shader by name, e.g. `"passes/trace.cartesian"`.
pub fn spirv(name: &str) -> Result<&'static [u8]> {
    SHADERS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, bytes)| *bytes)
        .ok_or_else(|| Error::UnknownShader(name.to_string()))
}
