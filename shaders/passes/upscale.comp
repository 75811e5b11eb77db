#version 460
// A sampling grid coarser than the screen (`uniform-budget`: VP's sample count on a regular
// grid) brought to the screen by bilinear interpolation of the texel centres, borders clamped.
#include "../common/layouts.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D grid;
layout(set = 0, binding = 1, rgba32f) uniform writeonly image2D screen;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(screen);
    if (any(greaterThanEqual(p, size))) return;
    ivec2 g = imageSize(grid);
    // Screen pixel centre in grid texel units, relative to the texel centres.
    vec2 at = (vec2(p) + 0.5) * vec2(g) / vec2(size) - 0.5;
    vec2 f = fract(at);
    ivec2 t0 = clamp(ivec2(floor(at)), ivec2(0), g - 1);
    ivec2 t1 = clamp(ivec2(floor(at)) + 1, ivec2(0), g - 1);
    vec4 top = mix(imageLoad(grid, t0), imageLoad(grid, ivec2(t1.x, t0.y)), f.x);
    vec4 bottom = mix(imageLoad(grid, ivec2(t0.x, t1.y)), imageLoad(grid, t1), f.x);
    imageStore(screen, p, mix(top, bottom, f.y));
}
