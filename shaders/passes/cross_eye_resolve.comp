#version 460
// Cross-eye reuse, second pass: where the first pass merged the two eyes' samples, the merged
// demodulated radiance becomes this eye's radiance and, times this sample's own albedo (texture
// detail stays each eye's own), its colour — what the denoisers read.
#include "../common/layouts.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;

layout(set = 0, binding = 10, rgba32f) uniform readonly image2D merged;
layout(set = 0, binding = 11, rgba16f) uniform readonly image2D albedo;
layout(set = 0, binding = 12, rgba32f) uniform writeonly image2D color;
layout(set = 0, binding = 13, rgba32f) uniform writeonly image2D radiance;

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(t, imageSize(merged)))) return;
    vec4 m = imageLoad(merged, t);
    if (m.w < 0.0) return;
    imageStore(color, t, vec4(m.rgb * imageLoad(albedo, t).rgb, 1.0));
    imageStore(radiance, t, vec4(m.rgb, m.w));
}
