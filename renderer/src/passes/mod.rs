//! One module per compute pass: each owns its pipeline and params struct, takes typed inputs and
//! records into a `FrameRecorder`.

pub mod accumulate;
pub mod blur;
pub mod denoise;
pub mod mip_phi;
pub mod raycast;
pub mod remap;
pub mod tonemap;
pub mod trace;

/// Bytes of a push-constant struct, as the recorder takes them.
pub(crate) fn push_bytes<T: bytemuck::Pod>(p: &T) -> &[u8] {
    bytemuck::bytes_of(p)
}
