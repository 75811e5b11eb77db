#version 460
// BMFR weighted sum: each texel evaluates its own block's fit on its features (without the fit's
// regularisation noise), clamped ≥ 0. Texels without a hit keep their accumulated noisy radiance
// (they took no part in any fit); texels without a sample get zeros.
//! variants per space
#include "../../common/layouts.glsl"
#include "../../denoise/bmfr.glsl"

// The live tiles of the trace (bmfr_idle.comp writes the idle ones).
#define TILE_LIST_BINDING 30
#include "../../common/tiles.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { BmfrBlockPush p; } push;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D noisy;               // accumulated rgb
layout(set = 0, binding = 1, rgba16f) uniform readonly image2D normal;              // accumulated
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D features_position;   // xyz, w footprint (0: miss)
layout(set = 0, binding = 3, rgba32f) uniform readonly image2D weights;
layout(set = 0, binding = 4, rgba32f) uniform writeonly image2D fitted;

void main() {
    ivec2 t = tile_list_texel(0u);
    Grid g = grid_make(push.p.space);
    if (any(greaterThanEqual(t, g.size))) return;
    if (!grid_holds_sample(g, t)) {
        imageStore(fitted, t, vec4(0.0));
        return;
    }
    vec4 p = imageLoad(features_position, t);
    vec3 c = imageLoad(noisy, t).rgb;
    if (p.w > 0.0) {
        ivec2 block, slot;
        bmfr_block_of(g, t, 16 - push.p.config.xy, block, slot);
        ivec2 base = ivec2(block.x * int(BMFR_WEIGHT_TEXELS), block.y);
        float f[10];
        bmfr_features(imageLoad(normal, t).xyz, p.xyz, imageLoad(weights, base + ivec2(10, 0)).xyz,
                      imageLoad(weights, base + ivec2(11, 0)).xyz, f);
        c = vec3(0.0);
        for (int k = 0; k < 10; ++k) c += f[k] * imageLoad(weights, base + ivec2(k, 0)).rgb;
    }
    c = any(isnan(c)) || any(isinf(c)) ? vec3(0.0) : max(c, vec3(0.0));
    imageStore(fitted, t, vec4(c, 1.0));
}
