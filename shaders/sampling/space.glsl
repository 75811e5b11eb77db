// Selects the sampling space a kernel variant is compiled for. Every space provides
// `bool sample_screen_position(ivec2 texel, vec2 jitter, out vec2 screen)` and
// `bool sample_exists(ivec2 texel)` (whether the former returns true, without mapping). A space
// whose neighbouring texels are not neighbours on the screen defines SAMPLING_HAS_FOOTPRINT and
// `float sample_footprint(ivec2 texel, vec2 screen)` (the screen spacing of its samples there). A
// space tracing several samples in some texels defines SAMPLING_SAMPLES_PER_TEXEL and
// `uint sample_count_in_texel(ivec2 texel)`: the trace's sample index k draws only where k < it.
#ifndef FOVEA_SAMPLING_SPACE_GLSL
#define FOVEA_SAMPLING_SPACE_GLSL

#include "../common/layouts.glsl"

// Uniform for the same reason as `frame` (scene.glsl).
layout(std140, set = 0, binding = 9) uniform SamplingBuffer { SamplingParams data; } sampling;

#if defined(SAMPLING_CARTESIAN)
#include "cartesian.glsl"
#elif defined(SAMPLING_VISUAL_POLAR)
#include "visual_polar.glsl"
#elif defined(SAMPLING_LINEAR_FALLOFF)
#include "linear_falloff.glsl"
#elif defined(SAMPLING_RANDOM_ACUITY)
#include "random_acuity.glsl"
#elif defined(SAMPLING_PIXEL_BLOCKS)
#include "pixel_blocks.glsl"
#elif defined(SAMPLING_VRS_TILES)
#include "vrs_tiles.glsl"
#else
#error "no sampling space selected"
#endif

#endif
