// Layout of the φ-only mip chain of a Visual-Polar image (twin of renderer/src/passes/mip_phi.rs).
// Level 0 is the traced image. Level l ≥ 1 halves every column's φ rows (rounding up: an odd
// count wraps its last pair onto row 0, φ being periodic) and is stored in one stacked image,
// level l starting at row phi_mip_offset(l). Columns keep their own row counts (the fovea clip).
#ifndef FOVEA_SAMPLING_PHI_MIPS_GLSL
#define FOVEA_SAMPLING_PHI_MIPS_GLSL

// φ rows a column with `rows0` traced rows has at `level`.
uint phi_mip_rows(uint rows0, uint level) {
    uint m = rows0;
    for (uint i = 0u; i < level; ++i) m = (m + 1u) / 2u;
    return m;
}

// First row of `level` (≥ 1) in the stacked image, for a grid `height` rows tall.
uint phi_mip_offset(uint level, uint height) {
    uint offset = 0u;
    uint h = height;
    for (uint i = 1u; i < level; ++i) {
        h = (h + 1u) / 2u;
        offset += h;
    }
    return offset;
}

#endif
