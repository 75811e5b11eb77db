// ReSTIR DI (Bitterli et al. 2020) at the primary hit: light samples as points of the light
// table, the target function p̂, weighted reservoirs and their streaming update, and the primary
// surface the resampling passes re-fetch from the G-buffer (docs/design/resampling.md).
// Needs scene.glsl, random.glsl, brdf.glsl, lights.glsl and path.glsl first.
#ifndef FOVEA_RESAMPLING_GLSL
#define FOVEA_RESAMPLING_GLSL

// A light sample that evaluates exactly at any shading point: the light table entry and, for an
// emissive triangle, the barycentrics of the point; for the environment, its direction
// (octahedral); nothing more for punctual and directional lights.
struct LightPoint {
    uint light;   // light table entry
    vec2 data;
};

vec2 octahedral_encode(vec3 d) {
    d /= abs(d.x) + abs(d.y) + abs(d.z);
    vec2 o = d.xy;
    if (d.z < 0.0) o = (1.0 - abs(d.yx)) * vec2(d.x >= 0.0 ? 1.0 : -1.0, d.y >= 0.0 ? 1.0 : -1.0);
    return o;
}

vec3 octahedral_decode(vec2 o) {
    vec3 n = vec3(o, 1.0 - abs(o.x) - abs(o.y));
    float t = max(-n.z, 0.0);
    n.xy += vec2(n.x >= 0.0 ? -t : t, n.y >= 0.0 ? -t : t);
    return normalize(n);
}

// A candidate as next-event estimation draws it (lights.glsl: the entry by power through the
// alias table, a triangle's point uniform by area, the environment by luminance); false when the
// draw gives no sample (the environment not sampled, a pole). Draws 1 + 2 numbers (1 + 4 for the
// environment) from `rng`.
bool draw_light_point(inout uint rng, out LightPoint lp) {
    lp.light = 0u;
    lp.data = vec2(0.0);
    if (frame.data.counts.x == 0u) return false;
    float select_pdf;
    lp.light = pick_light(rng, select_pdf);
    if (select_pdf <= 0.0) return false;
    uint kind = lights.data[lp.light].kind_index.x;
    if (kind == LIGHT_KIND_TRIANGLE) {
        vec2 u = rng_next2(rng);
        float su = sqrt(u.x);
        lp.data = vec2(su * (1.0 - u.y), su * u.y);
        return true;
    }
    if (kind == LIGHT_KIND_ENVIRONMENT) {
        if (frame.data.environment.w == 0.0) return false;
        vec4 u = vec4(rng_next2(rng), rng_next2(rng));
        vec3 dir, radiance;
        float pdf;
        if (!env_sample(frame.data.environment, frame.data.environment_map, u, dir, radiance, pdf)) return false;
        lp.data = octahedral_encode(dir);
        return true;
    }
    return true;
}

// The radiance an emissive triangle sends along `dir` (from the shading point toward the light)
// from its point at barycentrics `bary`: exactly what next-event estimation reads there
// (fetch_surface's emission, texture level 0), without the rest of the surface.
vec3 emitter_radiance(PlacedTriangle placed, vec2 bary, vec3 dir) {
    vec3 a = placed.a.position_u.xyz, b = placed.b.position_u.xyz, c = placed.c.position_u.xyz;
    MaterialGpu m = materials.data[placed.tri.vertices.w & 0xffffu];
    vec3 e = m.emissive.rgb;
    if (m.textures.w != NO_TEXTURE) {
        vec3 w = vec3(1.0 - bary.x - bary.y, bary);
        vec2 uv = w.x * vec2(placed.a.position_u.w, placed.a.normal_v.w) + w.y * vec2(placed.b.position_u.w, placed.b.normal_v.w) + w.z * vec2(placed.c.position_u.w, placed.c.normal_v.w);
        e *= sample_texture(m.textures.w, uv, true).rgb;
    }
    vec3 ng = cross(b - a, c - a);
    if (placed.mirrored) ng = -ng;
    bool front = dot(ng, dir) < 0.0;
    return (front || (m.textures2.z & MATERIAL_DOUBLE_SIDED) != 0u) ? e : vec3(0.0);
}

