// Exposure, tone curve and sRGB encoding: linear radiance → the display-ready colour an 8-bit
// target stores. Shared by the tonemap pass and the foveated blur's last axis, which writes the
// display image itself when nothing reads the blurred radiance (fewer full-screen passes).
#ifndef FOVEA_COMMON_TONE_GLSL
#define FOVEA_COMMON_TONE_GLSL

#include "layouts.glsl"

// Narkowicz's fit of the ACES filmic curve: keeps highlights from clipping hard.
vec3 aces_fitted(vec3 x) {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

vec3 linear_to_srgb(vec3 c) {
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, greaterThan(c, vec3(0.0031308)));
}

// `p`: the tonemap push constants (x exposure; config.x the operator).
vec4 tone_map(vec3 radiance, TonemapPush p) {
    vec3 c = max(radiance * p.params.x, vec3(0.0));
    c = p.config.x == TONEMAP_ACES ? aces_fitted(c) : clamp(c, 0.0, 1.0);
    return vec4(linear_to_srgb(c), 1.0);
}

#endif
