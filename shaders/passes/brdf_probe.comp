#version 460
// Draws directions from brdf.glsl's brdf_sample for a list of random triples, so the device test
// (tests/brdf_sampling.rs) can hold the sampler to its density with a χ² goodness-of-fit test:
// randoms[i].xyz = u → directions[i] = (l, pdf): pdf as the sampler returns it, 0 when it ends
// the path, −1 for a mirror (delta) sample.
#include "../common/layouts.glsl"
#include "../common/scene.glsl"
#include "../common/brdf.glsl"

layout(local_size_x = WORKGROUP_1D) in;
layout(push_constant) uniform Push { BrdfProbePush p; } push;
// Above the scene's binding numbers (scene.glsl), which this kernel declares but never reads.
layout(std430, set = 0, binding = 30) readonly buffer RandomBuffer { vec4 data[]; } randoms;
layout(std430, set = 0, binding = 31) writeonly buffer DirectionBuffer { vec4 data[]; } directions;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.p.config.x) return;
    Surface s;
    s.position = vec3(0.0);
    s.geometric_normal = push.p.normal.xyz;
    s.normal = push.p.normal.xyz;
    s.uv = vec2(0.0);
    s.base_color = push.p.base_color_metallic.xyz;
    s.metallic = push.p.base_color_metallic.w;
    s.roughness = push.p.view_roughness.w;
    s.emission = vec3(0.0);
    s.dielectric_f0 = push.p.f0_specular.xyz;
    s.specular_factor = push.p.f0_specular.w;
    s.material = 0u;
    s.mesh = 0u;
    vec3 l;
    vec3 weight;
    bool delta;
    float pdf;
    bool kept = brdf_sample(s, push.p.view_roughness.xyz, randoms.data[i].xyz, l, weight, delta, pdf);
    directions.data[i] = vec4(l, kept ? (delta ? -1.0 : pdf) : 0.0);
}
