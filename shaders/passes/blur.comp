#version 460
// Foveated blur (visual-polar.md §7), one separable axis per dispatch: a Gaussian whose σ is 0
// inside the fovea and grows linearly with the distance from the gaze beyond it, so periphery
// aliasing from the coarse VP grid is removed without blurring what the eye resolves.
#include "../common/layouts.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { BlurPush p; } push;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D src;
layout(set = 0, binding = 1, rgba32f) uniform writeonly image2D dst;

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(dst);
    if (any(greaterThanEqual(t, size))) return;
    vec4 shape = push.p.shape;
    float sigma = shape.w * max(length(vec2(t) + 0.5 - shape.xy) - shape.z, 0.0);
    int radius = min(int(ceil(3.0 * sigma)), int(push.p.config.y));
    vec4 centre = imageLoad(src, t);
    if (radius < 1) {
        imageStore(dst, t, centre);
        return;
    }
    ivec2 axis = push.p.config.x == 0u ? ivec2(1, 0) : ivec2(0, 1);
    // w(i) = exp(−i²/2σ²) by recurrence: w(i+1) = w(i)·q·c^i, q = exp(−1/2σ²), c = q².
    float q = exp(-0.5 / (sigma * sigma));
    float c = q * q;
    float w = 1.0;
    float step = q;
    vec4 sum = centre;
    float weight = 1.0;
    for (int i = 1; i <= radius; ++i) {
        w *= step;
        step *= c;
        vec4 a = imageLoad(src, clamp(t + i * axis, ivec2(0), size - 1));
        vec4 b = imageLoad(src, clamp(t - i * axis, ivec2(0), size - 1));
        sum += w * (a + b);
        weight += 2.0 * w;
    }
    imageStore(dst, t, sum / weight);
}
