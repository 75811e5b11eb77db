#version 460
// Evaluates the Visual-Polar mapping of visual_polar_math.glsl / visual_polar_clipped.glsl (the
// layout the parameters were packed with) on a list of points, so the device test
// (tests/vp_mapping.rs) can compare it with the Rust twin point by point.
// points[i].xy: continuous grid coordinates → out[i].xy = vp_layout_vp_to_screen
// points[i].zw: screen position (pixels)    → out[i].zw = vp_layout_screen_to_vp
#include "../common/layouts.glsl"
#include "../sampling/visual_polar_clipped.glsl"

layout(local_size_x = WORKGROUP_1D) in;
layout(push_constant) uniform Push { VpProbePush p; } push;
layout(std430, set = 0, binding = 0) readonly buffer SamplingBuffer { SamplingParams data; } sampling;
layout(std430, set = 0, binding = 1) readonly buffer PointBuffer { vec4 data[]; } points;
layout(std430, set = 0, binding = 2) writeonly buffer OutBuffer { vec4 data[]; } mapped;
layout(set = 0, binding = 3) uniform samplerBuffer vp_columns; // VisualPolar::column_table

vec4 vp_table_texel(uint i) {
    return texelFetch(vp_columns, int(i));
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.p.config.x) return;
    SamplingParams s = sampling.data;
    VpParams P = vp_unpack(s.grid, s.gaze, s.shape0, s.shape1);
    vec4 q = points.data[i];
    mapped.data[i] = vec4(vp_layout_vp_to_screen(P, q.xy), vp_layout_screen_to_vp(P, q.zw));
}
