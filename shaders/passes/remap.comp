#version 460
// Visual-Polar image → screen by backward mapping (visual-polar.md §6): every screen pixel finds
// its VP coordinate and samples there. ρ: bilinear between the two nearest columns (clamped at
// the ends); φ: wrapped, bilinear inside each column (its own row count), trilinear across the
// φ-only mips with the level picked from the pixel's φ footprint in that column.
#include "../common/layouts.glsl"
#include "../sampling/visual_polar_math.glsl"
#include "../sampling/phi_mips.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { RemapPush p; } push;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D mips;          // all levels, stacked
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D screen_color;

vec4 fetch(uint level, uint height, uint col, uint row) {
    return imageLoad(mips, ivec2(col, phi_mip_offset(level, height) + row));
}

// Linear along φ at one level; y0 = continuous row coordinate at level 0 (texel centres at +½).
vec4 sample_phi(uint col, uint rows0, float y0, uint level, uint height) {
    uint m = phi_mip_rows(rows0, level);
    float y = y0 / float(1u << level) - 0.5;
    float f = floor(y);
    int a = int(f) % int(m);
    if (a < 0) a += int(m);
    uint b = (uint(a) + 1u) % m;
    return mix(fetch(level, height, col, uint(a)), fetch(level, height, col, b), y - f);
}

vec4 sample_column(VpParams P, uint col, float phi, float r, uint levels) {
    uint rows0 = vp_rows_in_column(P, col);
    float y0 = phi / VP_TAU * float(rows0);
    // One pixel spans 1/r radians of φ: that many rows of this column.
    float footprint = float(rows0) / (VP_TAU * max(r, 0.5));
    float lod = clamp(log2(max(footprint, 1.0)), 0.0, float(levels - 1u));
    uint l0 = uint(lod);
    uint l1 = min(l0 + 1u, levels - 1u);
    vec4 v0 = sample_phi(col, rows0, y0, l0, P.grid.y);
    vec4 v1 = sample_phi(col, rows0, y0, l1, P.grid.y);
    return mix(v0, v1, lod - float(l0));
}

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(t, imageSize(screen_color)))) return;
    VpParams P = vp_unpack(push.p.vp_grid, push.p.vp_gaze, push.p.vp_shape0, push.p.vp_shape1);
    vec2 d = vec2(t) + 0.5 - P.gaze;
    float r = length(d);
    float phi = r > 0.0 ? atan(d.y, d.x) : 0.0;
    if (phi < 0.0) phi += VP_TAU;
    float x = clamp(vp_u_of_r(P, r) * float(P.grid.x) - 0.5, 0.0, float(P.grid.x - 1u));
    uint c0 = uint(x);
    uint c1 = min(c0 + 1u, P.grid.x - 1u);
    uint levels = max(push.p.config.x, 1u);
    vec4 v0 = sample_column(P, c0, phi, r, levels);
    vec4 v1 = c1 == c0 ? v0 : sample_column(P, c1, phi, r, levels);
    imageStore(screen_color, t, mix(v0, v1, x - float(c0)));
}
