// The tracer's path loop from a primary hit, shared by the plain kernel and the A-SVGF variant
// that re-shades last frame's surfaces (passes/trace.comp): next-event estimation at every hit,
// BRDF-sampled continuation. Needs scene.glsl, random.glsl, brdf.glsl and lights.glsl first.
#ifndef FOVEA_PATH_GLSL
#define FOVEA_PATH_GLSL

// Whether the path leaves the primary hit's direct light (RESAMPLED_DI) and bounce (RESAMPLED_GI)
// to the resampling passes. A variable only where A-SVGF's gradient samples also need the plain
// path's estimate (trace.comp's `plain_path_estimate`); a constant everywhere else.
#if defined(RESAMPLED_DI) && defined(TRACE_GRADIENTS)
bool path_defers_to_resampling = true;
#elif defined(RESAMPLED_DI)
const bool path_defers_to_resampling = true;
#endif

// Rays traced by this invocation, for the tracer's exact counters.
uint shadow_rays = 0u;
uint continuation_rays = 0u;

#if defined(RESAMPLED_GI)
// ReSTIR GI's initial sample (GiSampleGpu), which shade_path fills instead of adding the bounce's
// light: the secondary hit, its normal facing the primary hit, the bounce's density (0: none) and
// the radiance the rest of the path gathered there; for a bounce that escaped, its direction, a
// zero normal and the environment's radiance along it.
vec4 gi_point = vec4(0.0);
vec3 gi_normal = vec3(0.0);
vec3 gi_radiance = vec3(0.0);
#endif

bool visible(vec3 p, vec3 n, LightSample ls) {
    Hit h;
    shadow_rays++;
    return !bvh_trace(offset_ray(p, n), ls.direction, 0.0, ls.distance * (1.0 - 1e-4), true, h);
}

// What a ray leaving the scene along `dir` sees: the environment map (a loaded one or the
// analytic sky baked into one, fovea_scene::Scene::environment_map); black when there is none.
vec3 sky_radiance(vec3 dir) {
    return env_radiance(frame.data.environment, frame.data.environment_map, dir);
}

// The power heuristic (Veach, β = 2): the weight of the strategy with density `a` against `b`.
float mis_power(float a, float b) {
    float a2 = a * a;
    return a2 / max(a2 + b * b, 1e-30);
}

vec3 direct_light(Surface s, vec3 v, inout uint rng) {
    LightSample ls;
    if (!sample_light(s.position, rng, ls)) return vec3(0.0);
    vec3 f = brdf_eval_cos(s, v, ls.direction);
    if (all(equal(f, vec3(0.0))) || !visible(s.position, s.geometric_normal, ls)) return vec3(0.0);
    // The environment is also found by the BRDF-sampled ray: each strategy keeps its MIS share.
    float w = ls.mis_pdf > 0.0 ? mis_power(ls.mis_pdf, brdf_pdf(s, v, ls.direction)) : 1.0;
    return f * ls.radiance_over_pdf * w;
}

// Radiance arriving along `dir` from the primary hit `s` (its emission included), paths of up to
// `max_depth` vertices; every random number comes from `rng`, so a surface and a state give one path.
// `cone`: the ray cone's width at `s` and its spread angle (texture level of detail; zero: level
// 0). Bounces keep the primary spread: no widening by curvature or roughness, so a bounce's
// textures are never blurrier than the pixel's cone would make them.
vec3 shade_path(Surface s, vec3 dir, uint max_depth, vec2 cone, inout uint rng) {
    vec3 color = vec3(0.0);
    if (max_depth >= 1u) color += s.emission;
    vec3 throughput = vec3(1.0);
    vec3 v = -dir;
    Hit hit;
    float min_pdf = 1e30;   // smallest bounce density so far (regularise)
#if defined(RESAMPLED_GI)
    // The colour gathered before the bounce's secondary hit; -1: the path was not split there.
    vec3 before_bounce = vec3(-1.0);
#endif
    for (uint depth_i = 1u; depth_i < max_depth; ++depth_i) {
#if defined(RESAMPLED_DI)
        // The primary hit's direct light is the resampling passes' (shaders/passes/resample_*).
        if (depth_i > 1u || !path_defers_to_resampling)
#endif
        color += throughput * direct_light(s, v, rng);
        // The environment's second strategy: at the last vertex a BRDF ray still looks for it
        // (its MIS share of the direct light); a surface it hits adds nothing there.
        bool last = depth_i + 1u >= max_depth;
        if (last && frame.data.environment_map.z == 0u) break;
        vec3 l, weight;
        bool delta;
        float pdf;
        vec3 u3 = vec3(rng_next2(rng), rng_next(rng));
        if (!brdf_sample(s, v, u3, l, weight, delta, pdf)) break;
        min_pdf = min(min_pdf, pdf);
        throughput *= weight;
        vec3 o = offset_ray(s.position, s.geometric_normal);
        continuation_rays++;
        // At the last vertex only escaping matters: the cheaper any-hit test answers that.
        if (!bvh_trace(o, l, 0.0, 1e30, last, hit)) {
#if defined(RESAMPLED_GI)
            // The primary hit's bounce escaped: ReSTIR GI's sample is the environment along l
            // (its MIS weight against next-event estimation is taken where the sample is used).
            if (depth_i == 1u && !delta && !last && path_defers_to_resampling) {
                gi_point = vec4(l, pdf);
                gi_normal = vec3(0.0);
                gi_radiance = sky_radiance(l);
                if (any(isnan(gi_radiance)) || any(isinf(gi_radiance))) gi_point.w = 0.0;
                break;
            }
#endif
            // Next-event estimation samples the environment too (when light selection can pick
            // it): weigh this estimate against it. A mirror bounce is this ray's alone.
            float light_pdf = delta ? 0.0 : frame.data.environment.w * env_pdf(frame.data.environment, frame.data.environment_map, l);
            float w = light_pdf > 0.0 ? mis_power(brdf_pdf(s, v, l), light_pdf) : 1.0;
            color += throughput * sky_radiance(l) * w;
            break;
        }
        if (last) break;
        cone.x += cone.y * hit.t;
        s = fetch_surface(hit, l, cone.x);
        regularise(s, min_pdf, frame.data.path.x);
        // A mirror bounce cannot be found by next-event estimation: count what it sees.
        if (delta) color += throughput * s.emission;
#if defined(RESAMPLED_GI)
        // A non-mirror bounce from the primary hit is ReSTIR GI's sample: what the path gathers
        // from here on is the radiance leaving the secondary hit toward the primary one (the
        // resampling passes weigh it by the primary hit's BRDF). Mirror bounces stay the path's.
        if (depth_i == 1u && !delta && path_defers_to_resampling) {
            before_bounce = color;
            throughput = vec3(1.0);
            gi_point = vec4(s.position, pdf);
            gi_normal = s.geometric_normal;
        }
#endif
        v = -l;
    }
#if defined(RESAMPLED_GI)
    if (before_bounce.x >= 0.0) {
        gi_radiance = color - before_bounce;
        if (any(isnan(gi_radiance)) || any(isinf(gi_radiance))) gi_point.w = 0.0;
        return before_bounce;
    }
#endif
    return color;
}

#endif
