//! GPU structs shared with GLSL, generated from `shaders/common/layouts.glsl` (the single source
//! of truth) by build.rs. `STRUCT_LAYOUTS` lists each field's Rust offset for the device test
//! that reads every field back through the GLSL layout.

/// One field of a shared struct as Rust lays it out.
#[derive(Debug)]
pub struct FieldLayout {
    pub name: &'static str,
    pub offset: usize,
    /// Size in 32-bit words.
    pub words: usize,
}

#[derive(Debug)]
pub struct StructLayout {
    pub name: &'static str,
    pub size: usize,
    pub fields: &'static [FieldLayout],
}

include!(concat!(env!("OUT_DIR"), "/layouts.rs"));

impl SamplingParams {
    /// The gaze-dependent slots, what a pass gets of the previous frame's space.
    pub fn frame(&self) -> SamplingFrame {
        SamplingFrame {
            gaze: self.gaze,
            shape0: self.shape0,
            shape1: self.shape1,
        }
    }
}
