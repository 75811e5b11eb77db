// Dispatch over a list of workgroup tiles (SamplingSpace::trace_tiles; renderer TileList): the
// buffer holds this frame's live tiles then its idle ones, each x | y << 16 in tiles of
// WORKGROUP_2D² texels, one workgroup of that size each. lavapipe runs masked-off lanes at nearly the cost of live ones, even where a
// whole workgroup returns on its first line, so kernels run over the tiles that hold work instead
// of the whole grid. The including kernel defines TILE_LIST_BINDING (bound by name: `tiles`).
#ifndef FOVEA_COMMON_TILES_GLSL
#define FOVEA_COMMON_TILES_GLSL

layout(std430, set = 0, binding = TILE_LIST_BINDING) readonly buffer TileList { uint data[]; } tiles;

// (WORKGROUP_2D, not gl_WorkGroupSize: glslang takes the latter as 1 before the kernel's
// local_size declaration, which comes after its includes.)
// The first texel of this workgroup's tile: entry `first` + the workgroup's index of the list.
uvec2 tile_list_origin(uint first) {
    uint tile = tiles.data[first + gl_WorkGroupID.x];
    return uvec2(tile & 0xffffu, tile >> 16u) * WORKGROUP_2D;
}

// This invocation's texel in its tile (row-major lanes).
ivec2 tile_list_texel(uint first) {
    return ivec2(tile_list_origin(first) + gl_LocalInvocationID.xy);
}

#endif