// The light point seen from `p`, unshadowed. `radiance`: what reaches p per unit of the light's
// own measure (a triangle: emitted radiance × cos at the light / distance², per area; the
// environment: radiance per solid angle; a punctual or directional light: its intensity with
// attenuation); `source_pdf`: the density draw_light_point gives it in that measure (selection ×
// point); `ls`: direction, distance and the MIS density (environment) as sample_light's;
// `solid_angle_to_measure`: what turns a solid-angle density at p into the light's measure
// (cos at the light / distance² for a triangle, 1 for the environment, 0 for punctual and
// directional lights, which no BRDF-sampled ray finds).
bool evaluate_light_point(vec3 p, LightPoint lp, out LightSample ls, out vec3 radiance, out float source_pdf, out float solid_angle_to_measure) {
    ls.direction = vec3(0.0, 1.0, 0.0);
    ls.distance = 0.0;
    ls.radiance_over_pdf = vec3(0.0);
    ls.mis_pdf = 0.0;
    radiance = vec3(0.0);
    source_pdf = 0.0;
    solid_angle_to_measure = 0.0;
    LightGpu l = lights.data[lp.light];
    float select_pdf = l.sampling.y;
    if (select_pdf <= 0.0) return false;
    uint kind = l.kind_index.x;
    if (kind == LIGHT_KIND_TRIANGLE) {
        PlacedTriangle placed = placed_triangle(l.kind_index.y);
        vec3 a = placed.a.position_u.xyz, b = placed.b.position_u.xyz, c = placed.c.position_u.xyz;
        vec3 q = (1.0 - lp.data.x - lp.data.y) * a + lp.data.x * b + lp.data.y * c;
        vec3 to = q - p;
        float d2 = dot(to, to);
        vec3 cr = cross(b - a, c - a);
        float area = 0.5 * length(cr);
        if (d2 <= 0.0 || area <= 0.0) return false;
        ls.distance = sqrt(d2);
        ls.direction = to / ls.distance;
        float cos_light = abs(dot(cr / (2.0 * area), ls.direction));
        solid_angle_to_measure = cos_light / d2;
        radiance = emitter_radiance(placed, lp.data, ls.direction) * solid_angle_to_measure;
        source_pdf = select_pdf / area;
    } else if (kind == LIGHT_KIND_ENVIRONMENT) {
        if (frame.data.environment.w == 0.0) return false;
        ls.direction = octahedral_decode(lp.data);
        ls.distance = 1e30;
        radiance = env_radiance(frame.data.environment, frame.data.environment_map, ls.direction);
        source_pdf = select_pdf * env_pdf(frame.data.environment, frame.data.environment_map, ls.direction);
        ls.mis_pdf = source_pdf;
        solid_angle_to_measure = 1.0;
    } else if (kind == LIGHT_KIND_DIRECTIONAL) {
        ls.direction = -l.direction.xyz;
        ls.distance = 1e30;
        radiance = l.intensity.rgb;
        source_pdf = select_pdf;
    } else {
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
        radiance = l.intensity.rgb * atten;
        source_pdf = select_pdf;
    }
    if (source_pdf <= 0.0 || all(equal(radiance, vec3(0.0)))) return false;
    ls.radiance_over_pdf = radiance / source_pdf;
    return true;
}

float resampling_luminance(vec3 c) {
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}

