#version 460
// Path tracer, one sample per sampling-grid texel: primary ray, next-event estimation at every
// hit, BRDF-sampled continuation (real-time: depth 3 = one indirect bounce). Writes the per-sample
// G-buffer that the denoisers read, sized to the sampling grid.
// The *_gradients variants serve A-SVGF (Schied et al. 2018): a texel that the forward projection
// of last frame's samples chose (asvgf_forward.comp) also traces that frame's path again on that
// frame's surface with that frame's random state (apart from its own sample), and every texel
// writes the visibility (barycentrics, random state, and the luminance a next projection compares
// against) the next projection reads. Plain rendering keeps the variants without them and pays
// nothing. With resampling (*_resampled_gradients, *_resampled_gi_gradients) the texel's own
// sample is resampled as usual and the gradient compares plain path estimates instead: one texel
// per stratum (the stratum's source) and the gradient sample also trace the path as the plain
// kernel would (`plain_path_estimate`), with the same random state in both frames, so δ is the
// change of the light and never the reservoirs' noise.
// The *_resampled variants (RESAMPLED_DI) leave the primary hit's next-event estimation to the
// resampling passes (ReSTIR DI, docs/design/resampling.md) and write the primary hit's
// barycentrics and ray-cone width, from which those passes re-fetch the surface. The
// *_resampled_gi variants (RESAMPLED_GI too) also leave the primary hit's bounce to them (ReSTIR
// GI): they write the bounce's secondary hit and the radiance gathered there instead of adding it.
// Its variants are the sampling spaces of shaders/sampling/trace_spaces.txt.
//! variants per trace space
//! variants per gradient trace space _gradients: TRACE_GRADIENTS
//! variants per resampling trace space _resampled: RESAMPLED_DI
//! variants per resampling trace space _resampled_gi: RESAMPLED_DI RESAMPLED_GI
//! variants per resampling trace space _resampled_gradients: RESAMPLED_DI TRACE_GRADIENTS
//! variants per resampling trace space _resampled_gi_gradients: RESAMPLED_DI RESAMPLED_GI TRACE_GRADIENTS
//! traversals

#include "../common/scene.glsl"
#include "../common/random.glsl"
#include "../common/brdf.glsl"
#include "../common/lights.glsl"
#include "../common/camera.glsl"
#include "../sampling/space.glsl"
#include "../common/path.glsl"
#if defined(TRACE_GRADIENTS)
#include "../denoise/strata.glsl"
#include "../denoise/svgf.glsl"
#endif

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;

layout(push_constant) uniform Push { TracePush p; } push;

layout(set = 0, binding = 10, rgba32f) uniform writeonly image2D out_color;        // full radiance
layout(set = 0, binding = 11, rgba32f) uniform writeonly image2D out_radiance;     // radiance / albedo, w the primary hit's roughness (cross_eye.comp)
layout(set = 0, binding = 12, rgba16f) uniform writeonly image2D out_albedo;
layout(set = 0, binding = 13, rgba32f) uniform writeonly image2D out_normal_depth; // normal, linear depth (0: miss)
layout(set = 0, binding = 14, rgba32f) uniform writeonly image2D out_position;     // camera-relative position, depth change per grid texel
layout(set = 0, binding = 15, rg32ui) uniform writeonly uimage2D out_ids;          // triangle + 1 (0: miss), material | mesh << 16
layout(set = 0, binding = 16, rg32f) uniform writeonly image2D out_motion;         // previous-frame screen position (−1: none)
// Exact ray counts for the report: [0] primary, [1] shadow, [2] continuation rays,
// [3] traced samples whose screen position is off the screen, [4] samples culled off the screen
// (FRAME_FLAG_CULL_OFFSCREEN: not traced).
layout(std430, set = 0, binding = 17) buffer RayCounters { uint data[]; } ray_counters;
// This frame's live tiles (SamplingSpace::trace_tiles): one workgroup each.
#define TILE_LIST_BINDING 26
#include "../common/tiles.glsl"
#if defined(TRACE_GRADIENTS)
// From 21: binding 18 is the VP sampling table (sampling/visual_polar.glsl).
layout(set = 0, binding = 21, rgba32ui) uniform writeonly uimage2D out_visibility; // barycentrics (float bits), RNG state after the jitter, source luminance (asvgf_source_bits)
layout(std430, set = 0, binding = 22) buffer GradientSamples { AsvgfGradientSample data[]; } gradient_samples;
layout(set = 0, binding = 23, rgba32f) uniform writeonly image2D out_gradient;      // per stratum: δ, max f, 1
#endif
#if defined(RESAMPLED_DI)
layout(set = 0, binding = 27, rgba32f) uniform writeonly image2D out_primary_hit;  // barycentrics u, v, ray-cone width, 0
#endif
#if defined(RESAMPLED_GI)
layout(std430, set = 0, binding = 28) writeonly buffer OutGiSamples { GiSampleGpu data[]; } out_gi_samples;
#endif

