//! Ray sets and their timing for `fovea bench`'s ray-rate figures, shared by the scene and
//! Visual-Polar measurements.

use anyhow::Result;
use fovea_renderer::frame::CameraPose;
use fovea_renderer::gpu_scene::GpuScene;
use fovea_renderer::layouts::{HitGpu, RayGpu};
use fovea_renderer::passes::raycast::RayCaster;
use glam::Vec3;

/// Runs of each ray set after the untimed warm-up; the median GPU time is reported.
const TIMED_RUNS: usize = 5;

/// Traces `rays` once untimed (warm-up), then `TIMED_RUNS` times; returns the hits and the
/// median GPU milliseconds.
pub fn timed_trace(
    caster: &mut RayCaster,
    gpu: &GpuScene,
    rays: &[RayGpu],
    any_hit: bool,
) -> Result<(Vec<HitGpu>, f64)> {
    let (hits, _) = caster.trace(gpu, rays, any_hit)?;
    let mut ms = Vec::with_capacity(TIMED_RUNS);
    for _ in 0..TIMED_RUNS {
        ms.push(caster.trace(gpu, rays, any_hit)?.1);
    }
    ms.sort_by(f64::total_cmp);
    Ok((hits, ms[TIMED_RUNS / 2]))
}

/// One primary ray through each pixel centre of a `w`×`h` frame seen from `pose`.
pub fn primary_rays(pose: &CameraPose, w: u32, h: u32) -> Vec<RayGpu> {
    let origin = pose.world_from_view.w_axis.truncate();
    let t = pose.fov_tan;
    let mut rays = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let fx = (x as f32 + 0.5) / w as f32;
            let fy = (y as f32 + 0.5) / h as f32;
            let view = Vec3::new(t.x + fx * (t.y - t.x), t.w + fy * (t.z - t.w), -1.0);
            let dir = pose.world_from_view.transform_vector3(view).normalize();
            rays.push(RayGpu {
                origin_tmin: origin.extend(0.0),
                direction_tmax: dir.extend(1e30),
            });
        }
    }
    rays
}
