#version 460
// A-SVGF forward projection (Schied et al. 2018, §4.1): per stratum of last frame's grid, the
// brightest sample that the tracer marked as a possible source (its luminance in the visibility's
// w, asvgf_source_bits: without resampling every sample that hit a surface, so the brightest — a
// moving penumbra shows up there first; with resampling the one texel whose plain path estimate
// the tracer kept) is carried to this frame — world position → this frame's screen → this
// frame's grid — and claims the stratum it lands in (the first claim wins). The tracer's gradient
// variant then traces that sample's path on that surface again, with its random state, from the
// texel it landed in. The luminance is the tracer's own, before
// resampling or another eye's samples change the G-buffer's radiance. Runs before the tracer, so
// the G-buffer still holds last frame. Each invocation also clears its stratum of the gradient
// image, where the tracer writes the strata that got a gradient sample (the strata grids of both
// frames are one). Strata in the Visual-Polar grid: shaders/denoise/strata.glsl.
//! variants per space
#include "../../common/layouts.glsl"
#include "../../common/camera.glsl"
#include "../../denoise/strata.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { AsvgfForwardPush p; } push;
layout(std140, set = 0, binding = 0) uniform FrameBuffer { FrameData data; } frame;
layout(set = 0, binding = 2, rg32ui) uniform readonly uimage2D ids;           // x triangle + 1 (0: miss)
layout(set = 0, binding = 3, rgba32f) uniform readonly image2D position;      // camera-relative (last camera)
layout(set = 0, binding = 4, rgba32ui) uniform readonly uimage2D visibility;  // barycentrics, RNG state, source luminance
layout(std430, set = 0, binding = 5) buffer GradientSamples { AsvgfGradientSample data[]; } gradient_samples;
layout(set = 0, binding = 6, rgba32f) uniform writeonly image2D gradient;   // per stratum: δ, max f, 1 (written by the tracer)

// The camera position of a rigid view-from-world transform.
vec3 camera_origin(mat4 view_from_world) {
    return -(transpose(mat3(view_from_world)) * view_from_world[3].xyz);
}

void main() {
    ivec2 s = ivec2(gl_GlobalInvocationID.xy);
    // The grid's rows per column do not depend on the gaze: this frame's grid addresses last frame's.
    Grid g = grid_make(push.p.space);
    if (any(greaterThanEqual(s, strata_size(g)))) return;
    imageStore(gradient, s, vec4(0.0));
    if (push.p.config.x == 0u || !stratum_holds_samples(g, s)) return;

    float brightest = -1.0;
    ivec2 picked = ivec2(0);
    for (int j = 0; j < STRATUM; ++j) {
        for (int i = 0; i < STRATUM; ++i) {
            ivec2 t = STRATUM * s + ivec2(i, j);
            uint source = imageLoad(visibility, t).w;
            if (!grid_holds_sample(g, t) || imageLoad(ids, t).x == 0u || !asvgf_is_source(source)) continue;
            float l = asvgf_source_luminance(source);
            if (l > brightest) {
                brightest = l;
                picked = t;
            }
        }
    }
    if (brightest < 0.0) return;

    // Read the frame data in place, not through a local copy: lavapipe specialises a kernel on
    // the values of uniforms copied into locals (a recompile whenever the camera turns).
    vec3 world = imageLoad(position, picked).xyz + camera_origin(frame.data.prev_view_from_world);
    vec3 view = transpose(mat3(frame.data.world_from_view)) * (world - frame.data.world_from_view[3].xyz);
    vec2 screen;
    vec2 p;
    if (!project_view(view, frame.data.fov_tan, frame.data.screen.xy, screen) || !grid_from_screen(g, screen, p)) return;
    ivec2 target = grid_nearest(g, p);
    if (!grid_holds_sample(g, target)) return;

    uint index = asvgf_stratum_index(target, g.size.x);
    uint claim = uint(picked.y * g.size.x + picked.x) + 1u;
    if (atomicCompSwap(gradient_samples.data[index].surface.x, 0u, claim) != 0u) return;
    uvec4 vis = imageLoad(visibility, picked);
    gradient_samples.data[index].surface.yzw = uvec3(imageLoad(ids, picked).x, vis.xy);
    gradient_samples.data[index].shading = uvec4(uint(target.x) | (uint(target.y) << 16u), vis.z, floatBitsToUint(brightest), ASVGF_NO_LUMINANCE);
}