// Screen pixels between this sample and the same jitter in a neighbouring texel (the larger of the
// two grid axes; 1 in Cartesian space): the denoisers compare depths per grid texel. Visual-Polar
// texels cover anything from a fraction of a pixel (fovea) to many pixels (periphery).
float texel_footprint(ivec2 texel, vec2 jitter, vec2 screen) {
#if defined(SAMPLING_HAS_FOOTPRINT)
    return sample_footprint(texel, screen);
#else
    float size = 0.0;
    for (int axis = 0; axis < 2; ++axis) {
        ivec2 step = axis == 0 ? ivec2(1, 0) : ivec2(0, 1);
        // The last column/row (or a clipped neighbour) has its neighbour on the other side. Picked
        // before mapping: lavapipe would map both candidates (a VP mapping each) under masks.
        ivec2 neighbour = sample_exists(texel + step) ? texel + step : texel - step;
        vec2 next;
        if (sample_screen_position(neighbour, jitter, next)) size = max(size, length(next - screen));
    }
    return size > 0.0 ? size : 1.0;
#endif
}

// How far off the screen a sample may lie and still be traced (FRAME_FLAG_CULL_OFFSCREEN): the
// remap reads the two columns around a pixel (one footprint) and, along φ, rows within two
// pixels of it (bilinear at the level and the level above, a level's row being about a pixel
// there); TAA's 3×3 box one footprint more. Beyond that a sample never reaches the screen.
const float OFFSCREEN_CULL_FOOTPRINTS = 3.0;
const float OFFSCREEN_CULL_PIXELS = 3.0;

bool far_off_screen(ivec2 texel, vec2 jitter, vec2 screen) {
    vec2 size = frame.data.screen.xy;
    vec2 outside = max(max(-screen, screen - size), vec2(0.0));
    if (all(equal(outside, vec2(0.0)))) return false;
    float margin = OFFSCREEN_CULL_FOOTPRINTS * texel_footprint(texel, jitter, screen) + OFFSCREEN_CULL_PIXELS;
    return max(outside.x, outside.y) > margin;
}

#if defined(TRACE_GRADIENTS) && defined(RESAMPLED_DI)
// The texel of `texel`'s stratum whose plain path estimate this frame keeps for the next frame's
// gradient: one of the nine by a hash of the stratum and the frame (Schied et al.'s random pick;
// the plain kernel picks the brightest, which needs every texel's plain estimate), moved on by
// one where it is the stratum's gradient sample (`gradient_texel`, which re-estimates anyway).
// A pick that holds no sample or hits nothing leaves its stratum without a source this frame.
bool is_gradient_source(ivec2 texel, uint stratum, ivec2 gradient_texel) {
    uint k = pcg_hash(stratum * 9781u + frame.data.frame.x * 6271u + 1u) % 9u;
    ivec2 origin = (texel / STRATUM) * STRATUM;
    ivec2 pick = origin + ivec2(int(k % 3u), int(k / 3u));
    if (pick == gradient_texel) pick = origin + ivec2(int((k + 1u) % 9u % 3u), int((k + 1u) % 9u / 3u));
    return pick == texel;
}

#endif

#if defined(TRACE_GRADIENTS)
// The path from the primary hit `s` as the plain kernel traces it (its own next-event estimation
// and bounce), demodulated luminance: what A-SVGF's gradient compares between two frames.
float plain_path_estimate(Surface s, vec3 dir, uint max_depth, vec2 cone, uint rng, vec3 albedo) {
#if defined(RESAMPLED_DI)
    path_defers_to_resampling = false;
#endif
    vec3 c = shade_path(s, dir, max_depth, cone, rng);
#if defined(RESAMPLED_DI)
    path_defers_to_resampling = true;
#endif
    return svgf_luminance(svgf_sanitize(c / albedo));
}
#endif

