#version 460
// Splat (the way back of spaces whose samples lie anywhere on the screen: random acuity, the
// packed variable-rate tiles): each grid texel's sample added to the screen pixel its position
// falls in, then every pixel's mean.
// Scatter (config.x = 0, one lane per grid texel): the sample's position recomputed by the space
// (the same draw as the trace), its radiance added in fixed point (SPLAT_FIXED_POINT) with integer
// atomics — float atomics are an extension — and a count. Resolve (config.x = 1, one lane per
// pixel): the mean, alpha 1 where a sample landed, 0 elsewhere (the push-pull fill's input).
// One variant per trace variant: the splat recomputes each sample's position with the very
// mapping the trace used (renderer::passes::splat takes the space's trace_variant).
//! variants per trace space
#include "../common/layouts.glsl"
#include "../sampling/space.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { SplatPush p; } push;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D grid_color;
// Per pixel (row-major): r, g, b sums in fixed point and the sample count. Cleared every frame.
layout(std430, set = 0, binding = 1) buffer Sums { uvec4 data[]; } sums;
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D sparse;

void scatter(ivec2 texel) {
    if (any(greaterThanEqual(texel, imageSize(grid_color)))) return;
    vec2 screen;
    if (!sample_screen_position(texel, vec2(0.0), screen)) return;
    ivec2 size = imageSize(sparse);
    ivec2 pixel = ivec2(floor(screen));
    // The paper's layout traces positions off the screen, as Visual-Polar does: they are lost.
    if (any(lessThan(pixel, ivec2(0))) || any(greaterThanEqual(pixel, size))) return;
    vec3 c = imageLoad(grid_color, texel).rgb;
    if (any(isnan(c)) || any(isinf(c))) return;
    uvec3 fixed_point = uvec3(round(clamp(c, 0.0, SPLAT_MAX_RADIANCE) * SPLAT_FIXED_POINT));
    uint i = uint(pixel.y * size.x + pixel.x);
    atomicAdd(sums.data[i].x, fixed_point.x);
    atomicAdd(sums.data[i].y, fixed_point.y);
    atomicAdd(sums.data[i].z, fixed_point.z);
    atomicAdd(sums.data[i].w, 1u);
}

void resolve(ivec2 pixel) {
    ivec2 size = imageSize(sparse);
    if (any(greaterThanEqual(pixel, size))) return;
    uvec4 s = sums.data[pixel.y * size.x + pixel.x];
    vec4 mean = s.w == 0u ? vec4(0.0) : vec4(vec3(s.xyz) / (SPLAT_FIXED_POINT * float(s.w)), 1.0);
    imageStore(sparse, pixel, mean);
}

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (push.p.config.x == 0u) scatter(t);
    else resolve(t);
}
