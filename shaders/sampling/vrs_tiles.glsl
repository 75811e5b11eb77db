// Variable-rate tiles (the foveation eye-tracked headsets ship through variable-rate shading),
// packed so no lane idles: the screen in shape0.x-pixel tiles, each traced at one sample per
// pixel, per 2×2 or per 4×4 block — rate 1 for tiles nearer the gaze than gaze.z, 2 nearer than
// gaze.w, else 4 (by the tile's point nearest the gaze; the radii where Visual-Polar's density
// falls to 1/4 and 1/16, from the Rust side). The grid is the screen padded to whole tiles, read
// in 8×8 workgroup order; each tile row owns the grid's next tiles_x × 256 texels, filled with its
// rate-1 tiles' samples, then rate 2, then rate 4, the rest idle (whole workgroups, at its end).
// Within a tile the blocks go by 4×4 patches; a block's sample is the pixel nearest its centre
// (clamped to the screen). Way back: splat, fill, blur. Rust: sampling::VrsTiles.
#ifndef FOVEA_SAMPLING_VRS_TILES_GLSL
#define FOVEA_SAMPLING_VRS_TILES_GLSL

// Pixels per tile side: sampling::VRS_TILE, passed in shape0.x (one source of truth).
int vrs_tile_pixels() {
    return int(sampling.data.shape0.x);
}

// Tile columns [x, y) of tile row `row` whose nearest point lies closer than `r` to the gaze.
ivec2 vrs_columns_within(int row, float r) {
    vec2 g = sampling.data.gaze.xy;
    float t = float(vrs_tile_pixels());
    float dy = max(0.0, max(float(row) * t - g.y, g.y - float(row + 1) * t));
    if (dy >= r) return ivec2(0);
    float w = sqrt(r * r - dy * dy);
    int tiles_x = int(sampling.data.shape0.y);
    int lo = clamp(int(floor((g.x - w) / t)), 0, tiles_x);
    int hi = min(tiles_x, int(ceil((g.x + w) / t)));
    return ivec2(lo, max(lo, hi));
}

// The screen pixel of grid texel `texel`'s sample; false where the texel holds none.
bool vrs_pixel(ivec2 texel, out ivec2 pixel) {
    pixel = ivec2(0);
    ivec2 grid = ivec2(sampling.data.grid.xy);
    ivec2 screen = ivec2(sampling.data.grid.zw);
    if (any(lessThan(texel, ivec2(0))) || any(greaterThanEqual(texel, grid))) return false;
    int tiles_x = int(sampling.data.shape0.y);
    int k = ((texel.y / 8) * (grid.x / 8) + texel.x / 8) * 64 + (texel.y % 8) * 8 + texel.x % 8;
    int tile = vrs_tile_pixels();
    int capacity = tiles_x * tile * tile;
    int row = k / capacity;
    k -= row * capacity;
    ivec2 fine = vrs_columns_within(row, sampling.data.gaze.z);
    ivec2 mid = vrs_columns_within(row, sampling.data.gaze.w);
    if (fine.x == fine.y) fine = ivec2(mid.x);
    // (first tile, tiles, rate) of the row's five runs, in packing order.
    ivec3 runs[5] = ivec3[5](ivec3(fine.x, fine.y - fine.x, 1), ivec3(mid.x, fine.x - mid.x, 2), ivec3(fine.y, mid.y - fine.y, 2),
                             ivec3(0, mid.x, 4), ivec3(mid.y, tiles_x - mid.y, 4));
    for (int i = 0; i < 5; ++i) {
        int rate = runs[i].z;
        int per_side = tile / rate;
        int per_tile = per_side * per_side;
        if (k < runs[i].y * per_tile) {
            int column = runs[i].x + k / per_tile;
            int s = k % per_tile;
            int patches = per_side / 4;
            int group = s / 16, q = s % 16;
            ivec2 block = ivec2((group % patches) * 4 + q % 4, (group / patches) * 4 + q / 4);
            ivec2 origin = ivec2(column, row) * tile + block * rate;
            if (any(greaterThanEqual(origin, screen))) return false;
            pixel = min(origin + rate / 2, screen - 1);
            return true;
        }
        k -= runs[i].y * per_tile;
    }
    return false;
}

bool sample_exists(ivec2 texel) {
    ivec2 pixel;
    return vrs_pixel(texel, pixel);
}

bool sample_screen_position(ivec2 texel, vec2 jitter, out vec2 screen) {
    ivec2 pixel;
    bool exists = vrs_pixel(texel, pixel);
    screen = vec2(pixel) + jitter;
    return exists;
}

#endif
