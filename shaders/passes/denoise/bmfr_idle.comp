#version 460
// BMFR's per-texel state in the trace's idle tiles (renderer TileList). Its per-texel kernels run
// over the live tiles only (lavapipe runs masked-off lanes at nearly full cost); here the idle
// tiles get what those kernels write there: the history a later frame reads, the features the fit
// reads over whole blocks, the fitted colour and the output. A texel there holds no sample (all
// zeros) or one culled off the screen, which the trace leaves a miss without motion: the
// accumulation starts it afresh (zero radiance, history length 1, no surface), the weighted sum
// keeps that zero and the accumulation after the fit, without reprojection, keeps it too.
//! variants per space
#include "../../common/layouts.glsl"
#include "../../denoise/grid.glsl"
#define TILE_LIST_BINDING 30
#include "../../common/tiles.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { BmfrIdlePush p; } push;
layout(set = 0, binding = 0, rgba32f) uniform writeonly image2D noisy;             // rgb, history length
layout(set = 0, binding = 1, rgba16f) uniform writeonly image2D normal;
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D features_position; // w footprint, 0 miss
layout(set = 0, binding = 3, rgba32f) uniform writeonly image2D fitted;
layout(set = 0, binding = 4, rgba32f) uniform writeonly image2D filtered;          // history
layout(set = 0, binding = 5, rgba32f) uniform writeonly image2D dst;

void main() {
    ivec2 t = tile_list_texel(push.p.config.x);
    Grid g = grid_make(push.p.space);
    if (any(greaterThanEqual(t, g.size))) return;
    float culled = grid_holds_sample(g, t) ? 1.0 : 0.0;
    imageStore(noisy, t, vec4(0.0, 0.0, 0.0, culled));
    imageStore(normal, t, vec4(0.0));
    imageStore(features_position, t, vec4(0.0));
    imageStore(fitted, t, vec4(0.0, 0.0, 0.0, culled));
    imageStore(filtered, t, vec4(0.0, 0.0, 0.0, culled));
    imageStore(dst, t, vec4(0.0));
}
