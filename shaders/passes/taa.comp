#version 460
// TAA (Karis 2014) in the sampling grid: the history is reprojected through the tracer's previous
// screen position into the previous frame's grid (bilinear over same-surface taps), clipped toward
// the mean of this frame's 3×3 neighbourhood in YCoCg (grid.glsl taps: Visual-Polar wraps on φ and
// keeps the angle across columns), and blended with luma weights 1/(1 + luma) against flicker.
// Without a usable history (first frame, disocclusion, off the previous grid) the sample starts
// afresh: the bilinear taps are the reprojected history, the previous 3×3 surfaces decide
// whether it may be used. Writes the new history, which is also the pass's output, and this frame's surface.
//! variants per space
#include "../common/layouts.glsl"
#include "../denoise/grid.glsl"
#include "../denoise/svgf.glsl"
#include "../denoise/taa.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { TaaPush p; } push;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D color;          // denoised or raw radiance
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D normal_depth;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D position;       // w: depth gradient per texel
layout(set = 0, binding = 3, rg32ui) uniform readonly uimage2D ids;
layout(set = 0, binding = 4, rg32f) uniform readonly image2D motion;           // previous screen position (−1: none)
layout(set = 0, binding = 5, rgba32f) uniform readonly image2D prev_history;
layout(set = 0, binding = 6, rgba32ui) uniform readonly uimage2D prev_surface;
layout(set = 0, binding = 7, rgba32f) uniform writeonly image2D history;       // output = next history
layout(set = 0, binding = 8, rgba32ui) uniform writeonly uimage2D surface;

// A bilinear footprint with less of the grid's samples than this has no usable history.
const float TAA_MIN_HISTORY_WEIGHT = 0.01;

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    Grid g = grid_make(push.p.space);
    if (any(greaterThanEqual(t, g.size))) return;
    if (!grid_holds_sample(g, t)) {
        imageStore(history, t, vec4(0.0));
        imageStore(surface, t, uvec4(0u));
        return;
    }
    vec3 c = svgf_sanitize(imageLoad(color, t).rgb);
    SvgfSurface s = svgf_surface(imageLoad(normal_depth, t), imageLoad(position, t).w, imageLoad(ids, t).xy);
    imageStore(surface, t, svgf_pack_surface(s));

    // Neighbourhood statistics in YCoCg over the grid's own 3×3 (taps off the grid are dropped).
    vec3 cy = rgb_to_ycocg(c);
    vec3 lo = cy, hi = cy, sum = vec3(0.0);
    float n = 0.0;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 tap;
            if (!grid_tap(g, t, ivec2(dx, dy), tap) || !grid_holds_sample(g, tap)) continue;
            vec3 q = rgb_to_ycocg(svgf_sanitize(imageLoad(color, tap).rgb));
            lo = min(lo, q);
            hi = max(hi, q);
            sum += q;
            n += 1.0;
        }
    }
    vec3 mean = sum / n;

    vec3 hist = vec3(0.0);
    float hist_weight = 0.0;
    vec2 prev_screen = imageLoad(motion, t).xy;
    Grid prev = grid_make(push.p.space, push.p.prev);
    vec2 p;
    if (push.p.params.y == 0.0 && prev_screen != vec2(-1.0) && grid_from_screen(prev, prev_screen, p)) {
        // The motion belongs to the jittered sample; the history is kept at texel centres, so step
        // back by the jitter (its y in rows of the column it lands in).
        vec2 off = push.p.params.zw - 0.5;
        float x = clamp(p.x - off.x, 0.0, float(g.size.x) - 1e-3);
        p = vec2(x, grid_row_in_column(prev, vec2(p.x, p.y - off.y), int(floor(x))));
        // Disocclusion: this sample's surface is nowhere in the previous 3×3 around its position.
        // Not a per-tap test: at a geometric edge the jittered sample lands on either surface
        // from frame to frame, and the history there is meant to average both (anti-aliasing).
        bool seen = false;
        ivec2 centre = grid_nearest(prev, p);
        for (int dy = -1; dy <= 1 && !seen; ++dy) {
            for (int dx = -1; dx <= 1 && !seen; ++dx) {
                ivec2 tap;
                if (grid_tap(prev, centre, ivec2(dx, dy), tap) && grid_holds_sample(prev, tap))
                    seen = svgf_same_surface(s, svgf_unpack_surface(imageLoad(prev_surface, tap)));
            }
        }
        ivec2 taps[4];
        vec4 w;
        grid_bilinear(prev, p, taps, w);
        for (int i = 0; i < 4 && seen; ++i) {
            if (w[i] <= 0.0 || !grid_holds_sample(prev, taps[i])) continue;
            vec3 h = imageLoad(prev_history, taps[i]).rgb;
            if (any(isnan(h)) || any(isinf(h))) continue;
            hist += w[i] * h;
            hist_weight += w[i];
        }
    }

    vec3 result = c;
    if (hist_weight >= TAA_MIN_HISTORY_WEIGHT) {
        vec3 hy = clip_toward_mean(lo, hi, mean, rgb_to_ycocg(max(hist / hist_weight, vec3(0.0))));
        result = taa_blend(cy, hy, push.p.params.x);
    }
    // Alpha: whether this frame traced the sample (0: culled off the screen), for the grid blur.
    imageStore(history, t, vec4(result, imageLoad(color, t).a));
}
