#version 460
// Exposure, tone curve and sRGB encoding: linear radiance → display-ready 8-bit colour.
//! variant own:
//! variant external: EXTERNAL_TARGET
// `external` writes an image the engine does not own (a swapchain's UNORM image, RGBA or BGRA):
// no format qualifier, so the view's format decides the channel order, and the view's pixels go
// at an offset (stereo side by side in one window).
#include "../common/layouts.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { TonemapPush p; } push;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D hdr;
#ifdef EXTERNAL_TARGET
layout(set = 0, binding = 1) uniform writeonly image2D ldr;
#else
layout(set = 0, binding = 1, rgba8) uniform writeonly image2D ldr;
#endif

// Narkowicz's fit of the ACES filmic curve: keeps highlights from clipping hard.
vec3 aces_fitted(vec3 x) {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

vec3 linear_to_srgb(vec3 c) {
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, greaterThan(c, vec3(0.0031308)));
}

void main() {
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(texel, imageSize(hdr)))) return;
    ivec2 target = texel + ivec2(push.p.config.yz);
    if (any(greaterThanEqual(target, imageSize(ldr)))) return;
    vec3 c = max(imageLoad(hdr, texel).rgb * push.p.params.x, vec3(0.0));
    c = push.p.config.x == TONEMAP_ACES ? aces_fitted(c) : clamp(c, 0.0, 1.0);
    imageStore(ldr, target, vec4(linear_to_srgb(c), 1.0));
}
