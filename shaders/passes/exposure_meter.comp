#version 460
// Automatic exposure, step 1: one view's screen radiance into the frame's histogram of log2
// luminance. One invocation per block of pixels: the block's mean luminance over 4×4 taps is
// binned, so a noisy frame (sparse bright samples among black ones) is metered by its mean and
// not by its specks. Each block weighs 1 + boost · exp(−(d / r)²) at distance d from the gaze
// (metering centred where the eye looks); blocks with no light (the void around a scene) are
// left out, so a lit object in the dark is exposed for itself. Every view adds to the one
// histogram: both eyes share one exposure.
#include "../common/layouts.glsl"

layout(local_size_x = WORKGROUP_2D, local_size_y = WORKGROUP_2D) in;
layout(push_constant) uniform Push { ExposureMeterPush p; } push;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D radiance;
layout(set = 0, binding = 1, std430) buffer Histogram { uint bins[]; } histogram;

shared uint local_bins[EXPOSURE_BINS];

const uint LANES = WORKGROUP_2D * WORKGROUP_2D;
const int TAPS = 4;

void main() {
    uint lane = gl_LocalInvocationIndex;
    for (uint i = lane; i < EXPOSURE_BINS; i += LANES) local_bins[i] = 0u;
    barrier();
    int block = int(push.p.config.x);
    ivec2 size = imageSize(radiance);
    ivec2 origin = ivec2(gl_GlobalInvocationID.xy) * block;
    if (all(lessThan(origin, size))) {
        ivec2 extent = min(ivec2(block), size - origin);
        float sum = 0.0;
        int n = 0;
        for (int y = 0; y < TAPS; ++y) {
            for (int x = 0; x < TAPS; ++x) {
                ivec2 tap = origin + (ivec2(x, y) * extent + extent / 2) / TAPS;
                float l = dot(imageLoad(radiance, tap).rgb, vec3(0.2126, 0.7152, 0.0722));
                // NaN and infinity (a broken sample) are left out rather than poisoning the mean.
                if (l >= 0.0 && l < 3.0e38) {
                    sum += l;
                    ++n;
                }
            }
        }
        float mean = n > 0 ? sum / float(n) : 0.0;
        if (mean > exp2(EXPOSURE_LOG2_MIN) && mean < 3.0e38) {
            float t = (log2(mean) - EXPOSURE_LOG2_MIN) / (EXPOSURE_LOG2_MAX - EXPOSURE_LOG2_MIN);
            uint bin = uint(clamp(t * float(EXPOSURE_BINS), 0.0, float(EXPOSURE_BINS - 1u)));
            float d = length(vec2(origin) + 0.5 * vec2(extent) - push.p.gaze.xy) * push.p.gaze.z;
            float w = 1.0 + push.p.gaze.w * exp(-d * d);
            atomicAdd(local_bins[bin], uint(round(EXPOSURE_WEIGHT_SCALE * w)));
        }
    }
    barrier();
    for (uint i = lane; i < EXPOSURE_BINS; i += LANES) {
        if (local_bins[i] != 0u) atomicAdd(histogram.bins[i], local_bins[i]);
    }
}
