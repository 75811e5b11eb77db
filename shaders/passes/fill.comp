#version 460
// Push-pull hole filling (Gortler et al. 1996) of a sparse screen image whose alpha marks the
// pixels that hold a sample (linear falloff's kept pixels, random-acuity samples splatted to their
// pixel). Pull (config.x = 0): level l → l+1, the alpha-weighted mean of the 2×2 children with
// alpha min(1, Σ alpha). Push (config.x = 1): level l's own value over the filled coarser level,
// bilinearly, in proportion to its alpha; every pixel of the result holds a colour.
#include "../common/layouts.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { FillPush p; } push;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D fine;    // pull: source; push: this level as pulled
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D coarse;  // push: the filled level below (pull: unused, = fine)
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D dst;

vec4 pull(ivec2 t) {
    ivec2 size = imageSize(fine);
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    for (int i = 0; i < 4; ++i) {
        ivec2 c = 2 * t + ivec2(i & 1, i >> 1);
        if (any(greaterThanEqual(c, size))) continue;
        vec4 v = imageLoad(fine, c);
        sum += v.rgb * v.a;
        weight += v.a;
    }
    return weight > 0.0 ? vec4(sum / weight, min(weight, 1.0)) : vec4(0.0);
}

vec4 coarse_bilinear(ivec2 t) {
    ivec2 size = imageSize(coarse);
    vec2 p = (vec2(t) + 0.5) * 0.5 - 0.5;
    ivec2 i0 = ivec2(floor(p));
    vec2 f = p - vec2(i0);
    vec4 a = imageLoad(coarse, clamp(i0, ivec2(0), size - 1));
    vec4 b = imageLoad(coarse, clamp(i0 + ivec2(1, 0), ivec2(0), size - 1));
    vec4 c = imageLoad(coarse, clamp(i0 + ivec2(0, 1), ivec2(0), size - 1));
    vec4 d = imageLoad(coarse, clamp(i0 + ivec2(1, 1), ivec2(0), size - 1));
    return mix(mix(a, b, f.x), mix(c, d, f.x), f.y);
}

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(t, imageSize(dst)))) return;
    if (push.p.config.x == 0u) {
        imageStore(dst, t, pull(t));
        return;
    }
    vec4 own = imageLoad(fine, t);
    vec3 below = coarse_bilinear(t).rgb;
    imageStore(dst, t, vec4(mix(below, own.rgb, clamp(own.a, 0.0, 1.0)), 1.0));
}
