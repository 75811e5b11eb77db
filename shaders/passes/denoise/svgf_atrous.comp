#version 460
// One SVGF à-trous iteration (Schied et al. 2017, §4.3): a 5×5 B3-spline kernel with taps
// `config.x` texels apart, stopped at edges by depth (relative to the gradient), normal and
// luminance (relative to σ_l·√(3×3-Gaussian variance)); the variance is filtered with the squared
// weights. Texels without a sample are never read and get zeros; misses keep their value.
//! variants per space
#include "../../common/layouts.glsl"
#include "../../denoise/grid.glsl"
#include "../../denoise/svgf.glsl"
// The live tiles of the trace (SvgfIdlePass writes what later frames read of the idle ones).
#define TILE_LIST_BINDING 30
#include "../../common/tiles.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { SvgfAtrousPush p; } push;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D src;         // colour, variance
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D normal_depth;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D position;    // w: depth gradient per texel
layout(set = 0, binding = 3, rgba32f) uniform writeonly image2D dst;        // colour, variance

const float B3[3] = float[3](3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0);
const float GAUSS3[2] = float[2](1.0 / 2.0, 1.0 / 4.0);

void main() {
    ivec2 t = tile_list_texel(0u);
    Grid g = grid_make(push.p.space);
    if (any(greaterThanEqual(t, g.size))) return;
    if (!grid_holds_sample(g, t)) {
        imageStore(dst, t, vec4(0.0));
        return;
    }
    vec4 centre = imageLoad(src, t);
    vec4 centre_normal_depth = imageLoad(normal_depth, t);
    if (all(equal(centre_normal_depth.xyz, vec3(0.0)))) {
        // A miss (or a sample culled off the screen): no tap passes the normal test, the texel
        // keeps its value. Skipping the 34 taps matters where whole runs are misses (sky, culled).
        imageStore(dst, t, centre);
        return;
    }

    // The luminance edge-stop uses a 3×3 Gaussian of the variance: single-texel estimates are noisy.
    int rows_here = grid_rows(g, t.x);
    float var = 0.0;
    float var_w = 0.0;
    for (int dx = -1; dx <= 1; ++dx) {
        GridColumn col;
        if (!grid_column(g, t, rows_here, dx, col)) continue;
        for (int dy = -1; dy <= 1; ++dy) {
            ivec2 q;
            if (!grid_column_tap(col, t, dy, q)) continue;
            float k = GAUSS3[abs(dx)] * GAUSS3[abs(dy)];
            var += k * imageLoad(src, q).a;
            var_w += k;
        }
    }
    float phi_l = push.p.params.x * sqrt(max(var / var_w, 0.0) + 1e-10);

    SvgfSurface s = svgf_surface(centre_normal_depth, imageLoad(position, t).w, uvec2(0u));
    float l = svgf_luminance(centre.rgb);
    int step = int(push.p.config.x);
    float w0 = B3[0] * B3[0];
    vec3 sum_c = w0 * centre.rgb;
    float sum_v = w0 * w0 * centre.a;
    float sum_w = w0;
    for (int dx = -2; dx <= 2; ++dx) {
        GridColumn col;
        if (!grid_column(g, t, rows_here, dx * step, col)) continue;
        for (int dy = -2; dy <= 2; ++dy) {
            ivec2 q;
            if ((dx == 0 && dy == 0) || !grid_column_tap(col, t, dy * step, q)) continue;
            vec4 c = imageLoad(src, q);
            SvgfSurface sq = svgf_surface(imageLoad(normal_depth, q), 0.0, uvec2(0u));
            float w = B3[abs(dx)] * B3[abs(dy)] * svgf_edge_weight(s, sq, float(step) * length(vec2(dx, dy)),
                push.p.params.y, push.p.params.z, l - svgf_luminance(c.rgb), phi_l);
            sum_c += w * c.rgb;
            sum_v += w * w * c.a;
            sum_w += w;
        }
    }
    imageStore(dst, t, vec4(sum_c / sum_w, sum_v / (sum_w * sum_w)));
}
