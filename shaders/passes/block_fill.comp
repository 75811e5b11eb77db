#version 460
// Pixel blocks back to the screen (Mohanto et al. 2023): each pixel takes its level from its
// distance to the gaze (sampling/pixel_blocks.glsl); a fovea pixel is its own unit, a pixel of
// the 2×2 or 4×4 levels the bilinear interpolation between the centres of the four nearest
// blocks of that level (alpha-weighted: only traced units count — the regions' dilation makes
// all four traced).
//! variant pixel_blocks: SAMPLING_PIXEL_BLOCKS
#include "../common/layouts.glsl"
#include "../sampling/space.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D grid;  // the atlas, mean of each unit's samples
layout(set = 0, binding = 1, rgba32f) uniform writeonly image2D screen;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(screen)))) return;
    int level = pb_level_of(vec2(p) + 0.5);
    if (level == 0) {
        imageStore(screen, p, vec4(imageLoad(grid, pb_atlas_texel(0, p)).rgb, 1.0));
        return;
    }
    float b = float(1 << level);
    vec2 q = (vec2(p) + 0.5) / b - 0.5;
    ivec2 i0 = ivec2(floor(q));
    vec2 f = q - vec2(i0);
    ivec2 size = pb_level_size(level);
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    for (int i = 0; i < 4; ++i) {
        ivec2 o = ivec2(i & 1, i >> 1);
        vec4 v = imageLoad(grid, pb_atlas_texel(level, clamp(i0 + o, ivec2(0), size - 1)));
        float w = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y) * v.a;
        sum += w * v.rgb;
        weight += w;
    }
    imageStore(screen, p, vec4(weight > 0.0 ? sum / weight : vec3(0.0), 1.0));
}
