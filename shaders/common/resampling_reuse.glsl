// Which reservoirs ReSTIR DI's and GI's passes reuse (docs/design/resampling.md): last frame's
// only from a shading point near this one, a neighbour's only on a similar surface.
// Needs scene.glsl (the frame) and denoise/svgf.glsl first.
#ifndef FOVEA_RESAMPLING_REUSE_GLSL
#define FOVEA_RESAMPLING_REUSE_GLSL

// How far (in pixels at the sample's depth) last frame's shading point may lie from this one for
// its reservoir to be reused: in the Visual-Polar periphery a texel spans many pixels and its
// jittered sample crosses it from frame to frame, and a reservoir drawn for a point that far away
// is a poor proposal here.
const float RESAMPLING_TEMPORAL_PIXELS = 2.0;

bool resampling_near_previous(vec3 previous, vec3 here, float depth) {
    float pixel = (frame.data.fov_tan.y - frame.data.fov_tan.x) * frame.data.screen.z * depth;
    return distance(previous, here) <= RESAMPLING_TEMPORAL_PIXELS * pixel;
}

// A neighbour's reservoir is reused on a surface within this relative depth and angle of the
// sample's own (its p̂ is re-evaluated here; the test keeps out what the re-evaluation cannot
// see: occlusion between the two surfaces and their different visibility).
const float RESAMPLING_NEIGHBOUR_DEPTH = 0.1;
const float RESAMPLING_NEIGHBOUR_NORMAL_COS = 0.9;

bool similar_surface(SvgfSurface a, SvgfSurface b) {
    return b.key != 0u && abs(a.depth - b.depth) <= RESAMPLING_NEIGHBOUR_DEPTH * a.depth
        && dot(a.normal, b.normal) >= RESAMPLING_NEIGHBOUR_NORMAL_COS;
}

#endif
