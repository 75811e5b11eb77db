#version 460
// Traces a list of rays against the scene BVH: the GPU side of the BVH correctness tests and of
// the ray-throughput benchmark (primary, shadow and indirect ray sets).
#include "../common/scene.glsl"

layout(local_size_x = WORKGROUP_1D) in;
layout(push_constant) uniform Push { RaycastPush p; } push;
layout(std430, set = 0, binding = 10) readonly buffer RayBuffer { RayGpu data[]; } rays;
layout(std430, set = 0, binding = 11) writeonly buffer HitBuffer { HitGpu data[]; } hits;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.p.config.x) return;
    RayGpu r = rays.data[i];
    Hit h;
    bool any_hit = push.p.config.y != 0u;
    if (bvh_trace(r.origin_tmin.xyz, r.direction_tmax.xyz, r.origin_tmin.w, r.direction_tmax.w, any_hit, h)) {
        hits.data[i].t_u_v = vec4(h.t, h.u, h.v, 0.0);
        hits.data[i].triangle = uvec4(h.triangle, 0u, 0u, 0u);
    } else {
        hits.data[i].t_u_v = vec4(-1.0, 0.0, 0.0, 0.0);
        hits.data[i].triangle = uvec4(0xffffffffu, 0u, 0u, 0u);
    }
}
