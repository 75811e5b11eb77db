#version 460
// Traces a list of rays against the scene BVH: the GPU side of the BVH correctness tests and of
// the ray-throughput benchmark (primary, shadow and indirect ray sets). The `counters` variant
// also writes what each ray's traversal read (bvh.glsl's BVH_COUNTERS); `hits` pays nothing for it.
//! variant hits:
//! variant counters: BVH_COUNTERS
//! traversals
#include "../common/scene.glsl"

layout(local_size_x = WORKGROUP_1D) in;
layout(push_constant) uniform Push { RaycastPush p; } push;
layout(set = 0, binding = 10) uniform samplerBuffer rays;   // RayGpu = 2 RGBA32F texels
layout(std430, set = 0, binding = 11) writeonly buffer HitBuffer { HitGpu data[]; } hits;
#if defined(BVH_COUNTERS)
// Per ray: nodes opened, leaf triangles tested, alpha tests, bytes of node + triangle data read.
layout(std430, set = 0, binding = 12) writeonly buffer CountBuffer { uvec4 data[]; } counts;
#endif

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.p.config.x) return;
    vec4 origin_tmin = texelFetch(rays, int(i) * 2 + 0);
    vec4 direction_tmax = texelFetch(rays, int(i) * 2 + 1);
    Hit h;
    bool any_hit = push.p.config.y != 0u;
    // One unconditional store per field: lavapipe runs both sides of a branch under a mask, and
    // each per-lane storage write is a scalar loop over the lanes.
    bool found = bvh_trace(origin_tmin.xyz, direction_tmax.xyz, origin_tmin.w, direction_tmax.w, any_hit, h);
    HitGpu o;
    o.t_u_v = found ? vec4(h.t, h.u, h.v, 0.0) : vec4(-1.0, 0.0, 0.0, 0.0);
    o.triangle = uvec4(found ? h.triangle : 0xffffffffu, 0u, 0u, 0u);
    hits.data[i] = o;
#if defined(BVH_COUNTERS)
    counts.data[i] = bvh_counts;
#endif
}
