// The Visual-Polar parameters of the `sampling` buffer and the layout's per-column arcs, for
// every space that maps through Visual-Polar's mapping (visual_polar.glsl, random_acuity.glsl).
#ifndef FOVEA_SAMPLING_VISUAL_POLAR_PARAMS_GLSL
#define FOVEA_SAMPLING_VISUAL_POLAR_PARAMS_GLSL

#include "visual_polar_clipped.glsl"

// The layout's table (VisualPolar::column_table: per-column arcs, then the screen-aware axis' knots).
layout(set = 0, binding = 18) uniform samplerBuffer sampling_table;

vec4 vp_table_texel(uint i) {
    return texelFetch(sampling_table, int(i));
}

VpParams sampling_vp_params() {
    SamplingParams s = sampling.data;
    return vp_unpack(s.grid, s.gaze, s.shape0, s.shape1);
}

#endif
