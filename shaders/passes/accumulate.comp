#version 460
// Running mean of the traced colour over many samples (reference renders): accum holds the mean
// of `count` samples; the new one is blended in with weight 1/(count+1), in f32. With config.y = 1
// a texel whose sample was not traced (alpha 0) keeps its mean (spaces that trace some texels
// more often than others: every traced texel then has `count` samples so far).
#include "../common/layouts.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { AccumulatePush p; } push;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D sample_color;
layout(set = 0, binding = 1, rgba32f) uniform image2D accum;

void main() {
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(texel, imageSize(accum)))) return;
    float count = float(push.p.config.x);
    vec4 mean = count > 0.0 ? imageLoad(accum, texel) : vec4(0.0);
    vec4 s = imageLoad(sample_color, texel);
    if (push.p.config.y != 0u && count > 0.0 && s.a == 0.0) return;
    imageStore(accum, texel, mean + (s - mean) / (count + 1.0));
}
