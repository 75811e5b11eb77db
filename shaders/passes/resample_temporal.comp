#version 460
// ReSTIR DI, first pass (Bitterli et al. 2020, Alg. 5; docs/design/resampling.md): per sample of
// the grid, N light candidates drawn as next-event estimation draws them and N_B drawn by
// sampling the BRDF, resampled by p̂ = luminance of the unshadowed contribution (MIS-weighted
// RIS); the previous frame's reservoir, found through the tracer's previous screen position in
// the previous gaze's grid and kept only on the same surface, joins with its M capped and p̂
// re-evaluated here; then one shadow ray to the chosen sample (occluded, it keeps its M with
// W = 0: visibility reuse) and, where the previous reservoir joined, one from the previous
// frame's point (the unbiased 1/Z normalisation).
// Writes this frame's reservoirs, which the spatial pass reads.
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
layout(push_constant) uniform Push { ResampleTemporalPush p; } push;

layout(set = 0, binding = 10, rgba32f) uniform readonly image2D normal_depth;
layout(set = 0, binding = 11, rgba32f) uniform readonly image2D position;      // camera-relative, w: depth gradient per texel
layout(set = 0, binding = 12, rg32ui) uniform readonly uimage2D ids;
layout(set = 0, binding = 13, rg32f) uniform readonly image2D motion;          // previous screen position (−1: none)
layout(set = 0, binding = 14, rgba32f) uniform readonly image2D primary_hit;   // barycentrics, ray-cone width
layout(std430, set = 0, binding = 15) readonly buffer History { ReservoirGpu data[]; } history;
layout(std430, set = 0, binding = 16) writeonly buffer Fresh { ReservoirGpu data[]; } fresh;
// [1]: shadow rays (the tracer's counters, passes/trace.comp).
layout(std430, set = 0, binding = 17) buffer RayCounters { uint data[]; } ray_counters;

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    Grid g = grid_make(push.p.space);
    if (any(greaterThanEqual(t, g.size))) return;
    uint index = uint(t.y) * uint(g.size.x) + uint(t.x);
    uvec2 id = imageLoad(ids, t).xy;
    // Direct light at the primary hit needs a second path vertex (max depth ≥ 2).
    if (!grid_holds_sample(g, t) || id.x == 0u || frame.data.frame.z < 2u) {
        fresh.data[index] = reservoir_none();
        return;
    }
    vec4 pos = imageLoad(position, t);
    vec3 dir;
    Surface s = primary_surface(id.x - 1u, imageLoad(primary_hit, t), pos.xyz, dir);
    vec3 v = -dir;
    SvgfSurface here = svgf_surface(imageLoad(normal_depth, t), pos.w, id);
    uvec4 packed_here = svgf_pack_surface(here);

    uint rng = rng_seed(uvec2(t), frame.data.frame.x, frame.data.frame.y, RESAMPLING_SALT_CANDIDATES);
    Reservoir r = reservoir_empty();
    LightSample chosen;
    // Whether the chosen sample is known to be visible: a BRDF candidate's ray found it.
    bool chosen_seen = false;
    uint candidates = uint(push.p.params.x);
    uint brdf_candidates = uint(frame.data.path.z);
    float n_light = float(candidates), n_brdf = float(brdf_candidates);
    for (uint i = 0u; i < candidates; ++i) {
        LightPoint lp;
        LightSample ls;
        float w = 0.0, target = 0.0;
        if (draw_light_point(rng, lp)) w = light_point_candidate(s, v, lp, n_light, n_brdf, ls, target);
        if (reservoir_update(r, lp, w, target, rng_next(rng))) {
            chosen = ls;
            chosen_seen = false;
        }
    }
    // BRDF candidates find what light sampling rarely draws: the part of a large emitter that a
    // glossy lobe reflects.
    for (uint i = 0u; i < brdf_candidates; ++i) {
        LightPoint lp;
        LightSample ls;
        float w = 0.0, target = 0.0;
        if (draw_brdf_light_point(s, v, rng, lp)) w = light_point_candidate(s, v, lp, n_light, n_brdf, ls, target);
        if (reservoir_update(r, lp, w, target, rng_next(rng))) {
            chosen = ls;
            chosen_seen = true;
        }
    }
    r.m = n_light + n_brdf;
    // In the combination each reservoir weighs p̂_here(y)·W·M; this frame's own is its Σw.
    Reservoir combined = reservoir_empty();
    reservoir_update(combined, r.y, r.weight_sum, r.target, 0.0);
    combined.m = r.m;

    float m_prev = 0.0;        // the previous reservoir's M as combined (0: none)
    vec3 prev_position = s.position;
    vec2 prev_screen = imageLoad(motion, t).xy;
    Grid prev = grid_make(push.p.space, push.p.prev);
    vec2 p;
    if (push.p.params.z == 0.0 && prev_screen != vec2(-1.0) && grid_from_screen(prev, prev_screen, p)) {
        ivec2 pt = grid_nearest(prev, p);
        if (grid_holds_sample(prev, pt)) {
            ReservoirGpu q = history.data[uint(pt.y) * uint(g.size.x) + uint(pt.x)];
            // An empty reservoir of the same surface still counts its candidates (M). Only from
            // a shading point within a few pixels of this one: in the Visual-Polar periphery a
            // texel spans many pixels and its jittered sample crosses it from frame to frame, and
            // a reservoir drawn for a point that far away is a poor proposal here.
            bool near = resampling_near_previous(q.position.xyz, s.position, here.depth);
            if (near && svgf_same_surface(here, svgf_unpack_surface(q.surface))) {
                float m_q = min(q.weights.y, push.p.params.y * r.m);
                float u = rng_next(rng);
                if (q.light_point.x != 0u && q.weights.x > 0.0) {
                    LightPoint y = reservoir_light_point(q);
                    LightSample ls;
                    float source_pdf;
                    float target = resampling_luminance(light_point_contribution(s, v, y, ls, source_pdf));
                    if (reservoir_update(combined, y, target * q.weights.x * m_q, target, u)) {
                        chosen = ls;
                        chosen_seen = false;
                    }
                }
                combined.m += m_q;
                m_prev = m_q;
                prev_position = q.position.xyz;
            }
        }
    }
    // Visibility reuse: an occluded choice keeps its candidates (M) and weighs nothing, so what
    // this reservoir passes on estimates the visible light only (its target becomes p̂·V).
    // Unbiased normalisation (Bitterli et al. 2020, Alg. 6): 1/Z, Z counting the previous
    // reservoir's M only if its point (last frame's sample of this surface: another position in
    // the texel, or moved with the camera) reaches the chosen sample; 1/M would count previous
    // candidates that the penumbra there hid, and darken the penumbra here.
    float w = 0.0;
    if (combined.full && combined.target > 0.0 && (chosen_seen || visible(s.position, s.geometric_normal, chosen))) {
        float z = r.m;
        if (m_prev > 0.0 && light_point_reaches(prev_position, s.normal, v, combined.y)) z += m_prev;
        w = combined.weight_sum / (z * combined.target);
    }
    if (shadow_rays > 0u) atomicAdd(ray_counters.data[1], shadow_rays);
    if (continuation_rays > 0u) atomicAdd(ray_counters.data[2], continuation_rays);
    fresh.data[index] = reservoir_pack(combined, w, packed_here, s.position);
}
