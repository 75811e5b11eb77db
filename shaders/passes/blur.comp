#version 460
// Foveated blur (visual-polar.md §7), one separable axis per dispatch: a Gaussian whose σ is 0
// inside the fovea and grows linearly with the distance from the gaze beyond it, so periphery
// aliasing from the coarse VP grid is removed without blurring what the eye resolves.
// The `ldr` variants are the last axis writing the display image (tone curve and sRGB encoding of
// common/tone.glsl, at the target offset) instead of radiance, saving the tonemap's full-screen
// pass when nothing reads the blurred radiance; `ldr_external` writes an image the engine does
// not own, as the tonemap's `external` variant does.
//! variant hdr:
//! variant ldr: BLUR_TONEMAP
//! variant ldr_external: BLUR_TONEMAP EXTERNAL_TARGET
#include "../common/tone.glsl"
#include "../common/gaussian.glsl"

// 64 pixels of one row per workgroup: with 8×8 tiles the vertical pass's taps (up to ±26 rows)
// from 8 rows at once fell into the same CPU cache sets (row pitch 20 KiB at 1280 px) and it ran
// 1.4× slower than the horizontal one on lavapipe (52 → 39 ms at 1280×1440); rows are the natural
// unit of a separable pass on a GPU too.
layout(local_size_x = 64, local_size_y = 1) in;
layout(push_constant) uniform Push { BlurPush p; } push;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D src;
#if defined(EXTERNAL_TARGET)
layout(set = 0, binding = 1) uniform writeonly image2D dst;
#elif defined(BLUR_TONEMAP)
layout(set = 0, binding = 1, rgba8) uniform writeonly image2D dst;
#else
layout(set = 0, binding = 1, rgba32f) uniform writeonly image2D dst;
#endif
#if defined(BLUR_TONEMAP)
layout(std430, set = 0, binding = 2) readonly buffer Exposure { ExposureState s; } exposure;
#endif

void store(ivec2 t, vec4 radiance) {
#if defined(BLUR_TONEMAP)
    ivec2 target = t + ivec2(push.p.tone.config.yz);
    if (all(lessThan(target, imageSize(dst)))) imageStore(dst, target, tone_map(radiance.rgb, exposure.s.values.x, push.p.tone));
#else
    imageStore(dst, t, radiance);
#endif
}

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(src);
    if (any(greaterThanEqual(t, size))) return;
    vec4 shape = push.p.shape;
    float sigma = shape.w * max(length(vec2(t) + 0.5 - shape.xy) - shape.z, 0.0);
    // Wide kernels only occur in the periphery, where the image is a magnified, already smooth
    // VP image: taps about σ/2 apart out to 2.5σ (5 or 6 per side from σ ≈ 9 px, at most 8)
    // keep the cost flat; the sampled Gaussian's first alias sits at 2/σ cycles per pixel, where
    // the continuous one has fallen to e^(−8π²), and the tails beyond 2.5σ hold 1.2 % of its
    // weight. Float arithmetic: an integer division runs lane by lane on lavapipe.
    float spacing_px = max(1.0, floor(sigma * 0.5 + 0.5));
    int spacing = int(spacing_px);
    int taps = int(min(ceil(2.5 * sigma / spacing_px), floor(float(push.p.config.y) / spacing_px)));
    vec4 centre = imageLoad(src, t);
    if (taps < 1) {
        store(t, centre);
        return;
    }
    ivec2 step_px = spacing * (push.p.config.x == 0u ? ivec2(1, 0) : ivec2(0, 1));
    GaussianTaps gauss = gaussian_taps(sigma / spacing_px);
    vec4 sum = centre;
    float weight = 1.0;
    for (int i = 1; i <= taps; ++i) {
        float w = gaussian_next(gauss);
        vec4 a = imageLoad(src, clamp(t + i * step_px, ivec2(0), size - 1));
        vec4 b = imageLoad(src, clamp(t - i * step_px, ivec2(0), size - 1));
        sum += w * (a + b);
        weight += 2.0 * w;
    }
    store(t, sum / weight);
}
