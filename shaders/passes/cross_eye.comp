#version 460
// Cross-eye reuse, first pass (docs/design/binocular.md): each sample of this eye finds the
// sample of the other eye that looked at the same surface this frame — its primary hit projected
// into the other eye's camera and grid (its own gaze and shape), accepted on the same mesh at the
// same depth and normal as the denoisers' reprojection tests — and averages the two demodulated
// radiances. Where the surface's BRDF lobe is narrower than the angle between the eyes' views,
// the other eye saw other light (a reflection moves with the eye) and its sample weighs less,
// down to nothing (the roughness is the tracer's, in the radiance's w). Writes the merged radiance
// into `merged` (w: the roughness; −1 where nothing merged); the resolve pass writes it back once
// both eyes have read each other's samples.
//! variants per space
#include "../common/layouts.glsl"
#include "../common/frame.glsl"
#include "../common/camera.glsl"
#include "../denoise/grid.glsl"
#include "../denoise/svgf.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { CrossEyePush p; } push;

// The other eye's frame data (its camera), as binding 8 holds this eye's; an array of one, read
// at a push-constant index (see main).
layout(std140, set = 0, binding = 9) uniform OtherFrameBuffer { FrameData data[1]; } other_frame;
layout(set = 0, binding = 10, rgba32f) uniform readonly image2D radiance;
layout(set = 0, binding = 11, rgba32f) uniform readonly image2D normal_depth;
layout(set = 0, binding = 12, rgba32f) uniform readonly image2D position;      // camera-relative, w: depth gradient per texel
layout(set = 0, binding = 13, rg32ui) uniform readonly uimage2D ids;
layout(set = 0, binding = 14, rgba32f) uniform readonly image2D other_radiance;
layout(set = 0, binding = 15, rgba32f) uniform readonly image2D other_normal_depth;
layout(set = 0, binding = 16, rgba32f) uniform readonly image2D other_position;
layout(set = 0, binding = 17, rg32ui) uniform readonly uimage2D other_ids;
layout(set = 0, binding = 18, rgba32f) uniform writeonly image2D merged;

// The other eye's sample weighs fully where the lobe (GGX α = roughness²) is at least twice
// this multiple of the angle between the two views, nothing below once that multiple.
const float CROSS_EYE_LOBE_MARGIN = 2.0;
// As SVGF's reprojection: below this total bilinear weight the other eye has no sample here.
const float CROSS_EYE_MIN_TAP_WEIGHT = 0.01;

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(t, imageSize(merged)))) return;
    uvec2 id = imageLoad(ids, t).xy;
    // No sample here, or the environment seen directly (noise-free): nothing to merge.
    if (id.x == 0u) {
        imageStore(merged, t, vec4(-1.0));
        return;
    }
    vec4 pos = imageLoad(position, t);
    // The cameras and frusta through an index lavapipe cannot fold (push constant config.x,
    // always 0), as the tracer reads its own: lavapipe specialises kernels on the uniform values
    // that decide branches and would recompile this one per eye and whenever a camera moves.
    uint c0 = push.p.config.x;
    FrameData other_eye = other_frame.data[c0];
    // The point relative to the other camera, from camera-relative values (no large world
    // coordinates); the cameras are rigid: the transpose inverts their rotation.
    vec3 from_other = pos.xyz + (frame.data.world_from_view[c0 + 3u].xyz - other_eye.world_from_view[3].xyz);
    vec3 local = transpose(mat3(other_eye.world_from_view)) * from_other;
    vec2 size = vec2(push.p.other.grid.zw);
    vec2 screen, p;
    Grid other = grid_make(push.p.other);
    bool seen = project_view(local, other_eye.fov_tan, size, screen)
             && all(greaterThanEqual(screen, vec2(0.0))) && all(lessThan(screen, size))
             && grid_from_screen(other, screen, p);
    // The other eye's radiance at this point: its samples around it on the same surface,
    // bilinearly weighted (one sample's worth, as this eye's own).
    vec3 theirs = vec3(0.0);
    float found = 0.0;
    if (seen) {
        vec4 nd = imageLoad(normal_depth, t);
        // This sample's surface as the other eye sees it (its depth along the other camera's
        // axis), against what the other eye hit around it.
        SvgfSurface here = svgf_surface(vec4(nd.xyz, -local.z), pos.w, id);
        ivec2 taps[4];
        vec4 w;
        grid_bilinear(other, p, taps, w);
        for (int k = 0; k < 4; ++k) {
            ivec2 o = taps[k];
            if (w[k] <= 0.0 || !grid_holds_sample(other, o)) continue;
            uvec2 other_id = imageLoad(other_ids, o).xy;
            if (other_id.x == 0u) continue;
            SvgfSurface there = svgf_surface(imageLoad(other_normal_depth, o), imageLoad(other_position, o).w, other_id);
            if (!svgf_same_surface(here, there)) continue;
            // Finite: the tracer and the resampling passes write no NaN or Inf.
            theirs += w[k] * imageLoad(other_radiance, o).rgb;
            found += w[k];
        }
    }
    vec4 mine = imageLoad(radiance, t);
    float weight = 0.0;
    // Taps of a negligible bilinear weight alone are not a sample of this point.
    if (found > CROSS_EYE_MIN_TAP_WEIGHT) {
        theirs /= found;
        float roughness = mine.w;
        // The angle between the two views of the point (atan2: exact for small angles too).
        vec3 a = normalize(pos.xyz), b = normalize(from_other);
        float parallax = atan(length(cross(a, b)), dot(a, b));
        float lobe = roughness * roughness / max(CROSS_EYE_LOBE_MARGIN * parallax, 1e-6);
        // Up to one sample's worth, as this eye's own.
        weight = smoothstep(1.0, 2.0, lobe);
    }
    if (weight <= 0.0) {
        imageStore(merged, t, vec4(-1.0));
        return;
    }
    imageStore(merged, t, vec4((mine.rgb + weight * theirs) / (1.0 + weight), mine.w));
}