// This invocation's texel: the workgroup's tile (from the list of live tiles: lavapipe runs
// masked-off lanes at nearly full cost, so tiles without a sample to trace are not dispatched)
// walked as 4×2 blocks, so that each run of 8
// consecutive invocations (one 256-bit vector on llvmpipe) covers a 4×2 block instead of a row of
// 8 texels. In Visual-Polar space a row runs out along ρ, and 8 columns of the periphery spread
// far across the screen; the block keeps a vector's paths closer (VP trace 2–3 % faster on
// lavapipe, Cartesian ≈ 1 %). A GPU's 32-lane warp still covers an 8×4 block, as before.
ivec2 swizzled_texel() {
    const uint blocks_across = WORKGROUP_2D / 4u;
    uint block = gl_LocalInvocationIndex / 8u, lane = gl_LocalInvocationIndex % 8u;
    uvec2 within = uvec2(lane % 4u + 4u * (block % blocks_across), lane / 4u + 2u * (block / blocks_across));
    return ivec2(tile_list_origin(0u) + within);
}

void main() {
    ivec2 texel = swizzled_texel();
    if (any(greaterThanEqual(texel, ivec2(sampling.data.grid.xy)))) return;
    // The cameras through a column index lavapipe cannot fold (push constant config.y, always 0):
    // it specialises kernels on foldable uniform values, which recompiled this one on every head
    // rotation (fovea xr, ~1 s per frame).
    uint c0 = push.p.config.y;
    mat4 world_from_view = mat4(frame.data.world_from_view[c0], frame.data.world_from_view[c0 + 1u], frame.data.world_from_view[c0 + 2u], frame.data.world_from_view[c0 + 3u]);
    mat4 prev_view_from_world = mat4(frame.data.prev_view_from_world[c0], frame.data.prev_view_from_world[c0 + 1u], frame.data.prev_view_from_world[c0 + 2u], frame.data.prev_view_from_world[c0 + 3u]);
    uint rng = rng_seed(uvec2(texel), frame.data.frame.x, frame.data.frame.y, push.p.config.x);
    vec2 screen;
    vec2 jitter = rng_next2(rng);
    if ((frame.data.frame.w & FRAME_FLAG_HALTON_JITTER) != 0u) jitter = frame.data.jitter.xy;
    bool traced = sample_screen_position(texel, jitter, screen);
#if defined(SAMPLING_SAMPLES_PER_TEXEL)
    traced = traced && push.p.config.x < sample_count_in_texel(texel);
#endif
    bool culled = traced && (frame.data.frame.w & FRAME_FLAG_CULL_OFFSCREEN) != 0u && far_off_screen(texel, jitter, screen);
    if (culled) {
        atomicAdd(ray_counters.data[4], 1u);
        traced = false;
    }
    if (!traced) {
        imageStore(out_color, texel, vec4(0.0));
        imageStore(out_radiance, texel, vec4(0.0));
        imageStore(out_albedo, texel, vec4(0.0));
        imageStore(out_normal_depth, texel, vec4(0.0));
        imageStore(out_position, texel, vec4(0.0));
        imageStore(out_ids, texel, uvec4(0u));
        imageStore(out_motion, texel, vec4(-1.0));
#if defined(TRACE_GRADIENTS)
        imageStore(out_visibility, texel, uvec4(0u));
#endif
#if defined(RESAMPLED_DI)
        imageStore(out_primary_hit, texel, vec4(0.0));
#endif
#if defined(RESAMPLED_GI)
        out_gi_samples.data[uint(texel.y) * sampling.data.grid.x + uint(texel.x)] = GiSampleGpu(vec4(0.0), vec4(0.0), vec4(0.0));
#endif
        return;
    }
    if (any(lessThan(screen, vec2(0.0))) || any(greaterThanEqual(screen, frame.data.screen.xy))) atomicAdd(ray_counters.data[3], 1u);
    vec3 org = world_from_view[3].xyz;
    vec3 view_dir = view_direction(screen, frame.data.fov_tan, frame.data.screen.xy);
    vec3 dir = normalize(mat3(world_from_view) * view_dir);
    uint max_depth = frame.data.frame.z;
#if defined(TRACE_GRADIENTS)
    // A gradient sample: besides its own sample along its jitter, this texel looks at the
    // surface the forward projection put here (it lies inside the texel) and, if it is still
    // visible, traces last frame's path there again with last frame's random state
    // (`plain_path_estimate`). That path only measures the gradient: shown in the image, last
    // frame's brightest sample of the stratum, again and at its bright point, would bias it up.
    uint stratum = asvgf_stratum_index(texel, int(sampling.data.grid.x));
    AsvgfGradientSample gs = gradient_samples.data[stratum];
    bool gradient = gs.surface.x != 0u && gs.shading.x == (uint(texel.x) | (uint(texel.y) << 16u));
    vec2 gradient_bary = uintBitsToFloat(gs.surface.zw);
    vec3 gradient_dir = dir;
    if (gradient) {
        PlacedTriangle placed = placed_triangle(gs.surface.y - 1u); // placed id: world space also for instances
        vec3 p = (1.0 - gradient_bary.x - gradient_bary.y) * placed.a.position_u.xyz
               + gradient_bary.x * placed.b.position_u.xyz
               + gradient_bary.y * placed.c.position_u.xyz;
        gradient_dir = normalize(p - org);
    }
#endif

    Hit hit;
    vec3 color = vec3(0.0);
    vec3 albedo = vec3(1.0);
    float roughness = 0.0;
    vec4 normal_depth = vec4(0.0);
    vec4 position = vec4(0.0);
    uvec2 ids = uvec2(0u);
    vec2 prev_screen = vec2(-1.0);
    vec4 primary_hit = vec4(0.0);   // RESAMPLED_DI: barycentrics, ray-cone width
    bool found = bvh_trace(org, dir, 0.0, 1e30, false, hit);
    float pixel_tan = (frame.data.fov_tan.y - frame.data.fov_tan.x) * frame.data.screen.z;
    float footprint = found ? texel_footprint(texel, jitter, screen) : 1.0;
    // The angle this sample stands for on the screen (its footprint in pixels, wider in the
    // Visual-Polar periphery; a pixel's angle shrinks off-axis by cos θ = 1/|view_dir|).
    float spread = pixel_tan * footprint / length(view_dir);
    // Surface noise: everything after the jitter is drawn from the hit's cell (dir is unit
    // length: t is the distance, spread × t the footprint's width there; path.y footprints
    // make a cell).
    if (found && (frame.data.frame.w & FRAME_FLAG_SURFACE_NOISE) != 0u)
        rng = surface_rng_seed(org + dir * hit.t, spread * hit.t * frame.data.path.y, frame.data.frame.x, frame.data.frame.y, push.p.config.x);
#if defined(TRACE_GRADIENTS)
    uint path_rng = rng;
    // The luminance the next frame's gradient compares against, if this texel is its stratum's
    // source (asvgf_forward.comp): -1 where it is not.
    float source_luminance = -1.0;
    float plain_current = 0.0;
#if defined(RESAMPLED_DI)
    ivec2 gradient_texel = gs.surface.x != 0u ? ivec2(int(gs.shading.x & 0xffffu), int(gs.shading.x >> 16u)) : ivec2(-1);
    bool source = found && is_gradient_source(texel, stratum, gradient_texel);
#endif
#endif
    if (!found) {
        // Nothing hit: the environment (black without one); the previous position is the same direction.
        if (max_depth >= 1u) color = sky_radiance(dir);
        vec3 prev_view = mat3(prev_view_from_world) * dir;
        project_view(prev_view, frame.data.prev_fov_tan, frame.data.screen.xy, prev_screen);
    } else {
        // The ray cone (texture LOD): from a pinhole, width = spread × distance.
        vec2 cone = vec2(0.0);
        if ((frame.data.frame.w & FRAME_FLAG_TEXTURE_LOD) != 0u) cone = vec2(spread * hit.t, spread);
        Surface s = fetch_surface(hit, dir, cone.x);
        vec3 p_rel = s.position - org;
        float depth = dot(p_rel, mat3(world_from_view) * vec3(0.0, 0.0, -1.0));
        float cos_view = max(abs(dot(s.geometric_normal, dir)), 0.05);
        float depth_gradient = depth * pixel_tan * footprint
                             * sqrt(max(1.0 - cos_view * cos_view, 0.0)) / cos_view;
        albedo = max(s.base_color, vec3(0.01));
        roughness = s.roughness;
        normal_depth = vec4(s.normal, depth);
        position = vec4(p_rel, depth_gradient);
        ids = uvec2(hit.triangle + 1u, s.material | (s.mesh << 16u));
        project_view((prev_view_from_world * vec4(s.position, 1.0)).xyz, frame.data.prev_fov_tan, frame.data.screen.xy, prev_screen);
        color = shade_path(s, dir, max_depth, cone, rng);
        primary_hit = vec4(hit.u, hit.v, cone.x, 0.0);
#if defined(TRACE_GRADIENTS) && defined(RESAMPLED_DI)
        if (source) source_luminance = plain_path_estimate(s, dir, max_depth, cone, path_rng, albedo);
#endif
    }
#if defined(TRACE_GRADIENTS)
    if (gradient) {
        Hit gh;
        gradient = bvh_trace(org, gradient_dir, 0.0, 1e30, false, gh) && gh.triangle == gs.surface.y - 1u;
        if (gradient) {
            atomicAdd(ray_counters.data[0], 1u);
            gh.u = gradient_bary.x;
            gh.v = gradient_bary.y;
            vec2 g_cone = vec2(0.0);
            if ((frame.data.frame.w & FRAME_FLAG_TEXTURE_LOD) != 0u) {
                // The texel's own spread (its footprint is computed only when its own ray hit).
                float g_spread = found ? spread : pixel_tan * texel_footprint(texel, jitter, screen) / length(view_dir);
                g_cone = vec2(g_spread * gh.t, g_spread);
            }
            Surface g_s = fetch_surface(gh, gradient_dir, g_cone.x);
            plain_current = plain_path_estimate(g_s, gradient_dir, max_depth, g_cone, gs.shading.y, max(g_s.base_color, vec3(0.01)));
        }
    }
#endif
#if defined(RESAMPLED_DI)
    imageStore(out_primary_hit, texel, primary_hit);
#endif
#if defined(RESAMPLED_GI)
    out_gi_samples.data[uint(texel.y) * sampling.data.grid.x + uint(texel.x)] = GiSampleGpu(gi_point, vec4(gi_normal, 0.0), vec4(gi_radiance, 0.0));
#endif
    atomicAdd(ray_counters.data[0], 1u);
    if (shadow_rays > 0u) atomicAdd(ray_counters.data[1], shadow_rays);
    if (continuation_rays > 0u) atomicAdd(ray_counters.data[2], continuation_rays);
    // Never let a NaN/Inf from a degenerate triangle poison the accumulators downstream.
    if (any(isnan(color)) || any(isinf(color))) color = vec3(0.0);
    imageStore(out_color, texel, vec4(color, 1.0));
    imageStore(out_radiance, texel, vec4(color / albedo, roughness));
    imageStore(out_albedo, texel, vec4(albedo, 1.0));
    imageStore(out_normal_depth, texel, normal_depth);
    imageStore(out_position, texel, position);
    imageStore(out_ids, texel, uvec4(ids, 0u, 0u));
    imageStore(out_motion, texel, vec4(prev_screen, 0.0, 0.0));
#if defined(TRACE_GRADIENTS)
    float current = plain_current;
#if !defined(RESAMPLED_DI)
    // Every sample is a plain estimate: each may be its stratum's source.
    if (found) source_luminance = svgf_luminance(svgf_sanitize(color / albedo));
#endif
    imageStore(out_visibility, texel, uvec4(floatBitsToUint(vec2(hit.u, hit.v)), path_rng, asvgf_source_bits(source_luminance)));
    if (gradient) {
        float previous = uintBitsToFloat(gs.shading.z);
        gradient_samples.data[stratum].shading.w = floatBitsToUint(current);
        imageStore(out_gradient, texel / int(ASVGF_STRATUM), vec4(current - previous, max(current, previous), 1.0, 0.0));
    }
#endif
}
