#version 460
// Exposure (the frame's ExposureState), tone curve and sRGB encoding: linear radiance → display-ready 8-bit colour.
//! variant own:
//! variant external: EXTERNAL_TARGET
// `external` writes an image the engine does not own (a swapchain's UNORM image, RGBA or BGRA):
// no format qualifier, so the view's format decides the channel order, and the view's pixels go
// at an offset (stereo side by side in one window).
#include "../common/tone.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { TonemapPush p; } push;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D hdr;
#ifdef EXTERNAL_TARGET
layout(set = 0, binding = 1) uniform writeonly image2D ldr;
#else
layout(set = 0, binding = 1, rgba8) uniform writeonly image2D ldr;
#endif
layout(std430, set = 0, binding = 2) readonly buffer Exposure { ExposureState s; } exposure;

void main() {
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(texel, imageSize(hdr)))) return;
    ivec2 target = texel + ivec2(push.p.config.yz);
    if (any(greaterThanEqual(target, imageSize(ldr)))) return;
    imageStore(ldr, target, tone_map(imageLoad(hdr, texel).rgb, exposure.s.values.x, push.p));
}
