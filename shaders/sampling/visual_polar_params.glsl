// The Visual-Polar parameters of the `sampling` buffer and the layout's per-column arcs, for
// every space that maps through Visual-Polar's mapping (visual_polar.glsl, random_acuity.glsl).
#ifndef FOVEA_SAMPLING_VISUAL_POLAR_PARAMS_GLSL
#define FOVEA_SAMPLING_VISUAL_POLAR_PARAMS_GLSL

#include "visual_polar_clipped.glsl"

// Per-column arcs of the layout (VisualPolar::column_table, two RGBA32F texels per column).
layout(set = 0, binding = 18) uniform samplerBuffer sampling_table;

VpArcs vp_column_arcs(uint col) {
    return VpArcs(texelFetch(sampling_table, int(2u * col)), texelFetch(sampling_table, int(2u * col + 1u)));
}

VpParams sampling_vp_params() {
    SamplingParams s = sampling.data;
    return vp_unpack(s.grid, s.gaze, s.shape0, s.shape1);
}

#endif
