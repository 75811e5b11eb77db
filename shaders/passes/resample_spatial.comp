#version 460
// ReSTIR DI, second pass (Bitterli et al. 2020, Alg. 5 and 6; docs/design/resampling.md): each
// sample combines its reservoir from the first pass with those of k random grid neighbours
// within a radius (grid.glsl taps: Visual-Polar wraps on φ and keeps the angle across columns,
// clipped texels hold none) that lie on a similar surface, re-evaluating p̂ of theirs here; one
// shadow ray to the chosen light point and, where it is lit, one from each neighbour that could
// have produced it (the unbiased 1/Z normalisation); its contribution f·Le·G·W joins the
// tracer's colour and demodulated radiance before any denoiser runs. The combined reservoir
// shades this frame only: next frame's history is the first pass's (ReservoirPair).
//! variants per space
//! traversals
#include "../common/scene.glsl"
#include "../common/random.glsl"
#include "../common/brdf.glsl"
#include "../common/lights.glsl"
#include "../common/path.glsl"
#include "../common/resampling.glsl"
#include "../denoise/grid.glsl"
#include "../denoise/svgf.glsl"
#include "../common/resampling_reuse.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { ResampleSpatialPush p; } push;

layout(set = 0, binding = 10, rgba32f) uniform image2D color;                  // the tracer's, + direct light
layout(set = 0, binding = 11, rgba32f) uniform image2D radiance;               // colour / albedo
layout(set = 0, binding = 12, rgba32f) uniform readonly image2D normal_depth;
layout(set = 0, binding = 13, rgba32f) uniform readonly image2D position;      // camera-relative, w: depth gradient per texel
layout(set = 0, binding = 14, rg32ui) uniform readonly uimage2D ids;
layout(set = 0, binding = 15, rgba32f) uniform readonly image2D primary_hit;   // barycentrics, ray-cone width
layout(std430, set = 0, binding = 16) readonly buffer Fresh { ReservoirGpu data[]; } fresh;
// [1]: shadow rays (the tracer's counters, passes/trace.comp).
layout(std430, set = 0, binding = 19) buffer RayCounters { uint data[]; } ray_counters;

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    Grid g = grid_make(push.p.space);
    if (any(greaterThanEqual(t, g.size))) return;
    uint index = uint(t.y) * uint(g.size.x) + uint(t.x);
    ReservoirGpu own = fresh.data[index];
    // The first pass left no surface where there is no sample to shade (a miss, a clipped or
    // untraced texel, max depth 1).
    if (own.surface.w == 0u) return;
    uvec2 id = imageLoad(ids, t).xy;
    vec4 pos = imageLoad(position, t);
    vec3 dir;
    Surface s = primary_surface(id.x - 1u, imageLoad(primary_hit, t), pos.xyz, dir);
    vec3 v = -dir;
    SvgfSurface here = svgf_unpack_surface(own.surface);

    // This texel's own reservoir weighs p̂(y)·W·M with p̂ already evaluated on this surface.
    Reservoir combined = reservoir_empty();
    reservoir_update(combined, reservoir_light_point(own), own.weights.z * own.weights.x * own.weights.y, own.weights.z, 0.0);
    combined.m = own.weights.y;

    uint rng = rng_seed(uvec2(t), frame.data.frame.x, frame.data.frame.y, RESAMPLING_SALT_REUSE);
    uint neighbours = min(uint(push.p.params.x), RESAMPLING_MAX_NEIGHBOURS);
    float radius = push.p.params.y;
    // The neighbours combined and their M, for the normalisation below.
    ivec2 taps[RESAMPLING_MAX_NEIGHBOURS];
    float tap_m[RESAMPLING_MAX_NEIGHBOURS];
    uint combined_taps = 0u;
    int source = -1;   // the tap whose sample was chosen (−1: this texel's own)
    for (uint k = 0u; k < neighbours; ++k) {
        vec2 u = rng_next2(rng);
        float u_choice = rng_next(rng);
        float r = radius * sqrt(u.x), a = 2.0 * PI * u.y;
        ivec2 o = ivec2(round(r * vec2(cos(a), sin(a))));
        ivec2 tap;
        if (o == ivec2(0) || !grid_tap(g, t, o, tap) || !grid_holds_sample(g, tap)) continue;
        ReservoirGpu q = fresh.data[uint(tap.y) * uint(g.size.x) + uint(tap.x)];
        if (!similar_surface(here, svgf_unpack_surface(q.surface))) continue;
        if (q.light_point.x != 0u && q.weights.x > 0.0) {
            LightPoint y = reservoir_light_point(q);
            LightSample ls;
            float source_pdf;
            float target = resampling_luminance(light_point_contribution(s, v, y, ls, source_pdf));
            if (reservoir_update(combined, y, target * q.weights.x * q.weights.y, target, u_choice)) source = int(combined_taps);
        }
        combined.m += q.weights.y;
        taps[combined_taps] = tap;
        tap_m[combined_taps] = q.weights.y;
        combined_taps++;
    }

    // Shading: the chosen sample's contribution here if this surface sees it.
    LightSample ls;
    float source_pdf;
    vec3 contribution = combined.full ? light_point_contribution(s, v, combined.y, ls, source_pdf) : vec3(0.0);
    bool lit = any(greaterThan(contribution, vec3(0.0))) && visible(s.position, s.geometric_normal, ls);
    // Unbiased normalisation (Bitterli et al. 2020, Alg. 6, with visibility): 1/Z instead of 1/M,
    // Z the candidates of the reservoirs that could have produced the chosen sample: this texel's
    // own (it sees it), and each neighbour whose surface has p̂ > 0 for it and sees it (a shadow
    // ray from there; the source's own reservoir saw it already). 1/M would count the neighbours
    // that cannot reach the sample, which darkens the edges of shadows.
    float z = 0.0;
    if (lit) {
        z = own.weights.y;
        for (uint k = 0u; k < combined_taps; ++k) {
            if (int(k) == source) {
                z += tap_m[k];
                continue;
            }
            // The neighbour's own point and normal as the first pass stored and the G-buffer has.
            ivec2 tap = taps[k];
            ReservoirGpu q = fresh.data[uint(tap.y) * uint(g.size.x) + uint(tap.x)];
            vec3 tap_v = -normalize(imageLoad(position, tap).xyz);
            if (light_point_reaches(q.position.xyz, imageLoad(normal_depth, tap).xyz, tap_v, combined.y)) z += tap_m[k];
        }
    }
    float w = lit && z > 0.0 && combined.target > 0.0 ? combined.weight_sum / (z * combined.target) : 0.0;
    atomicAdd(ray_counters.data[1], shadow_rays);
    if (w <= 0.0) return;
    vec3 direct = contribution * w;
    if (any(isnan(direct)) || any(isinf(direct))) return;
    vec3 albedo = max(s.base_color, vec3(0.01));
    vec4 c = imageLoad(color, t), l = imageLoad(radiance, t);
    imageStore(color, t, vec4(c.rgb + direct, c.a));
    imageStore(radiance, t, vec4(l.rgb + direct / albedo, l.a));
}
