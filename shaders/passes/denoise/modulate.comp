#version 460
// Re-modulation: filtered demodulated radiance × albedo → radiance for the way to the screen.
// Texels without a sample have albedo 0 (the tracer's convention), so they stay 0 with alpha 0,
// like the tracer's colour image.
#include "../../common/layouts.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D filtered;
layout(set = 0, binding = 1, rgba16f) uniform readonly image2D albedo;
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D dst;

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(t, imageSize(dst)))) return;
    vec4 a = imageLoad(albedo, t);
    imageStore(dst, t, vec4(imageLoad(filtered, t).rgb * a.rgb, a.a));
}
