#version 460
// One iteration of A-SVGF's gradient reconstruction (Schied et al. 2018, §4.2) on the 1/3-size
// strata grid: a 5×5 B3-spline à-trous filter, taps `config.x` strata apart, joint-bilateral on
// the depth and normal of each stratum's centre texel (SVGF's edge-stopping functions, no
// luminance term: the gradient itself is what is being estimated). It filters the temporal
// difference δ = f_i − f_{i−1} and the normaliser max(f_i, f_{i−1}) of the strata that have a
// re-shaded gradient sample; z carries the fraction of the kernel's weight that had one, which is
// the next iteration's confidence. The first iteration reads what the tracer wrote (δ, max f, 1
// where a stratum has a gradient sample, zeros elsewhere).
//! variants per space
#include "../../common/layouts.glsl"
#include "../../denoise/strata.glsl"
#include "../../denoise/svgf.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { AsvgfGradientPush p; } push;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D src;    // δ, max f, confidence
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D normal_depth;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D position;  // w: depth gradient per texel
layout(set = 0, binding = 3, rgba32f) uniform writeonly image2D dst;      // δ, max f, confidence

const float B3[3] = float[3](3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0);

void main() {
    ivec2 s = ivec2(gl_GlobalInvocationID.xy);
    Grid g = grid_make(push.p.space);
    if (any(greaterThanEqual(s, strata_size(g)))) return;
    if (!stratum_holds_samples(g, s)) {
        imageStore(dst, s, vec4(0.0));
        return;
    }
    ivec2 t = stratum_centre_texel(g, s);
    SvgfSurface c = svgf_surface(imageLoad(normal_depth, t), imageLoad(position, t).w, uvec2(0u));
    int step = int(push.p.config.x);
    vec2 sum = vec2(0.0);
    float sum_confident = 0.0;
    float sum_w = 0.0;
    for (int dx = -2; dx <= 2; ++dx) {
        for (int dy = -2; dy <= 2; ++dy) {
            ivec2 q;
            if (!strata_tap(g, s, ivec2(dx, dy) * step, q)) continue;
            ivec2 tq = stratum_centre_texel(g, q);
            SvgfSurface sq = svgf_surface(imageLoad(normal_depth, tq), 0.0, uvec2(0u));
            float distance = float(STRATUM * step) * length(vec2(dx, dy));
            float w = B3[abs(dx)] * B3[abs(dy)] * svgf_edge_weight(c, sq, distance, push.p.params.x, push.p.params.y, 0.0, 1.0);
            vec3 v = imageLoad(src, q).xyz;
            sum += w * v.z * v.xy;
            sum_confident += w * v.z;
            sum_w += w;
        }
    }
    vec2 mean = sum_confident > 0.0 ? sum / sum_confident : vec2(0.0);
    imageStore(dst, s, vec4(mean, sum_w > 0.0 ? sum_confident / sum_w : 0.0, 0.0));
}
