//! The reservoir buffers both resampling passes bind (a leaf: the passes and their parent import
//! it).

use crate::vk::Buffer;

/// One reservoir (`ReservoirGpu`) per grid texel, twice: `history` holds last frame's final
/// reservoirs until the first pass has read them (the second pass then writes this frame's there),
/// `fresh` the first pass's output that the second reads.
pub struct Reservoirs {
    pub history: Buffer,
    pub fresh: Buffer,
}

/// ReSTIR GI's reservoirs (`GiReservoirGpu` per grid texel), used as [`Reservoirs`]' are.
pub struct GiReservoirs {
    pub history: Buffer,
    pub fresh: Buffer,
}
