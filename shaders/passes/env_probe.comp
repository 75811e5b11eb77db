#version 460
// Evaluates environment.glsl on a list of points so the device test (tests/environment_map.rs)
// can compare it with the Rust twin (fovea_scene::environment) point by point:
// in[i].xyz: a world direction → out[2i] = (texel index, solid-angle pdf, u, v) of env_pdf's lookup;
// in[i] as four uniform numbers → out[2i+1] = env_sample's world direction and pdf.
#include "../common/layouts.glsl"
#include "../common/environment.glsl"

layout(local_size_x = WORKGROUP_1D) in;
layout(push_constant) uniform Push { EnvProbePush p; } push;
layout(std430, set = 0, binding = 0) readonly buffer PointBuffer { vec4 data[]; } points;
layout(std430, set = 0, binding = 1) writeonly buffer OutBuffer { vec4 data[]; } mapped;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.p.config.x) return;
    vec4 env = push.p.environment;
    uvec4 map = push.p.environment_map;
    vec4 q = points.data[i];
    vec2 uv = env_direction_to_uv(env_to_local(env, normalize(q.xyz)));
    mapped.data[2u * i] = vec4(float(env_texel_index(uv, map)), env_pdf(env, map, normalize(q.xyz)), uv);
    vec3 dir;
    vec3 radiance;
    float pdf;
    if (!env_sample(env, map, q, dir, radiance, pdf)) pdf = 0.0;
    mapped.data[2u * i + 1u] = vec4(dir, pdf);
}
