// The environment map: what escaping rays see, and its importance sampling for next-event
// estimation. The Rust twin (mapping, alias sampling, pdf) is fovea_scene::environment; the
// environment probe kernel (passes/env_probe.comp) proves them equal on the device.
// Mapping: u = azimuth / 2π with the map-local direction (−sin θ sin φ, cos θ, sin θ cos φ),
// v = θ / π from +Y; the map's rotation about +Y is (cos, sin) in `env.xy`.
// Every function takes FrameData's two environment slots (`env`, `map`) as arguments so that
// the probe can call them with push constants.
// Binding 24: above every pass-specific binding of the tracer (10..23).
#ifndef FOVEA_ENVIRONMENT_GLSL
#define FOVEA_ENVIRONMENT_GLSL

#include "layouts.glsl"

layout(std430, set = 0, binding = 24) readonly buffer EnvironmentBuffer { EnvTexelGpu data[]; } environment;

const float ENV_PI = 3.14159265358979;

vec3 env_to_local(vec4 env, vec3 d) {
    return vec3(env.x * d.x - env.y * d.z, d.y, env.y * d.x + env.x * d.z);
}

vec3 env_to_world(vec4 env, vec3 d) {
    return vec3(env.x * d.x + env.y * d.z, d.y, -env.y * d.x + env.x * d.z);
}

vec2 env_direction_to_uv(vec3 d) {
    float u = atan(-d.x, d.z) / (2.0 * ENV_PI);
    return vec2(u < 0.0 ? u + 1.0 : u, acos(clamp(d.y, -1.0, 1.0)) / ENV_PI);
}

vec3 env_uv_to_direction(vec2 uv) {
    float phi = 2.0 * ENV_PI * uv.x;
    float theta = ENV_PI * uv.y;
    float st = sin(theta);
    return vec3(-st * sin(phi), cos(theta), st * cos(phi));
}

uint env_texel_index(vec2 uv, uvec4 map) {
    uint x = min(uint(uv.x * float(map.x)), map.x - 1u);
    uint y = min(uint(uv.y * float(map.y)), map.y - 1u);
    return y * map.x + x;
}

// A texel's probability as a density per unit solid angle at polar coordinate v
// (uniform in (u, v) inside the texel; dω = 2π² sin θ du dv).
float env_pdf_solid_angle(float p, float v, uvec4 map) {
    float sin_theta = sin(ENV_PI * v);
    if (sin_theta <= 1e-7) return 0.0;
    return p * float(map.x * map.y) / (2.0 * ENV_PI * ENV_PI * sin_theta);
}

// Radiance from world direction `dir` (black without an environment).
vec3 env_radiance(vec4 env, uvec4 map, vec3 dir) {
    if (map.z == 0u) return vec3(0.0);
    return environment.data[env_texel_index(env_direction_to_uv(env_to_local(env, dir)), map)].radiance.rgb * env.z;
}

// Density of env_sample per unit solid angle for world direction `dir` (selection not included).
float env_pdf(vec4 env, uvec4 map, vec3 dir) {
    if (map.z == 0u) return 0.0;
    vec2 uv = env_direction_to_uv(env_to_local(env, dir));
    return env_pdf_solid_angle(environment.data[env_texel_index(uv, map)].radiance.w, uv.y, map);
}

// A direction ∝ luminance × solid angle from four uniform numbers: texel slot, alias choice,
// position inside the texel. Returns false where the density vanishes (a pole).
bool env_sample(vec4 env, uvec4 map, vec4 u, out vec3 dir, out vec3 radiance, out float pdf) {
    uint n = map.x * map.y;
    uint i = min(uint(u.x * float(n)), n - 1u);
    EnvTexelGpu t = environment.data[i];
    if (u.y >= uintBitsToFloat(t.alias.y)) {
        i = t.alias.x;
        t = environment.data[i];
    }
    vec2 uv = vec2((float(i % map.x) + u.z) / float(map.x), (float(i / map.x) + u.w) / float(map.y));
    dir = env_to_world(env, env_uv_to_direction(uv));
    radiance = t.radiance.rgb * env.z;
    pdf = env_pdf_solid_angle(t.radiance.w, uv.y, map);
    return pdf > 0.0;
}

#endif
