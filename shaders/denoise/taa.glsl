// TAA resolve shared by the sampling-grid pass (taa.comp) and the screen-space pass
// (taa_screen.comp): YCoCg neighbourhood statistics, clipping toward the mean, luma-weighted blend.
#ifndef FOVEA_DENOISE_TAA_GLSL
#define FOVEA_DENOISE_TAA_GLSL

vec3 rgb_to_ycocg(vec3 c) {
    return vec3(dot(c, vec3(0.25, 0.5, 0.25)), dot(c, vec3(0.5, 0.0, -0.5)), dot(c, vec3(-0.25, 0.5, -0.25)));
}

vec3 ycocg_to_rgb(vec3 c) {
    return vec3(c.x + c.y - c.z, c.x + c.z, c.x - c.y - c.z);
}

// The point where the segment from `mean` (inside the box) to `h` leaves the box [lo, hi]: a clip
// toward the mean keeps the history's hue where a per-axis clamp would not.
vec3 clip_toward_mean(vec3 lo, vec3 hi, vec3 mean, vec3 h) {
    vec3 d = h - mean;
    float t = 1.0;
    for (int i = 0; i < 3; ++i) {
        if (d[i] > 1e-7) t = min(t, (hi[i] - mean[i]) / d[i]);
        else if (d[i] < -1e-7) t = min(t, (lo[i] - mean[i]) / d[i]);
    }
    return mean + max(t, 0.0) * d;
}

// Current sample `cy` and history `hy` (both YCoCg, history already clipped) blended with
// Karis's luma weights: a bright outlier pulls the blend far less than its share `alpha`.
vec3 taa_blend(vec3 cy, vec3 hy, float alpha) {
    float wc = alpha / (1.0 + max(cy.x, 0.0));
    float wh = (1.0 - alpha) / (1.0 + max(hy.x, 0.0));
    return max(ycocg_to_rgb((wc * cy + wh * hy) / (wc + wh)), vec3(0.0));
}

#endif
