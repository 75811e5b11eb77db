#version 460
// SVGF's state in the trace's idle tiles (renderer TileList). SVGF's kernels run over the live
// tiles only (lavapipe runs masked-off lanes at nearly full cost); here the idle tiles get what
// those kernels would write there that a later frame reads: this frame's moments and surfaces and
// the colour history (à-trous iteration 0's output). A texel there holds no sample or one culled
// off the screen, which the temporal pass starts afresh (a miss: zero colour, history length 1).
// Their other images are read there only by edge-stopped taps, whose weight is 0 for a texel
// without a surface.
//! variants per space
#include "../../common/layouts.glsl"
#include "../../denoise/grid.glsl"
#include "../../denoise/svgf.glsl"
#define TILE_LIST_BINDING 30
#include "../../common/tiles.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { SvgfIdlePush p; } push;
layout(set = 0, binding = 0, rgba32f) uniform writeonly image2D moments;       // m1, m2, history length
layout(set = 0, binding = 1, rgba32ui) uniform writeonly uimage2D surface;
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D history_color; // colour, variance

void main() {
    ivec2 t = tile_list_texel(push.p.config.x);
    Grid g = grid_make(push.p.space);
    if (any(greaterThanEqual(t, g.size))) return;
    bool culled = grid_holds_sample(g, t);
    imageStore(moments, t, vec4(0.0, 0.0, culled ? 1.0 : 0.0, 0.0));
    imageStore(surface, t, culled ? svgf_pack_surface(svgf_surface(vec4(0.0), 0.0, uvec2(0u))) : uvec4(0u));
    imageStore(history_color, t, vec4(0.0));
}
