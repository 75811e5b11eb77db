#version 460
// Automatic exposure, step 2: the frame's histogram → the exposure every view's tone mapping
// applies. The mean log2 luminance over the histogram's weight, its darkest and brightest shares
// left out, is brought to the key (middle grey); the applied exposure moves toward that target
// like an eye adapting, faster toward a brighter scene than toward a darker one, and the first
// metered frame takes its target at once. The histogram is cleared for the next frame. In manual
// mode the exposure is the given multiplier (written here, on the queue, so frames in flight
// never see it change under them).
#include "../common/layouts.glsl"

layout(local_size_x = 1) in;
layout(push_constant) uniform Push { ExposureAdaptPush p; } push;
layout(set = 0, binding = 0, std430) buffer Histogram { uint bins[]; } histogram;
layout(set = 0, binding = 1, std430) buffer State { ExposureState s; } state;
// This frame's copy, read back with the frame (host-visible, one per frame slot).
layout(set = 0, binding = 2, std430) writeonly buffer FrameExposure { ExposureState s; } frame_exposure;

void main() {
    vec4 s = state.s.values;
    if (push.p.params.x < 0.5) {
        float e = push.p.params.y;
        state.s.values = vec4(e, log2(e), log2(e), s.w);
        frame_exposure.s.values = state.s.values;
        return;
    }
    float total = 0.0;
    for (uint i = 0u; i < EXPOSURE_BINS; ++i) total += float(histogram.bins[i]);
    float current = s.w > 0.0 ? s.y : 0.0;
    float target = current;
    if (total > 0.0) {
        float lo = total * push.p.adapt.z;
        float hi = total * (1.0 - push.p.adapt.w);
        float below = 0.0, sum = 0.0, weight = 0.0;
        float bin_log2 = (EXPOSURE_LOG2_MAX - EXPOSURE_LOG2_MIN) / float(EXPOSURE_BINS);
        for (uint i = 0u; i < EXPOSURE_BINS; ++i) {
            float w = float(histogram.bins[i]);
            float kept = max(0.0, min(below + w, hi) - max(below, lo));
            below += w;
            sum += kept * (EXPOSURE_LOG2_MIN + (float(i) + 0.5) * bin_log2);
            weight += kept;
        }
        float mean = weight > 0.0 ? sum / weight : 0.0;
        target = clamp(push.p.limits.z - mean + push.p.params.z, push.p.limits.x, push.p.limits.y);
        if (s.w > 0.0) {
            // A lower target exposure: the scene got brighter.
            float tau = target < current ? push.p.adapt.x : push.p.adapt.y;
            current += (target - current) * (1.0 - exp(-push.p.params.w / max(tau, 1e-6)));
        } else {
            current = target;
        }
        s.w += 1.0;
    }
    state.s.values = vec4(exp2(current), current, target, s.w);
    frame_exposure.s.values = state.s.values;
    for (uint i = 0u; i < EXPOSURE_BINS; ++i) histogram.bins[i] = 0u;
}
