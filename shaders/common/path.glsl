// The tracer's path loop from a primary hit, shared by the plain kernel and the A-SVGF variant
// that re-shades last frame's surfaces (passes/trace.comp): next-event estimation at every hit,
// BRDF-sampled continuation. Needs scene.glsl, random.glsl, brdf.glsl and lights.glsl first.
#ifndef FOVEA_PATH_GLSL
#define FOVEA_PATH_GLSL

// Rays traced by this invocation, for the tracer's exact counters.
uint shadow_rays = 0u;
uint continuation_rays = 0u;

bool visible(vec3 p, vec3 n, LightSample ls) {
    Hit h;
    shadow_rays++;
    return !bvh_trace(offset_ray(p, n), ls.direction, 0.0, ls.distance * (1.0 - 1e-4), true, h);
}

// The analytic sky (fovea_scene::Sky) seen by a ray leaving the scene along `dir`: horizon to
// zenith with √(sin elevation) above the horizon, constant below. Black when the scene has none.
vec3 sky_radiance(vec3 dir) {
    if (frame.data.sky_ground.w == 0.0) return vec3(0.0);
    if (dir.y < 0.0) return frame.data.sky_ground.rgb;
    return mix(frame.data.sky_horizon.rgb, frame.data.sky_zenith.rgb, sqrt(dir.y));
}

vec3 direct_light(Surface s, vec3 v, inout uint rng) {
    LightSample ls;
    if (!sample_light(s.position, rng, ls)) return vec3(0.0);
    vec3 f = brdf_eval_cos(s, v, ls.direction);
    if (all(equal(f, vec3(0.0))) || !visible(s.position, s.geometric_normal, ls)) return vec3(0.0);
    return f * ls.radiance_over_pdf;
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
    for (uint depth_i = 1u; depth_i < max_depth; ++depth_i) {
        color += throughput * direct_light(s, v, rng);
        // The sky is not sampled by next-event estimation, so at the last vertex a BRDF ray still
        // looks for it (the sky's "direct light"); a surface it hits adds nothing there.
        bool last = depth_i + 1u >= max_depth;
        if (last && frame.data.sky_ground.w == 0.0) break;
        vec3 l, weight;
        bool delta;
        vec3 u3 = vec3(rng_next2(rng), rng_next(rng));
        if (!brdf_sample(s, v, u3, l, weight, delta)) break;
        throughput *= weight;
        vec3 o = offset_ray(s.position, s.geometric_normal);
        continuation_rays++;
        // At the last vertex only escaping matters: the cheaper any-hit test answers that.
        if (!bvh_trace(o, l, 0.0, 1e30, last, hit)) {
            // Next-event estimation never samples the sky, so the BRDF-sampled ray that escapes
            // is its only estimator (no MIS weight needed).
            color += throughput * sky_radiance(l);
            break;
        }
        if (last) break;
        cone.x += cone.y * hit.t;
        s = fetch_surface(hit, l, cone.x);
        // A mirror bounce cannot be found by next-event estimation: count what it sees.
        if (delta) color += throughput * s.emission;
        v = -l;
    }
    return color;
}

#endif
