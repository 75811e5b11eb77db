// Next-event estimation: pick one light from the alias table (probability ∝ power), then a point
// on it. Emissive triangles are sampled uniformly by area; punctual lights follow KHR_lights_punctual;
// the environment map by its luminance (environment.glsl), one entry of the same table.
#ifndef FOVEA_LIGHTS_GLSL
#define FOVEA_LIGHTS_GLSL

#include "environment.glsl"

struct LightSample {
    vec3 direction;     // from the shading point toward the light
    float distance;     // to the light point (1e30 for directional and the environment)
    vec3 radiance_over_pdf; // incident radiance × geometry term / (selection pdf × point pdf)
    // Selection × solid-angle pdf for lights a BRDF-sampled ray can also find (the environment),
    // for the MIS weight in path.glsl; 0 for lights only next-event estimation counts.
    float mis_pdf;
};

uint pick_light(inout uint rng, out float select_pdf) {
    uint count = frame.data.counts.x;
    float u = rng_next(rng) * float(count);
    uint i = min(uint(u), count - 1u);
    LightGpu l = lights.data[i];
    if (fract(u) >= l.sampling.x) i = l.kind_index.z;
    select_pdf = lights.data[i].sampling.y;
    return i;
}

// KHR_lights_punctual's recommended range window.
float range_window(float d, float range) {
    if (range <= 0.0) return 1.0;
    float r = d / range;
    float w = clamp(1.0 - r * r * r * r, 0.0, 1.0);
    return w * w;
}

bool sample_light(vec3 p, inout uint rng, out LightSample ls) {
    ls.radiance_over_pdf = vec3(0.0);
    ls.distance = 0.0;
    ls.direction = vec3(0.0, 1.0, 0.0);
    ls.mis_pdf = 0.0;
    if (frame.data.counts.x == 0u) return false;
    float select_pdf;
    LightGpu l = lights.data[pick_light(rng, select_pdf)];
    if (select_pdf <= 0.0) return false;
    uint kind = l.kind_index.x;
    if (kind == LIGHT_KIND_TRIANGLE) {
        // An instanced emitter is listed once per instance, by placed id, and sampled in world space.
        PlacedTriangle placed = placed_triangle(l.kind_index.y);
        vec3 a = placed.a.position_u.xyz, b = placed.b.position_u.xyz, c = placed.c.position_u.xyz;
        vec2 u = rng_next2(rng);
        float su = sqrt(u.x);
        Hit h;
        h.u = su * (1.0 - u.y);
        h.v = su * u.y;
        h.triangle = l.kind_index.y;
        vec3 q = (1.0 - h.u - h.v) * a + h.u * b + h.v * c;
        vec3 to = q - p;
        float d2 = dot(to, to);
        if (d2 <= 0.0) return false;
        ls.distance = sqrt(d2);
        ls.direction = to / ls.distance;
        vec3 cr = cross(b - a, c - a);
        float area = 0.5 * length(cr);
        float cos_light = abs(dot(cr / (2.0 * area), ls.direction));
        Surface e = fetch_surface(h, ls.direction, 0.0);
        ls.radiance_over_pdf = e.emission * cos_light * area / (d2 * select_pdf);
        return cos_light > 0.0 && area > 0.0;
    }
    if (kind == LIGHT_KIND_ENVIRONMENT) {
        // environment.w = 0: BRDF-only (RenderSettings::environment_sampling), the pick is wasted.
        if (frame.data.environment.w == 0.0) return false;
        vec3 radiance;
        float pdf;
        vec4 u = vec4(rng_next2(rng), rng_next2(rng));
        if (!env_sample(frame.data.environment, frame.data.environment_map, u, ls.direction, radiance, pdf)) return false;
        ls.distance = 1e30;
        ls.mis_pdf = select_pdf * pdf;
        ls.radiance_over_pdf = radiance / ls.mis_pdf;
        return true;
    }
    if (kind == LIGHT_KIND_DIRECTIONAL) {
        ls.direction = -l.direction.xyz;
        ls.distance = 1e30;
        ls.radiance_over_pdf = l.intensity.rgb / select_pdf;
        return true;
    }
    vec3 to = l.position.xyz - p;
    float d2 = dot(to, to);
    if (d2 <= 0.0) return false;
    ls.distance = sqrt(d2);
    ls.direction = to / ls.distance;
    float atten = range_window(ls.distance, l.position.w) / d2;
    if (kind == LIGHT_KIND_SPOT) {
        float cd = dot(l.direction.xyz, -ls.direction);
        float t = clamp((cd - l.direction.w) / max(l.intensity.w - l.direction.w, 1e-4), 0.0, 1.0);
        atten *= t * t;
    }
    ls.radiance_over_pdf = l.intensity.rgb * atten / select_pdf;
    return atten > 0.0;
}

#endif
