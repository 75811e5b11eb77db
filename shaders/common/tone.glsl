// Exposure, tone curve and sRGB encoding: linear radiance → the display-ready colour an 8-bit
// target stores. Shared by the tonemap pass and the foveated blur's last axis, which writes the
// display image itself when nothing reads the blurred radiance (fewer full-screen passes).
#ifndef FOVEA_COMMON_TONE_GLSL
#define FOVEA_COMMON_TONE_GLSL

#include "layouts.glsl"

// Narkowicz's fit of the ACES filmic curve: keeps highlights from clipping hard; shifts hues
// and darkens mid-tones.
vec3 aces_fitted(vec3 x) {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

// Khronos PBR Neutral: the identity (after a small toe) up to 0.76, so base colours under
// neutral light display as authored; above it, highlights compress toward white along the
// hue and desaturate gradually.
vec3 pbr_neutral(vec3 c) {
    const float start_compression = 0.8 - 0.04;
    const float desaturation = 0.15;
    float x = min(c.r, min(c.g, c.b));
    float offset = x < 0.08 ? x - 6.25 * x * x : 0.04;
    c -= offset;
    float peak = max(c.r, max(c.g, c.b));
    if (peak < start_compression) return c;
    const float d = 1.0 - start_compression;
    float new_peak = 1.0 - d * d / (peak + d - start_compression);
    c *= new_peak / peak;
    float g = 1.0 - 1.0 / (desaturation * (peak - new_peak) + 1.0);
    return mix(c, vec3(new_peak), g);
}

vec3 linear_to_srgb(vec3 c) {
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, greaterThan(c, vec3(0.0031308)));
}

// `exposure`: the frame's multiplier (ExposureState.values.x); `p`: the operator.
vec4 tone_map(vec3 radiance, float exposure, TonemapPush p) {
    vec3 c = max(radiance * exposure, vec3(0.0));
    if (p.config.x == TONEMAP_ACES) {
        c = aces_fitted(c);
    } else if (p.config.x == TONEMAP_NEUTRAL) {
        c = pbr_neutral(c);
    }
    return vec4(linear_to_srgb(clamp(c, 0.0, 1.0)), 1.0);
}

#endif
