//! The reservoir buffers the resampling passes bind (a leaf: the passes and their parent import
//! it).

use crate::vk::Buffer;

/// One reservoir per grid texel (`ReservoirGpu` for DI, `GiReservoirGpu` for GI), twice, in turn:
/// each frame the first pass reads last frame's reservoirs from one buffer (`history`) and writes
/// this frame's into the other (`fresh`), which the spatial pass reads and next frame's first pass
/// reads as its history. The spatial pass's combination shades this frame only: fed back as
/// history, it makes neighbouring texels' reservoirs share samples, and those correlated inputs
/// bias the means (docs/design/resampling.md#bias).
pub struct ReservoirPair {
    buffers: [Buffer; 2],
}

impl ReservoirPair {
    pub fn new(buffers: [Buffer; 2]) -> ReservoirPair {
        ReservoirPair { buffers }
    }

    /// (history, fresh) of the `frame`-th recorded frame.
    pub fn for_frame(&self, frame: u64) -> (&Buffer, &Buffer) {
        let fresh = (frame % 2) as usize;
        (&self.buffers[1 - fresh], &self.buffers[fresh])
    }

    /// GPU bytes of both buffers.
    pub fn bytes(&self) -> u64 {
        self.buffers.iter().map(|b| b.size).sum()
    }
}
