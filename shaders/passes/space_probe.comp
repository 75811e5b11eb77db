#version 460
// Evaluates a sampling space's `sample_screen_position` for every texel of its grid as the tracer
// does (the frame index and seed of the `frame` buffer, no jitter), so a device test can compare
// it with the space's Rust twin texel by texel (tests/comparators.rs, tests/pixel_blocks.rs).
// out[i] = (screen x, y, 1 if the texel holds a sample else 0, samples it traces per frame),
// i = y · width + x.
//! variants per trace space
#include "../common/layouts.glsl"
#include "../sampling/space.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(std430, set = 0, binding = 0) writeonly buffer OutBuffer { vec4 data[]; } mapped;

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(sampling.data.grid.xy);
    if (any(greaterThanEqual(t, size))) return;
    vec2 screen;
    bool exists = sample_screen_position(t, vec2(0.5), screen);
#if defined(SAMPLING_SAMPLES_PER_TEXEL)
    float samples = float(sample_count_in_texel(t));
#else
    float samples = exists ? 1.0 : 0.0;
#endif
    mapped.data[t.y * size.x + t.x] = vec4(screen, exists ? 1.0 : 0.0, samples);
}
