// ReSTIR GI (Ouyang et al. 2021) at the primary hit: the bounce's secondary hit and its radiance
// as the resampled sample, its target function at a primary hit, the reconnection Jacobian that
// moves it between primary hits, and its reservoirs (docs/design/resampling.md).
// Needs scene.glsl, random.glsl, brdf.glsl, lights.glsl, path.glsl and resampling.glsl first.
#ifndef FOVEA_RESAMPLING_GI_GLSL
#define FOVEA_RESAMPLING_GI_GLSL

// A secondary hit with the radiance it sends toward the primary hits that reuse it, or the
// environment along a direction (a bounce that escaped: `normal` zero, `point` the direction).
struct GiSample {
    vec3 point;
    vec3 normal;     // geometric, facing the primary hit that traced it; zero: the environment
    vec3 radiance;
};

bool gi_is_environment(GiSample y) {
    return y.normal == vec3(0.0);
}

struct GiReservoir {
    GiSample y;
    bool full;
    float weight_sum;
    float m;
    float target;
};

GiReservoir gi_reservoir_empty() {
    GiReservoir r;
    r.y.point = vec3(0.0);
    r.y.normal = vec3(0.0);
    r.y.radiance = vec3(0.0);
    r.full = false;
    r.weight_sum = 0.0;
    r.m = 0.0;
    r.target = 0.0;
    return r;
}

// As reservoir_update (resampling.glsl), for a secondary hit.
bool gi_reservoir_update(inout GiReservoir r, GiSample y, float w, float target, float u) {
    if (!reservoir_accepts(r.weight_sum, w, u)) return false;
    r.y = y;
    r.target = target;
    r.full = true;
    return true;
}

// The sample's contribution f·cos·L at surface `s` seen from `v` (per solid angle: divided by the
// density, or times W, it estimates the bounce's light); zero where the secondary hit lies below
// the surface or faces away from it. The radiance is taken to leave the secondary hit alike toward
// every primary hit (exact for diffuse secondary surfaces, ReSTIR GI's approximation otherwise).
vec3 gi_contribution(Surface s, vec3 v, GiSample y) {
    if (gi_is_environment(y)) {
        // The environment's BRDF-sampled share: the power heuristic against next-event
        // estimation's density for this direction, at this surface (as the path weighs it).
        vec3 l = y.point;
        float light_pdf = frame.data.environment.w * env_pdf(frame.data.environment, frame.data.environment_map, l);
        float w = light_pdf > 0.0 ? mis_power(brdf_pdf(s, v, l), light_pdf) : 1.0;
        vec3 c = brdf_eval_cos(s, v, l) * y.radiance * w;
        return (any(isnan(c)) || any(isinf(c))) ? vec3(0.0) : c;
    }
    vec3 to = y.point - s.position;
    float d2 = dot(to, to);
    if (d2 <= 0.0) return vec3(0.0);
    vec3 l = to * inversesqrt(d2);
    if (dot(y.normal, -l) <= 0.0) return vec3(0.0);
    vec3 c = brdf_eval_cos(s, v, l) * y.radiance;
    return (any(isnan(c)) || any(isinf(c))) ? vec3(0.0) : c;
}

// |∂ω_to/∂ω_from| of the reconnection shift: the secondary hit `y` seen from the primary hit
// `from`, reused at `to` (the ratio of the solid angles one patch of the secondary surface spans
// from the two). Zero where either primary hit lies behind the secondary surface; 1 for the
// environment (the direction stays).
float gi_jacobian(vec3 from, vec3 to, GiSample y) {
    if (gi_is_environment(y)) return 1.0;
    vec3 a = from - y.point, b = to - y.point;
    float da2 = dot(a, a), db2 = dot(b, b);
    if (da2 <= 0.0 || db2 <= 0.0) return 0.0;
    float ca = dot(y.normal, a) * inversesqrt(da2), cb = dot(y.normal, b) * inversesqrt(db2);
    if (ca <= 0.0 || cb <= 0.0) return 0.0;
    return (cb / ca) * (da2 / db2);
}

// Is the segment from the primary hit `p` (normal `n`) to the secondary hit unoccluded?
bool gi_visible(vec3 p, vec3 n, GiSample y) {
    vec3 o = offset_ray(p, n);
    Hit h;
    if (gi_is_environment(y)) {
        shadow_rays++;
        return !bvh_trace(o, y.point, 0.0, 1e30, true, h);
    }
    vec3 e = offset_ray(y.point, y.normal);
    vec3 d = e - o;
    float len = length(d);
    if (!(len > 0.0)) return false;
    shadow_rays++;
    return !bvh_trace(o, d / len, 0.0, len * (1.0 - 1e-3), true, h);
}

// Could the reservoir of the primary hit `p` (shading normal `n`, seen from `v`) have chosen
// `y`: does its bounce reach the secondary hit's front side from its upper hemisphere, without an
// occluder? For the 1/Z normalisation (the point's BRDF itself is not needed).
bool gi_sample_reaches(vec3 p, vec3 n, vec3 v, GiSample y) {
    if (gi_is_environment(y)) return dot(n, y.point) > 0.0 && dot(n, v) > 0.0 && gi_visible(p, n, y);
    vec3 l = y.point - p;
    return dot(n, l) > 0.0 && dot(n, v) > 0.0 && dot(y.normal, -l) > 0.0 && gi_visible(p, n, y);
}

GiSample gi_sample_of(GiReservoirGpu g) {
    GiSample y;
    y.point = g.point.xyz;
    y.normal = g.normal.xyz;
    y.radiance = g.radiance.rgb;
    return y;
}

GiReservoirGpu gi_reservoir_pack(GiReservoir r, float contribution_weight, uvec4 surface, vec3 position) {
    GiReservoirGpu g;
    g.point = vec4(r.y.point, contribution_weight);
    g.normal = vec4(r.y.normal, r.m);
    g.radiance = vec4(r.y.radiance, r.full ? r.target : 0.0);
    g.surface = surface;
    g.position = vec4(position, 0.0);
    return g;
}

GiReservoirGpu gi_reservoir_none() {
    GiReservoirGpu g;
    g.point = vec4(0.0);
    g.normal = vec4(0.0);
    g.radiance = vec4(0.0);
    g.surface = uvec4(0u);
    g.position = vec4(0.0);
    return g;
}

#endif
