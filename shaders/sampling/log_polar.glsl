// Kernel log-polar radial law (Meng et al. 2018; comparators.md §D): GLSL twin of
// renderer/src/sampling/log_polar.rs, op for op (same constants, same f32 order) so a device
// test can compare them. u = K(ln r / L), K(t) = t^α; r = exp(L · K⁻¹(u)). Included by
// visual_polar_math.glsl (after vp_ln), whose vp_r_of_u / vp_u_of_r call it when the space's
// radial law is log-polar; everything else of the polar space is Visual-Polar's.
#ifndef FOVEA_SAMPLING_LOG_POLAR_GLSL
#define FOVEA_SAMPLING_LOG_POLAR_GLSL

// e^x in plain arithmetic (Rust exp_f32): the driver's exp may be several ulp off.
float lp_exp(float x) {
    float k = floor(x * 1.442695 + 0.5);
    float f = (x - k * 0.69314575) - k * 1.4286068e-6;
    float p = ((((((1.984127e-4 * f + 1.3888889e-3) * f + 8.333333e-3) * f + 4.1666668e-2) * f + 0.16666667) * f + 0.5)
        * f + 1.0) * f + 1.0;
    return ldexp(p, int(k));
}

// t^a for t >= 0 (0 ↦ 0), Rust pow_unit.
float lp_pow_unit(float t, float a) {
    return t <= 0.0 ? 0.0 : lp_exp(a * vp_ln(t));
}

// Pixels from the gaze of normalised column u (Rust LogPolarLaw::r_of_u).
float lp_r_of_u(float u, float L, float alpha) {
    return lp_exp(L * lp_pow_unit(max(u, 0.0), 1.0 / alpha));
}

// Normalised column of distance r (Rust LogPolarLaw::u_of_r); within one pixel of the gaze, 0.
float lp_u_of_r(float r, float L, float alpha) {
    return r <= 1.0 ? 0.0 : lp_pow_unit(vp_ln(r) / L, alpha);
}

#endif
