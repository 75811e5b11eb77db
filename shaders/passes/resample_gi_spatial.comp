#version 460
// ReSTIR GI, second pass (Ouyang et al. 2021; docs/design/resampling.md): each sample combines
// its reservoir from the first pass with those of k random grid neighbours within a radius
// (grid.glsl taps, as ReSTIR DI's spatial pass) that lie on a similar surface, each neighbour's
// secondary hit reconnected to this primary hit (p̂ re-evaluated here, times the Jacobian of the
// shift). One ray tests that this point sees a neighbour's chosen secondary hit and, where it
// does, one from each other neighbour that could have produced it (the unbiased 1/Z
// normalisation); f·cos·L·W joins the tracer's colour and demodulated radiance before any
// denoiser runs. The combined reservoir shades this frame only: next frame's history is the
// first pass's.
//! variants per space
//! traversals
#include "../common/scene.glsl"
#include "../common/random.glsl"
#include "../common/brdf.glsl"
#include "../common/lights.glsl"
#include "../common/path.glsl"
#include "../common/resampling.glsl"
#include "../common/resampling_gi.glsl"
#include "../denoise/grid.glsl"
#include "../denoise/svgf.glsl"
#include "../common/resampling_reuse.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { ResampleSpatialPush p; } push;

layout(set = 0, binding = 10, rgba32f) uniform image2D color;                  // the tracer's, + the bounce's light
layout(set = 0, binding = 11, rgba32f) uniform image2D radiance;               // colour / albedo
layout(set = 0, binding = 12, rgba32f) uniform readonly image2D normal_depth;
layout(set = 0, binding = 13, rgba32f) uniform readonly image2D position;      // camera-relative, w: depth gradient per texel
layout(set = 0, binding = 14, rg32ui) uniform readonly uimage2D ids;
layout(set = 0, binding = 15, rgba32f) uniform readonly image2D primary_hit;   // barycentrics, ray-cone width
layout(std430, set = 0, binding = 16) readonly buffer Fresh { GiReservoirGpu data[]; } fresh;
// [1]: shadow rays (the tracer's counters, passes/trace.comp).
layout(std430, set = 0, binding = 19) buffer RayCounters { uint data[]; } ray_counters;

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    Grid g = grid_make(push.p.space);
    if (any(greaterThanEqual(t, g.size))) return;
    uint index = uint(t.y) * uint(g.size.x) + uint(t.x);
    GiReservoirGpu own = fresh.data[index];
    // The first pass left no surface where there is no sample to shade.
    if (own.surface.w == 0u) return;
    uvec2 id = imageLoad(ids, t).xy;
    vec4 pos = imageLoad(position, t);
    vec3 dir;
    Surface s = primary_surface(id.x - 1u, imageLoad(primary_hit, t), pos.xyz, dir);
    vec3 v = -dir;
    SvgfSurface here = svgf_unpack_surface(own.surface);

    // This texel's own reservoir weighs p̂(y)·W·M with p̂ already evaluated on this surface.
    GiReservoir combined = gi_reservoir_empty();
    if (own.radiance.a > 0.0)
        gi_reservoir_update(combined, gi_sample_of(own), own.radiance.a * own.point.w * own.normal.w, own.radiance.a, 0.0);
    combined.m = own.normal.w;

    uint rng = rng_seed(uvec2(t), frame.data.frame.x, frame.data.frame.y, RESAMPLING_SALT_GI_REUSE);
    uint neighbours = min(uint(push.p.params.x), RESAMPLING_MAX_NEIGHBOURS);
    float radius = push.p.params.y;
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
        GiReservoirGpu q = fresh.data[uint(tap.y) * uint(g.size.x) + uint(tap.x)];
        if (!similar_surface(here, svgf_unpack_surface(q.surface))) continue;
        if (q.radiance.a > 0.0 && q.point.w > 0.0) {
            GiSample y = gi_sample_of(q);
            float target = resampling_luminance(gi_contribution(s, v, y));
            float jacobian = gi_jacobian(q.position.xyz, s.position, y);
            if (gi_reservoir_update(combined, y, target * q.point.w * q.normal.w * jacobian, target, u_choice))
                source = int(combined_taps);
        }
        combined.m += q.normal.w;
        taps[combined_taps] = tap;
        tap_m[combined_taps] = q.normal.w;
        combined_taps++;
    }

    // Shading: the chosen secondary hit's light here if this point sees it (its own reservoir's
    // sample it does: W > 0 says the first pass found it so).
    vec3 contribution = combined.full ? gi_contribution(s, v, combined.y) : vec3(0.0);
    bool seen = any(greaterThan(contribution, vec3(0.0)))
             && (source < 0 || gi_visible(s.position, s.geometric_normal, combined.y));
    // Unbiased normalisation (as ReSTIR DI's): Z the candidates of the reservoirs that could have
    // produced the chosen sample: this texel's own, and each neighbour whose point reaches it.
    float z = 0.0;
    if (seen) {
        z = own.normal.w;
        for (uint k = 0u; k < combined_taps; ++k) {
            if (int(k) == source) {
                z += tap_m[k];
                continue;
            }
            ivec2 tap = taps[k];
            GiReservoirGpu q = fresh.data[uint(tap.y) * uint(g.size.x) + uint(tap.x)];
            vec3 tap_v = -normalize(imageLoad(position, tap).xyz);
            if (gi_sample_reaches(q.position.xyz, imageLoad(normal_depth, tap).xyz, tap_v, combined.y)) z += tap_m[k];
        }
    }
    float w = seen && z > 0.0 && combined.target > 0.0 ? combined.weight_sum / (z * combined.target) : 0.0;
    if (shadow_rays > 0u) atomicAdd(ray_counters.data[1], shadow_rays);
    if (w <= 0.0) return;
    vec3 bounce = contribution * w;
    if (any(isnan(bounce)) || any(isinf(bounce))) return;
    vec3 albedo = max(s.base_color, vec3(0.01));
    vec4 c = imageLoad(color, t), l = imageLoad(radiance, t);
    imageStore(color, t, vec4(c.rgb + bounce, c.a));
    imageStore(radiance, t, vec4(l.rgb + bounce / albedo, l.a));
}
