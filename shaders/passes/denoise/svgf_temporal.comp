#version 460
// SVGF temporal accumulation (Schied et al. 2017, §4.1) in the sampling grid. Each sample finds
// its previous grid position (the tracer's previous screen position mapped with the previous
// frame's space), takes the bilinear taps of the same surface (else the same-surface texels of the
// 3×3 around it), and blends colour and luminance moments with α = max(α_min, 1/history).
// Writes: accumulated colour + temporal variance, moments + history length, and this frame's
// surface for the next frame's test. Texels without a sample get zeros.
// The *_adaptive variants are A-SVGF's (Schied et al. 2018, §4.3): the reconstructed temporal
// gradient of the texel's stratum gives λ = |δ̂| / max(f_i, f_{i−1}), which raises both alphas to
// (1 − λ)·α + λ and shortens the history length by the same factor (a changed light restarts it).
//! variants per space
//! variants per space _adaptive: SVGF_ADAPTIVE_ALPHA
#include "../../common/layouts.glsl"
#include "../../denoise/grid.glsl"
#include "../../denoise/svgf.glsl"
// The live tiles of the trace (SvgfIdlePass writes what later frames read of the idle ones).
#define TILE_LIST_BINDING 30
#include "../../common/tiles.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { SvgfTemporalPush p; } push;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D radiance;       // demodulated
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D normal_depth;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D position;       // w: depth gradient per texel
layout(set = 0, binding = 3, rg32ui) uniform readonly uimage2D ids;
layout(set = 0, binding = 4, rg32f) uniform readonly image2D motion;           // previous screen position (−1: none)
layout(set = 0, binding = 5, rgba32f) uniform readonly image2D prev_color;     // colour history
layout(set = 0, binding = 6, rgba32f) uniform readonly image2D prev_moments;   // m1, m2, history length
layout(set = 0, binding = 7, rgba32ui) uniform readonly uimage2D prev_surface;
layout(set = 0, binding = 8, rgba32f) uniform writeonly image2D accum;         // colour, variance
layout(set = 0, binding = 9, rgba32f) uniform writeonly image2D moments;       // m1, m2, history length
layout(set = 0, binding = 10, rgba32ui) uniform writeonly uimage2D surface;
#if defined(SVGF_ADAPTIVE_ALPHA)
layout(set = 0, binding = 11, rgba32f) uniform readonly image2D gradient;      // per stratum: δ̂, max f, confidence
#endif

vec3 hist_color;
vec3 hist_moments; // m1, m2, length
float hist_weight;

void take(Grid prev, SvgfSurface s, ivec2 tap, float w) {
    if (w <= 0.0 || !grid_holds_sample(prev, tap)) return;
    if (!svgf_same_surface(s, svgf_unpack_surface(imageLoad(prev_surface, tap)))) return;
    vec3 c = imageLoad(prev_color, tap).rgb;
    vec3 m = imageLoad(prev_moments, tap).xyz;
    if (any(isnan(c)) || any(isnan(m))) return;
    hist_color += w * c;
    hist_moments += w * m;
    hist_weight += w;
}

void main() {
    ivec2 t = tile_list_texel(0u);
    Grid g = grid_make(push.p.space);
    if (any(greaterThanEqual(t, g.size))) return;
    if (!grid_holds_sample(g, t)) {
        imageStore(accum, t, vec4(0.0));
        imageStore(moments, t, vec4(0.0));
        imageStore(surface, t, uvec4(0u));
        return;
    }
    vec3 c = svgf_sanitize(imageLoad(radiance, t).rgb);
    SvgfSurface s = svgf_surface(imageLoad(normal_depth, t), imageLoad(position, t).w, imageLoad(ids, t).xy);
    vec2 prev_screen = imageLoad(motion, t).xy;

    hist_color = vec3(0.0);
    hist_moments = vec3(0.0);
    hist_weight = 0.0;
    Grid prev = grid_make(push.p.space, push.p.prev);
    vec2 p;
    if (push.p.params.w == 0.0 && prev_screen != vec2(-1.0) && grid_from_screen(prev, prev_screen, p)) {
        ivec2 taps[4];
        vec4 w;
        grid_bilinear(prev, p, taps, w);
        for (int i = 0; i < 4; ++i) take(prev, s, taps[i], w[i]);
        // Too little of the footprint is the same surface: any same-surface texel around it.
        if (hist_weight < 0.01) {
            hist_color = vec3(0.0);
            hist_moments = vec3(0.0);
            hist_weight = 0.0;
            ivec2 centre = grid_nearest(prev, p);
            for (int dy = -1; dy <= 1; ++dy) {
                for (int dx = -1; dx <= 1; ++dx) {
                    ivec2 tap;
                    if (grid_tap(prev, centre, ivec2(dx, dy), tap)) take(prev, s, tap, 1.0);
                }
            }
        }
    }

    float l = svgf_luminance(c);
    vec3 color = c;
    vec2 m = vec2(l, l * l);
    float len = 1.0;
    if (hist_weight > 0.0) {
        vec3 h = hist_color / hist_weight;
        vec3 hm = hist_moments / hist_weight;
#if defined(SVGF_ADAPTIVE_ALPHA)
        vec3 gr = imageLoad(gradient, t / int(ASVGF_STRATUM)).xyz;
        float lambda = gr.z > 0.0 ? clamp(abs(gr.x) / max(gr.y, 1e-6), 0.0, 1.0) : 0.0;
        len = min((1.0 - lambda) * hm.z + 1.0, push.p.params.z);
        color = mix(h, c, mix(max(push.p.params.x, 1.0 / len), 1.0, lambda));
        m = mix(hm.xy, m, mix(max(push.p.params.y, 1.0 / len), 1.0, lambda));
#else
        len = min(hm.z + 1.0, push.p.params.z);
        color = mix(h, c, max(push.p.params.x, 1.0 / len));
        m = mix(hm.xy, m, max(push.p.params.y, 1.0 / len));
#endif
    }
    imageStore(accum, t, vec4(color, max(m.y - m.x * m.x, 0.0)));
    imageStore(moments, t, vec4(m, len, 0.0));
    imageStore(surface, t, svgf_pack_surface(s));
}
