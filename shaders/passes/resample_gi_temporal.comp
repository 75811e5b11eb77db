#version 460
// ReSTIR GI, first pass (Ouyang et al. 2021; docs/design/resampling.md): per sample of the grid,
// the tracer's bounce (its secondary hit and the radiance gathered there, `*_resampled_gi`
// kernels) becomes a reservoir of one candidate weighted p̂/p, p̂ the luminance of f·cos·L at the
// primary hit; the previous frame's reservoir, found through the tracer's previous screen
// position in the previous gaze's grid and kept only on the same surface near the same point,
// joins with its M capped, its p̂ re-evaluated here and the reconnection Jacobian applied. Where
// the previous sample was chosen, one ray tests that this point sees it; where this frame's was
// and the previous reservoir joined, one from the previous point (the unbiased 1/Z
// normalisation). Writes this frame's GI reservoirs, which the spatial pass reads.
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
layout(push_constant) uniform Push { ResampleTemporalPush p; } push;

layout(set = 0, binding = 10, rgba32f) uniform readonly image2D normal_depth;
layout(set = 0, binding = 11, rgba32f) uniform readonly image2D position;      // camera-relative, w: depth gradient per texel
layout(set = 0, binding = 12, rg32ui) uniform readonly uimage2D ids;
layout(set = 0, binding = 13, rg32f) uniform readonly image2D motion;          // previous screen position (−1: none)
layout(set = 0, binding = 14, rgba32f) uniform readonly image2D primary_hit;   // barycentrics, ray-cone width
layout(std430, set = 0, binding = 15) readonly buffer GiSamples { GiSampleGpu data[]; } gi_samples;
layout(std430, set = 0, binding = 16) readonly buffer History { GiReservoirGpu data[]; } history;
layout(std430, set = 0, binding = 17) writeonly buffer Fresh { GiReservoirGpu data[]; } fresh;
// [1]: shadow rays (the tracer's counters, passes/trace.comp).
layout(std430, set = 0, binding = 19) buffer RayCounters { uint data[]; } ray_counters;

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    Grid g = grid_make(push.p.space);
    if (any(greaterThanEqual(t, g.size))) return;
    uint index = uint(t.y) * uint(g.size.x) + uint(t.x);
    uvec2 id = imageLoad(ids, t).xy;
    // The bounce's light needs a third path vertex (max depth ≥ 3).
    if (!grid_holds_sample(g, t) || id.x == 0u || frame.data.frame.z < 3u) {
        fresh.data[index] = gi_reservoir_none();
        return;
    }
    vec4 pos = imageLoad(position, t);
    vec3 dir;
    Surface s = primary_surface(id.x - 1u, imageLoad(primary_hit, t), pos.xyz, dir);
    vec3 v = -dir;
    SvgfSurface here = svgf_surface(imageLoad(normal_depth, t), pos.w, id);

    // This frame's candidate: the traced bounce, weight p̂/p (a bounce that escaped, was a
    // mirror's or found nothing is a candidate of weight 0: it still counts in M).
    GiSampleGpu traced = gi_samples.data[index];
    GiReservoir combined = gi_reservoir_empty();
    if (traced.point.w > 0.0) {
        GiSample y = GiSample(traced.point.xyz, traced.normal.xyz, traced.radiance.rgb);
        float target = resampling_luminance(gi_contribution(s, v, y));
        gi_reservoir_update(combined, y, target / traced.point.w, target, 0.0);
    }
    combined.m = 1.0;

    uint rng = rng_seed(uvec2(t), frame.data.frame.x, frame.data.frame.y, RESAMPLING_SALT_GI_TEMPORAL);
    float m_prev = 0.0;        // the previous reservoir's M as combined (0: none)
    bool chose_prev = false;
    vec3 prev_position = s.position, prev_normal = s.normal;
    vec2 prev_screen = imageLoad(motion, t).xy;
    Grid prev = grid_make(push.p.space, push.p.prev);
    vec2 p;
    if (push.p.params.z == 0.0 && prev_screen != vec2(-1.0) && grid_from_screen(prev, prev_screen, p)) {
        ivec2 pt = grid_nearest(prev, p);
        if (grid_holds_sample(prev, pt)) {
            GiReservoirGpu q = history.data[uint(pt.y) * uint(g.size.x) + uint(pt.x)];
            bool near = resampling_near_previous(q.position.xyz, s.position, here.depth);
            SvgfSurface there = svgf_unpack_surface(q.surface);
            if (near && svgf_same_surface(here, there)) {
                float m_q = min(q.normal.w, push.p.params.y);
                float u = rng_next(rng);
                if (q.radiance.a > 0.0 && q.point.w > 0.0) {
                    GiSample y = gi_sample_of(q);
                    float target = resampling_luminance(gi_contribution(s, v, y));
                    float jacobian = gi_jacobian(q.position.xyz, s.position, y);
                    chose_prev = gi_reservoir_update(combined, y, target * q.point.w * m_q * jacobian, target, u);
                }
                combined.m += m_q;
                m_prev = m_q;
                prev_position = q.position.xyz;
                prev_normal = there.normal;
            }
        }
    }
    // This frame's bounce sees its own secondary hit; a previous sample chosen here needs a ray.
    // Occluded, the reservoir keeps its M with W = 0 (what it passes on estimates visible light).
    // Unbiased normalisation: 1/Z, Z counting the previous reservoir's M only if its point
    // could have chosen this sample (it reaches it; where the previous sample was chosen, its W > 0
    // says it did). The previous point is seen along this frame's view direction.
    float w = 0.0;
    if (combined.full && combined.target > 0.0
        && (!chose_prev || gi_visible(s.position, s.geometric_normal, combined.y))) {
        float z = 1.0;
        if (chose_prev || (m_prev > 0.0 && gi_sample_reaches(prev_position, prev_normal, v, combined.y)))
            z += m_prev;
        w = combined.weight_sum / (z * combined.target);
    }
    if (shadow_rays > 0u) atomicAdd(ray_counters.data[1], shadow_rays);
    fresh.data[index] = gi_reservoir_pack(combined, w, svgf_pack_surface(here), s.position);
}
