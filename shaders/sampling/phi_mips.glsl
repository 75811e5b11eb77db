// Layout of the φ-only mip chain of a Visual-Polar image (twin of renderer/src/passes/mip_phi.rs).
// Level l halves every column's φ rows, rounding up (an odd count wraps its last pair onto row 0:
// φ is periodic), so a column with n rows keeps ceil(n / 2^l) at level l. All levels, level 0 (a
// copy of the traced image) included, are stacked in one image: level l starts at row
// 2·H' − 2·H' / 2^l, where H' is the grid height rounded up to a multiple of 2^(PHI_MIP_LEVELS−1)
// so every level's block is a whole number of rows. Closed forms on purpose: loops here cost the
// remap several times over on lavapipe.
#ifndef FOVEA_SAMPLING_PHI_MIPS_GLSL
#define FOVEA_SAMPLING_PHI_MIPS_GLSL

// φ rows a column with `rows0` traced rows has at `level`.
uint phi_mip_rows(uint rows0, uint level) {
    return (rows0 + (1u << level) - 1u) >> level;
}

// First row of `level` in the stacked image, for a grid `height` rows tall.
uint phi_mip_offset(uint level, uint height) {
    uint block = 1u << (PHI_MIP_LEVELS - 1u);
    uint padded2 = 2u * ((height + block - 1u) / block * block);
    return padded2 - (padded2 >> level);
}

#endif
