// The frame's data (binding 8), on its own for kernels that need the frame index and seed without
// the scene (the sparse spaces' sample choice, sampling/linear_falloff.glsl and friends).
#ifndef FOVEA_FRAME_GLSL
#define FOVEA_FRAME_GLSL

#include "layouts.glsl"

// Uniform, not storage: every lane reads the same frame data, and lavapipe turns storage-buffer
// reads into one load per lane (std140 = std430 here: FrameData is all vec4/mat4).
layout(std140, set = 0, binding = 8) uniform FrameBuffer { FrameData data; } frame;

#endif
