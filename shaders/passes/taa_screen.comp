#version 460
// TAA after the remap to the screen (Karis 2014 in screen space; the paper's future work). The
// tracer jitters each VP sample by a Halton offset inside its VP texel and the remap reads the
// samples where they were traced, so one screen pixel sees a different sub-texel position every
// frame — a fraction of a pixel in the fovea, many pixels in the periphery, where a texel's
// footprint is large. Accumulating those frames here super-samples the periphery on the screen
// grid. Because the jitter spans one texel footprint f, the neighbourhood whose YCoCg box clips
// the history is 3×3 taps spaced max(1, f) pixels apart (a 1-pixel box would reject the history
// wherever the jitter moves the image by more than a pixel).
// Reprojection: the pixel's depth from the nearest VP sample (G-buffer), its world point through
// this frame's camera, then the previous camera. History keeps colour and the depth it was
// resolved with; where no tap of the previous 3×3 (same spacing) lies on a surface at the expected
// depth the pixel starts afresh (disocclusion). Not a per-tap test: at a geometric edge the
// nearest sample flips between the two surfaces from frame to frame, and the history there is
// meant to average both.
// Two variants, as the remap's: lavapipe executes both sides of every branch, so the paper's
// layout gets a kernel without the screen-clipped mapping; `clipped` is the general kernel.
//! variant paper:
//! variant clipped: VP_LAYOUT_CLIPPED
#include "../common/layouts.glsl"
#include "../common/camera.glsl"
#include "../sampling/visual_polar_clipped.glsl"
#include "../denoise/svgf.glsl"
#include "../denoise/taa.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { TaaScreenPush p; } push;
layout(std140, set = 0, binding = 0) uniform FrameBuffer { FrameData data; } frame;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D color;          // remapped radiance (screen)
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D normal_depth;   // VP G-buffer: w linear depth (0: miss)
layout(set = 0, binding = 3, rgba32f) uniform readonly image2D position;       // VP G-buffer: w depth change per texel
layout(set = 0, binding = 4, rgba32f) uniform readonly image2D prev_history;   // rgb colour, a depth (0: miss)
layout(set = 0, binding = 5, rgba32f) uniform writeonly image2D history;       // output = next history

#if defined(VP_LAYOUT_CLIPPED)
layout(set = 0, binding = 6) uniform samplerBuffer vp_columns;                // VisualPolar::column_table

vec4 vp_table_texel(uint i) {
    return texelFetch(vp_columns, int(i));
}

vec2 to_screen(VpParams P, vec2 g) {
    return vp_layout_vp_to_screen(P, g);
}

vec2 to_grid(VpParams P, vec2 s) {
    return vp_layout_screen_to_vp(P, s);
}
#else
// The paper's layout: every column a full circle (starts 0, ends 2π), no knots.
vec4 vp_table_texel(uint i) {
    return (i & 1u) == 0u ? vec4(0.0) : vec4(VP_TAU);
}

vec2 to_screen(VpParams P, vec2 g) {
    return vp_vp_to_screen(P, g);
}

vec2 to_grid(VpParams P, vec2 s) {
    return vp_screen_to_vp(P, s);
}
#endif

// Depth agreement for "the same surface": a relative slack plus the depth change over the
// neighbourhood's spacing (the nearest sample may lie a texel away from the pixel).
const float TAA_SCREEN_DEPTH_SLACK = 0.02;
const float TAA_SCREEN_DEPTH_GRADIENTS = 2.0;

// Screen pixels between neighbouring VP samples at continuous grid position g (the larger of the
// ρ and φ steps of one texel, through the space's own mapping, so either ρ axis): the distance
// this frame's jitter can move the remapped image.
float texel_footprint(VpParams P, vec2 g) {
    float x = clamp(g.x, 0.5, float(P.grid.x) - 0.5);
    float step_rho = length(to_screen(P, vec2(x + 0.5, g.y)) - to_screen(P, vec2(x - 0.5, g.y)));
    float step_phi = length(to_screen(P, vec2(x, g.y + 0.5)) - to_screen(P, vec2(x, g.y - 0.5)));
    return max(max(step_rho, step_phi), 1.0);
}

