// Gaussian tap weights for the foveated blurs (passes/blur.comp on the screen, blur_grid.comp in
// the Visual-Polar grid): w(i) = exp(−i²/2s²) for taps i = 1, 2, … spaced evenly, s = σ in tap
// spacings, by recurrence instead of one exp per tap: w(i+1) = w(i)·q·c^i, q = exp(−1/2s²), c = q².
#ifndef FOVEA_GAUSSIAN_GLSL
#define FOVEA_GAUSSIAN_GLSL

struct GaussianTaps {
    float w;     // the last tap's weight (1 before the first)
    float ratio; // w(i+1) / w(i)
    float c;
};

GaussianTaps gaussian_taps(float sigma_in_spacings) {
    float q = exp(-0.5 / (sigma_in_spacings * sigma_in_spacings));
    return GaussianTaps(1.0, q, q * q);
}

// The next tap's weight.
float gaussian_next(inout GaussianTaps g) {
    g.w *= g.ratio;
    g.ratio *= g.c;
    return g.w;
}

#endif
