#version 460
// SVGF variance estimate (Schied et al. 2017, §4.2): the temporal variance where the history is
// long enough; below that, colour and moments are averaged over a 7×7 edge-stopped neighbourhood
// and the variance from those moments is boosted by 4/history (few frames underestimate it).
//! variants per space
#include "../../common/layouts.glsl"
#include "../../denoise/grid.glsl"
#include "../../denoise/svgf.glsl"
// The live tiles of the trace (SvgfIdlePass writes what later frames read of the idle ones).
#define TILE_LIST_BINDING 30
#include "../../common/tiles.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { SvgfVariancePush p; } push;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D accum;      // colour, temporal variance
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D moments;    // m1, m2, history length
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D normal_depth;
layout(set = 0, binding = 3, rgba32f) uniform readonly image2D position;   // w: depth gradient per texel
layout(set = 0, binding = 4, rgba32f) uniform writeonly image2D dst;       // colour, variance

void main() {
    ivec2 t = tile_list_texel(0u);
    Grid g = grid_make(push.p.space);
    if (any(greaterThanEqual(t, g.size))) return;
    if (!grid_holds_sample(g, t)) {
        imageStore(dst, t, vec4(0.0));
        return;
    }
    vec4 centre = imageLoad(accum, t);
    vec3 cm = imageLoad(moments, t).xyz;
    if (cm.z >= push.p.params.w) {
        imageStore(dst, t, centre);
        return;
    }
    vec4 centre_normal_depth = imageLoad(normal_depth, t);
    // A miss (or a culled sample): no neighbour passes the normal test, so the sums below would
    // hold the centre alone; skipped for whole runs of sky or culled texels.
    bool alone = all(equal(centre_normal_depth.xyz, vec3(0.0)));
    SvgfSurface s = svgf_surface(centre_normal_depth, imageLoad(position, t).w, uvec2(0u));
    float l = svgf_luminance(centre.rgb);
    vec3 sum_c = centre.rgb;
    vec2 sum_m = cm.xy;
    float sum_w = 1.0;
    int rows_here = grid_rows(g, t.x);
    for (int dx = -3; dx <= 3 && !alone; ++dx) {
        GridColumn col;
        if (!grid_column(g, t, rows_here, dx, col)) continue;
        for (int dy = -3; dy <= 3; ++dy) {
            ivec2 q;
            if ((dx == 0 && dy == 0) || !grid_column_tap(col, t, dy, q)) continue;
            vec3 c = imageLoad(accum, q).rgb;
            SvgfSurface sq = svgf_surface(imageLoad(normal_depth, q), 0.0, uvec2(0u));
            float w = svgf_edge_weight(s, sq, length(vec2(dx, dy)), push.p.params.y, push.p.params.z,
                                       l - svgf_luminance(c), push.p.params.x);
            sum_c += w * c;
            sum_m += w * imageLoad(moments, q).xy;
            sum_w += w;
        }
    }
    vec2 m = sum_m / sum_w;
    float variance = max(m.y - m.x * m.x, 0.0) * 4.0 / max(cm.z, 1.0);
    imageStore(dst, t, vec4(sum_c / sum_w, variance));
}