// The VP texel holding the sample nearest to continuous grid position g.
ivec2 nearest_texel(VpParams P, vec2 g) {
    uint col = vp_column_of(P, g.x);
    uint rows = vp_rows_in_column(P, col);
    return ivec2(col, min(uint(max(g.y, 0.0)), rows - 1u));
}

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(color);
    if (any(greaterThanEqual(t, size))) return;
    // Read the frame data in place, not through a local copy: lavapipe specialises a kernel on
    // the values of uniforms copied into locals (a recompile whenever the camera turns).
    VpParams P = vp_unpack(push.p.space.grid, push.p.space.gaze, push.p.space.shape0, push.p.space.shape1);
    vec2 s = vec2(t) + 0.5;
    vec3 c = svgf_sanitize(imageLoad(color, t).rgb);
    vec2 g = to_grid(P, s);
    ivec2 texel = nearest_texel(P, g);
    float depth = imageLoad(normal_depth, texel).w;
    float depth_step = imageLoad(position, texel).w;
    int spacing = int(round(texel_footprint(P, g)));

    // Neighbourhood statistics in YCoCg over 3×3 taps one footprint apart (clamped to the screen).
    vec3 cy = rgb_to_ycocg(c);
    vec3 lo = cy, hi = cy, sum = vec3(0.0);
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 tap = clamp(t + ivec2(dx, dy) * spacing, ivec2(0), size - 1);
            vec3 q = rgb_to_ycocg(svgf_sanitize(imageLoad(color, tap).rgb));
            lo = min(lo, q);
            hi = max(hi, q);
            sum += q;
        }
    }
    vec3 mean = sum / 9.0;

    // Where this pixel's surface (or, for a miss, its direction) was on the previous screen.
    vec3 view_dir = view_direction(s, frame.data.fov_tan, frame.data.screen.xy);
    vec3 prev_view;
    if (depth > 0.0) {
        vec3 world = (frame.data.world_from_view * vec4(view_dir * depth, 1.0)).xyz;
        prev_view = (frame.data.prev_view_from_world * vec4(world, 1.0)).xyz;
    } else {
        prev_view = mat3(frame.data.prev_view_from_world) * (mat3(frame.data.world_from_view) * view_dir);
    }
    float expected_depth = depth > 0.0 ? -prev_view.z : 0.0;
    vec2 prev_screen;
    bool on_screen = project_view(prev_view, frame.data.prev_fov_tan, frame.data.screen.xy, prev_screen)
                  && all(greaterThanEqual(prev_screen, vec2(0.0))) && all(lessThan(prev_screen, frame.data.screen.xy));

    vec3 result = c;
    if (push.p.params.y == 0.0 && on_screen) {
        float slack = TAA_SCREEN_DEPTH_SLACK * expected_depth + TAA_SCREEN_DEPTH_GRADIENTS * depth_step;
        ivec2 centre = ivec2(floor(prev_screen));
        bool seen = false;
        for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
                float d = imageLoad(prev_history, clamp(centre + ivec2(dx, dy) * spacing, ivec2(0), size - 1)).a;
                seen = seen || (depth > 0.0 ? abs(d - expected_depth) <= slack : d == 0.0);
            }
        }
        vec2 f = prev_screen - 0.5;
        ivec2 base = ivec2(floor(f));
        vec2 w = f - vec2(base);
        vec3 hist = vec3(0.0);
        float hist_weight = 0.0;
        for (int i = 0; i < 4 && seen; ++i) {
            ivec2 o = ivec2(i & 1, i >> 1);
            vec3 h = imageLoad(prev_history, clamp(base + o, ivec2(0), size - 1)).rgb;
            float wi = (o.x == 1 ? w.x : 1.0 - w.x) * (o.y == 1 ? w.y : 1.0 - w.y);
            if (any(isnan(h)) || any(isinf(h))) continue;
            hist += wi * h;
            hist_weight += wi;
        }
        if (hist_weight > 0.01) {
            vec3 hy = clip_toward_mean(lo, hi, mean, rgb_to_ycocg(max(hist / hist_weight, vec3(0.0))));
            result = taa_blend(cy, hy, push.p.params.x);
        }
    }
    imageStore(history, t, vec4(result, depth));
}
