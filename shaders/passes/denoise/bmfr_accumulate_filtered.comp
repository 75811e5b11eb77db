#version 460
// BMFR temporal accumulation after the fit (Koskela et al. 2019, §4): the fitted colour blended
// with its reprojected history — the same taps as the accumulation before the fit — with
// α = max(1/n, α_floor), n the history length that accumulation counted; then re-modulated by
// albedo, the denoiser's output. Texels without a sample have albedo 0 and stay 0.
//! variants per space
#include "../../common/layouts.glsl"

// The live tiles of the trace (bmfr_idle.comp writes the idle ones).
#define TILE_LIST_BINDING 30
#include "../../common/tiles.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { BmfrTemporalPush p; } push;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D fitted;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D normal_depth;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D position;       // camera-relative
layout(set = 0, binding = 3, rg32f) uniform readonly image2D motion;           // previous screen position (−1: none)
layout(set = 0, binding = 4, rgba32f) uniform readonly image2D noisy;          // w: history length
layout(set = 0, binding = 5, rgba16f) uniform readonly image2D prev_normal;
layout(set = 0, binding = 6, rgba32f) uniform readonly image2D prev_position;  // xyz, w footprint (0: miss)
layout(set = 0, binding = 7, rgba32f) uniform readonly image2D prev_filtered;
layout(set = 0, binding = 8, rgba16f) uniform readonly image2D albedo;
layout(set = 0, binding = 9, rgba32f) uniform writeonly image2D filtered;     // history
layout(set = 0, binding = 10, rgba32f) uniform writeonly image2D dst;
layout(set = 0, binding = 11, rgba32f) uniform readonly image2D features_position; // this frame's: w footprint, < 0 emitter, 0 miss

#define BMFR_REPROJECT
#include "../../denoise/bmfr.glsl"

void main() {
    ivec2 t = tile_list_texel(0u);
    Grid g = grid_make(push.p.space);
    if (any(greaterThanEqual(t, g.size))) return;
    vec4 a = imageLoad(albedo, t);
    if (!grid_holds_sample(g, t)) {
        imageStore(filtered, t, vec4(0.0));
        imageStore(dst, t, vec4(0.0, 0.0, 0.0, a.a));
        return;
    }
    vec3 c = imageLoad(fitted, t).rgb;
    vec4 nd = imageLoad(normal_depth, t);
    vec4 pw = imageLoad(position, t);
    bool hit = nd.w > 0.0;
    float alpha_floor = push.p.params.w;
    Grid prev = grid_make(push.p.space, push.p.prev);
    ivec2 taps[4];
    vec4 w;
    float kind = imageLoad(features_position, t).w;
    float tolerance = bmfr_tolerance(abs(kind), nd.w);
    if (alpha_floor < 1.0 && bmfr_reproject(prev, imageLoad(motion, t).xy, hit ? pw.xyz : vec3(0.0), nd.xyz, kind,
                                            tolerance, push.p.params.xyz, taps, w)) {
        vec3 h = vec3(0.0);
        for (int i = 0; i < 4; ++i) {
            if (w[i] > 0.0) h += w[i] * imageLoad(prev_filtered, taps[i]).rgb;
        }
        h /= w.x + w.y + w.z + w.w;
        float len = imageLoad(noisy, t).w;
        c = mix(h, c, max(1.0 / len, alpha_floor));
    }
    imageStore(filtered, t, vec4(c, 1.0));
    imageStore(dst, t, vec4(c * a.rgb, a.a));
}
