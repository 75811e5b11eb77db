#version 460
// The trace's idle tiles (SamplingSpace::trace_tiles: no texel holds a sample, or every sample
// lies too far off the screen to be traced) get what trace.comp writes for a sample it does not
// trace, without its cost: lavapipe runs the tracer's masked-off lanes at nearly full cost. The
// filters read these texels as misses. Adds the idle tiles' culled samples to ray counter 4.
//! variant plain:
//! variant gradients: TRACE_GRADIENTS
#include "../common/layouts.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { TraceClearPush p; } push;

layout(set = 0, binding = 10, rgba32f) uniform writeonly image2D out_color;
layout(set = 0, binding = 11, rgba32f) uniform writeonly image2D out_radiance;
layout(set = 0, binding = 12, rgba16f) uniform writeonly image2D out_albedo;
layout(set = 0, binding = 13, rgba32f) uniform writeonly image2D out_normal_depth;
layout(set = 0, binding = 14, rgba32f) uniform writeonly image2D out_position;
layout(set = 0, binding = 15, rg32ui) uniform writeonly uimage2D out_ids;
layout(set = 0, binding = 16, rg32f) uniform writeonly image2D out_motion;
layout(std430, set = 0, binding = 17) buffer RayCounters { uint data[]; } ray_counters;
#if defined(TRACE_GRADIENTS)
layout(set = 0, binding = 21, rgba32ui) uniform writeonly uimage2D out_visibility;
#endif
#define TILE_LIST_BINDING 26
#include "../common/tiles.glsl"

void main() {
    if (gl_WorkGroupID.x == 0u && gl_LocalInvocationIndex == 0u) atomicAdd(ray_counters.data[4], push.p.config.y);
    ivec2 texel = tile_list_texel(push.p.config.x);
    if (any(greaterThanEqual(texel, imageSize(out_color)))) return;
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
}