// The light point's unshadowed contribution at surface `s` seen from `v`, in the light's
// measure: f·cos · radiance, weighted for the environment by next-event estimation's MIS share
// against the BRDF-sampled ray that the path still traces (path.glsl), so that the two strategies
// still sum to one. Zero where the light does not reach the surface's upper side.
// `brdf_pdf_here`: the density of a BRDF candidate for the light point in the light's measure
// (zero for the environment and punctual lights, which BRDF candidates never take).
vec3 light_point_terms(Surface s, vec3 v, LightPoint lp, out LightSample ls, out float source_pdf, out float brdf_pdf_here) {
    vec3 radiance;
    float to_measure;
    brdf_pdf_here = 0.0;
    if (!evaluate_light_point(s.position, lp, ls, radiance, source_pdf, to_measure)) return vec3(0.0);
    vec3 f = brdf_eval_cos(s, v, ls.direction);
    float p_brdf = to_measure > 0.0 ? brdf_pdf(s, v, ls.direction) : 0.0;
    brdf_pdf_here = p_brdf * to_measure;
    float w = 1.0;
    if (ls.mis_pdf > 0.0) {
        // The environment: its BRDF-sampled share stays the path's, not a BRDF candidate's.
        w = mis_power(ls.mis_pdf, p_brdf);
        brdf_pdf_here = 0.0;
    }
    vec3 c = f * radiance * w;
    return (any(isnan(c)) || any(isinf(c))) ? vec3(0.0) : c;
}

vec3 light_point_contribution(Surface s, vec3 v, LightPoint lp, out LightSample ls, out float source_pdf) {
    float brdf_pdf_here;
    return light_point_terms(s, v, lp, ls, source_pdf, brdf_pdf_here);
}

// A candidate's resampling weight and p̂ (`target`) among `n_light` candidates drawn from the
// light table and `n_brdf` drawn by sampling the BRDF: MIS-weighted RIS with the balance
// heuristic, p̂·M / (N_L·p_L + N_B·p_B) with both densities in the light's measure and
// M = N_L + N_B, so that dividing the stream's weight sum by M·p̂ gives W as without BRDF
// candidates (Talbot et al. 2005; Bitterli et al. 2020, §4.1).
float light_point_candidate(Surface s, vec3 v, LightPoint lp, float n_light, float n_brdf, out LightSample ls, out float target) {
    float source_pdf, p_brdf;
    target = resampling_luminance(light_point_terms(s, v, lp, ls, source_pdf, p_brdf));
    float density = n_light * source_pdf + n_brdf * p_brdf;
    return (target > 0.0 && density > 0.0) ? target * (n_light + n_brdf) / density : 0.0;
}

// The light table entry of the emissive placed triangle `id`: the table lists emissive
// triangles first, by ascending placed id (fovea_scene::lights::build_light_table_scaled), so a
// binary search over that prefix finds it; false where the triangle is not in the table.
bool triangle_light_entry(uint id, out uint entry) {
    uint lo = 0u, hi = frame.data.counts.x;
    while (lo < hi) {
        uint mid = (lo + hi) >> 1u;
        uvec4 k = lights.data[mid].kind_index;
        if (k.x == LIGHT_KIND_TRIANGLE && k.y < id) lo = mid + 1u; else hi = mid;
    }
    entry = lo;
    if (lo >= frame.data.counts.x) return false;
    uvec4 k = lights.data[lo].kind_index;
    return k.x == LIGHT_KIND_TRIANGLE && k.y == id;
}

// A BRDF candidate: the point of an emissive triangle of the light table that a ray sampled
// from the BRDF at `s` reaches first; false where it finds none: another surface, the
// environment (its BRDF-sampled share is the path's own bounce, which ReSTIR GI resamples and
// reuses), a mirror lobe (next-event estimation cannot weigh it; the path keeps it), no
// direction. Draws 3 numbers and traces one ray; the point found is visible from `s`.
bool draw_brdf_light_point(Surface s, vec3 v, inout uint rng, out LightPoint lp) {
    lp.light = 0u;
    lp.data = vec2(0.0);
    vec3 u3 = vec3(rng_next2(rng), rng_next(rng));
    vec3 l, weight;
    bool delta;
    float pdf;
    if (!brdf_sample(s, v, u3, l, weight, delta, pdf) || delta) return false;
    Hit h;
    continuation_rays++;
    if (!bvh_trace(offset_ray(s.position, s.geometric_normal), l, 0.0, 1e30, false, h)) return false;
    if (!triangle_light_entry(h.triangle, lp.light)) return false;
    lp.data = vec2(h.u, h.v);
    return true;
}

