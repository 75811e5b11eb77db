#version 460
// BMFR temporal accumulation before the fit (Koskela et al. 2019, §4): the noisy demodulated
// radiance and the features (normal, camera-relative position) blended with their reprojected
// history, α = max(1/n, α_floor) for history length n (this frame included). Writes this frame's
// half of the history; texels without a sample get zeros.
//! variants per space
#include "../../common/layouts.glsl"

// The live tiles of the trace (bmfr_idle.comp writes the idle ones).
#define TILE_LIST_BINDING 30
#include "../../common/tiles.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { BmfrTemporalPush p; } push;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D radiance;       // demodulated
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D normal_depth;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D position;       // camera-relative
layout(set = 0, binding = 3, rg32f) uniform readonly image2D motion;           // previous screen position (−1: none)
layout(set = 0, binding = 4, rgba32f) uniform readonly image2D prev_noisy;     // rgb, history length
layout(set = 0, binding = 5, rgba16f) uniform readonly image2D prev_normal;
layout(set = 0, binding = 6, rgba32f) uniform readonly image2D prev_position;  // xyz, w footprint (0: miss)
layout(set = 0, binding = 7, rgba32f) uniform writeonly image2D noisy;
layout(set = 0, binding = 8, rgba16f) uniform writeonly image2D normal;
layout(set = 0, binding = 9, rgba32f) uniform writeonly image2D features_position; // w footprint, < 0 emitter, 0 miss
layout(set = 0, binding = 10, rg32ui) uniform readonly uimage2D ids;           // y: material | mesh << 16
layout(std430, set = 0, binding = 11) readonly buffer MaterialBuffer { MaterialGpu data[]; } materials;

#define BMFR_REPROJECT
#include "../../denoise/bmfr.glsl"
#include "../../denoise/svgf.glsl"

// World size of texel t: distance to the nearer neighbour along each grid axis (the other
// side may be another surface), the larger of the two axes; 0 without neighbours.
float footprint(Grid g, ivec2 t, vec3 p) {
    float size = 0.0;
    for (int axis = 0; axis < 2; ++axis) {
        float nearest = 3.0e38;
        for (int side = -1; side <= 1; side += 2) {
            ivec2 q;
            ivec2 o = axis == 0 ? ivec2(side, 0) : ivec2(0, side);
            if (grid_tap(g, t, o, q) && grid_holds_sample(g, q)) nearest = min(nearest, distance(imageLoad(position, q).xyz, p));
        }
        size = nearest < 3.0e38 ? max(size, nearest) : size;
    }
    return size;
}

void main() {
    ivec2 t = tile_list_texel(0u);
    Grid g = grid_make(push.p.space);
    if (any(greaterThanEqual(t, g.size))) return;
    if (!grid_holds_sample(g, t)) {
        imageStore(noisy, t, vec4(0.0));
        imageStore(normal, t, vec4(0.0));
        imageStore(features_position, t, vec4(0.0));
        return;
    }
    // Fireflies are capped like SVGF's input (NaN/Inf → 0, luminance ≤ 65504).
    vec3 c = svgf_sanitize(imageLoad(radiance, t).rgb);
    vec4 nd = imageLoad(normal_depth, t);
    vec4 pw = imageLoad(position, t);
    bool hit = nd.w > 0.0;
    vec3 n = nd.xyz;
    vec3 p = hit ? pw.xyz : vec3(0.0);

    float alpha_floor = push.p.params.w;
    vec3 shift = push.p.params.xyz;
    vec3 h_color = vec3(0.0);
    vec3 h_normal = vec3(0.0);
    vec3 h_position = vec3(0.0);
    float h_length = 0.0;
    float h_weight = 0.0;
    Grid prev = grid_make(push.p.space, push.p.prev);
    ivec2 taps[4];
    vec4 w;
    // Stored with the position (w) so that the pass after the fit accepts the same taps; its sign
    // tells emitters (kept out of the fits) from other surfaces, 0 misses.
    bool emitter = hit && any(greaterThan(materials.data[imageLoad(ids, t).y & 0xffffu].emissive.rgb, vec3(0.0)));
    float size = hit ? max(footprint(g, t, p), 1e-6 * nd.w + 1e-30) : 0.0;
    float kind = emitter ? -size : size;
    float tolerance = bmfr_tolerance(size, nd.w);
    if (alpha_floor < 1.0 && bmfr_reproject(prev, imageLoad(motion, t).xy, p, n, kind, tolerance, shift, taps, w)) {
        for (int i = 0; i < 4; ++i) {
            if (w[i] == 0.0) continue;
            vec4 hc = imageLoad(prev_noisy, taps[i]);
            h_color += w[i] * hc.rgb;
            h_length += w[i] * hc.w;
            h_normal += w[i] * imageLoad(prev_normal, taps[i]).xyz;
            h_position += w[i] * (imageLoad(prev_position, taps[i]).xyz + shift);
            h_weight += w[i];
        }
    }
    float len = 1.0;
    if (h_weight > 0.0) {
        len = min(h_length / h_weight + 1.0, BMFR_MAX_HISTORY);
        float a = max(1.0 / len, alpha_floor);
        c = mix(h_color / h_weight, c, a);
        n = mix(h_normal / h_weight, n, a);
        p = mix(h_position / h_weight, p, a);
    }
    imageStore(noisy, t, vec4(c, len));
    imageStore(normal, t, vec4(n, 0.0));
    imageStore(features_position, t, vec4(p, kind));
}
