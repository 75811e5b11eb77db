//! Judging images: per-ring error metrics against converged references (RMSE, SSIM, FLIP,
//! temporal flicker), the binocular consistency measure, sample density against its target, and
//! the line plots the reports draw.

pub mod binocular;
pub mod density;
pub mod flip;
pub mod metrics;
pub mod plot;