// A weighted reservoir (Chao's streaming resampling): the chosen sample, the sum of the weights
// seen, the candidates it stands for, and p̂ of the chosen sample at this texel's surface.
struct Reservoir {
    LightPoint y;
    bool full;
    float weight_sum;
    float m;
    float target;
};

Reservoir reservoir_empty() {
    Reservoir r;
    r.y.light = 0u;
    r.y.data = vec2(0.0);
    r.full = false;
    r.weight_sum = 0.0;
    r.m = 0.0;
    r.target = 0.0;
    return r;
}

// Weighted reservoir sampling's step, for DI's and GI's reservoirs alike: adds a candidate's
// weight `w` to the running sum; whether it replaces the chosen sample (`u` uniform in [0, 1)).
bool reservoir_accepts(inout float weight_sum, float w, float u) {
    if (!(w > 0.0)) return false;
    weight_sum += w;
    return u * weight_sum < w;
}

// Streams one candidate of weight `w` (and p̂ here `target`) into `r`; `u` uniform in [0, 1).
// Returns whether it became the chosen sample.
bool reservoir_update(inout Reservoir r, LightPoint y, float w, float target, float u) {
    if (!reservoir_accepts(r.weight_sum, w, u)) return false;
    r.y = y;
    r.target = target;
    r.full = true;
    return true;
}

ReservoirGpu reservoir_pack(Reservoir r, float contribution_weight, uvec4 surface, vec3 position) {
    ReservoirGpu g;
    g.light_point = uvec4(r.full ? r.y.light + 1u : 0u, floatBitsToUint(r.y.data), 0u);
    g.weights = vec4(contribution_weight, r.m, r.target, 0.0);
    g.surface = surface;
    g.position = vec4(position, 0.0);
    return g;
}

ReservoirGpu reservoir_none() {
    ReservoirGpu g;
    g.light_point = uvec4(0u);
    g.weights = vec4(0.0);
    g.surface = uvec4(0u);
    g.position = vec4(0.0);
    return g;
}

// Could a reservoir owned by the point `p` (shading normal `n`, seen from `v`) have chosen light
// point `y`: does `y` send light there from the upper side (a non-zero target: the BRDF's
// hemisphere and the light's own support) and is it not occluded? For the 1/Z normalisation; the
// point's BRDF itself is not needed, the geometric normal is taken to be `n`.
bool light_point_reaches(vec3 p, vec3 n, vec3 v, LightPoint y) {
    LightSample ls;
    vec3 radiance;
    float source_pdf, to_measure;
    if (!evaluate_light_point(p, y, ls, radiance, source_pdf, to_measure)) return false;
    return dot(n, ls.direction) > 0.0 && dot(n, v) > 0.0 && visible(p, n, ls);
}

LightPoint reservoir_light_point(ReservoirGpu g) {
    LightPoint lp;
    lp.light = max(g.light_point.x, 1u) - 1u;
    lp.data = uintBitsToFloat(g.light_point.yz);
    return lp;
}

// The primary hit's surface at texel `t`, re-fetched as the tracer shaded it: its triangle from
// the G-buffer ids, barycentrics and ray-cone width from the tracer's primary-hit image, the
// direction from the camera-relative position.
Surface primary_surface(uint triangle, vec4 primary_hit, vec3 position, out vec3 dir) {
    dir = normalize(position);
    Hit h;
    h.t = length(position);
    h.u = primary_hit.x;
    h.v = primary_hit.y;
    h.triangle = triangle;
    return fetch_surface(h, dir, primary_hit.z);
}

#endif
