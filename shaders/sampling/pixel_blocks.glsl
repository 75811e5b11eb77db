// Piecewise pixel blocks (Mohanto, Klunge and Staadt 2023, comparators.md §F): around the gaze a
// fovea of single pixels (r ≤ r_f), an intermediate ring of 2×2 blocks (to r_m) and a periphery of
// 4×4 blocks, each unit tracing its level's sample count (τ per pixel / per block) and filled back
// by bilinear interpolation between the block centres of a pixel's level (passes/block_fill).
// The grid is an atlas of windows: level 2's blocks over the whole screen at the origin, beside it
// a square window of level-0 pixels and one of level-1 blocks, both centred on the gaze and just
// large enough for their regions (so few lanes idle). A unit outside its level's region (dilated
// by B·√2 for levels 1 and 2, so every pixel's four interpolation neighbours are traced) holds no
// sample. Parameters: grid = (atlas w, h, screen w, h), gaze = (x, y, r_f, r_m) px, shape0 =
// (τ0, τ1, τ2, 0), shape1 = (level-0 window, level-1 window, 0, 0) in units. Rust:
// sampling::PixelBlocks.
#ifndef FOVEA_SAMPLING_PIXEL_BLOCKS_GLSL
#define FOVEA_SAMPLING_PIXEL_BLOCKS_GLSL

const float PB_SQRT2 = 1.41421356;

ivec2 pb_screen() {
    return ivec2(sampling.data.grid.zw);
}

// Blocks of `level` (edge 2^level px) covering the screen.
ivec2 pb_level_size(int level) {
    int b = 1 << level;
    return (pb_screen() + b - 1) / b;
}

// Each level's window of the atlas, in units (shape1 = (level-0 window, level-1 window) edges;
// level 2's window is the whole screen).
ivec2 pb_window_size(int level) {
    return level == 2 ? pb_level_size(2) : ivec2(int(sampling.data.shape1[level]));
}

// Where a level's window starts in the atlas: level 2 at the origin, 0 and 1 stacked beside it.
ivec2 pb_atlas_origin(int level) {
    int x = pb_level_size(2).x;
    return level == 2 ? ivec2(0) : level == 0 ? ivec2(x, 0) : ivec2(x, pb_window_size(0).y);
}

// The first block of a level's window: the gaze's block less half the window (levels 0 and 1
// follow the gaze; their windows hold every unit their dilated regions can trace).
ivec2 pb_window_first_block(int level) {
    if (level == 2) return ivec2(0);
    ivec2 gaze_block = ivec2(floor(sampling.data.gaze.xy / float(1 << level)));
    return gaze_block - pb_window_size(level) / 2;
}

// The level and block of an atlas texel; false outside the windows or the screen.
bool pb_unit(ivec2 texel, out int level, out ivec2 block) {
    level = texel.x < pb_atlas_origin(0).x ? 2 : texel.y < pb_atlas_origin(1).y ? 0 : 1;
    ivec2 local = texel - pb_atlas_origin(level);
    block = local + pb_window_first_block(level);
    return all(lessThan(local, pb_window_size(level))) && all(greaterThanEqual(block, ivec2(0))) && all(lessThan(block, pb_level_size(level)));
}

// The atlas texel of a level's block (inside its window).
ivec2 pb_atlas_texel(int level, ivec2 block) {
    return pb_atlas_origin(level) + block - pb_window_first_block(level);
}

// The level whose region holds a screen position (pixels).
int pb_level_of(vec2 p) {
    float d = length(p - sampling.data.gaze.xy);
    return d <= sampling.data.gaze.z ? 0 : d <= sampling.data.gaze.w ? 1 : 2;
}

bool pb_traced(int level, ivec2 block) {
    float b = float(1 << level);
    float d = length((vec2(block) + 0.5) * b - sampling.data.gaze.xy);
    float reach = b * PB_SQRT2;
    if (level == 0) return d <= sampling.data.gaze.z;
    if (level == 1) return d >= sampling.data.gaze.z - reach && d <= sampling.data.gaze.w + reach;
    return d >= sampling.data.gaze.w - reach;
}

// Samples the texel's unit traces this frame (0: none).
#define SAMPLING_SAMPLES_PER_TEXEL
uint sample_count_in_texel(ivec2 texel) {
    int level;
    ivec2 block;
    if (!pb_unit(texel, level, block) || !pb_traced(level, block)) return 0u;
    return uint(sampling.data.shape0[level]);
}

bool sample_exists(ivec2 texel) {
    return sample_count_in_texel(texel) > 0u;
}

// Jittered over the block's part on the screen.
bool sample_screen_position(ivec2 texel, vec2 jitter, out vec2 screen) {
    int level;
    ivec2 block;
    screen = vec2(0.0);
    if (!pb_unit(texel, level, block) || !pb_traced(level, block)) return false;
    int b = 1 << level;
    ivec2 lo = block * b;
    vec2 extent = vec2(min(lo + b, pb_screen()) - lo);
    screen = vec2(lo) + jitter * extent;
    return true;
}

// A unit's neighbours in the atlas are the neighbouring blocks of its level.
#define SAMPLING_HAS_FOOTPRINT
float sample_footprint(ivec2 texel, vec2 screen) {
    int level;
    ivec2 block;
    pb_unit(texel, level, block);
    return float(1 << level);
}

#endif
