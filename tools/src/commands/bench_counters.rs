//! `fovea bench`'s traversal counters: what a traversal reads per ray, counted on the device by
//! the counting kernel (`passes/raycast.counters`), so traversals and trees can be judged on any
//! device, lavapipe included: nodes opened, leaf triangles tested, alpha tests and bytes of node
//! and triangle data, per ray set (primary, shadow, indirect).
//!
//! A GPU runs rays in lockstep groups (32 lanes on NVIDIA): a group waits for its slowest ray.
//! `warp32_*` is the mean over groups of 32 consecutive rays of the group's largest count, a lower
//! bound of the group's lockstep steps; its ratio to the per-ray mean says how much the slowest
//! rays stretch a group.

use anyhow::Result;
use fovea_renderer::gpu_scene::GpuScene;
use fovea_renderer::layouts::RayGpu;
use fovea_renderer::passes::raycast::{RayCaster, RayCounts};
use serde::Serialize;

/// Rays per lockstep group of the `warp32_*` figures (an NVIDIA warp).
const WARP: usize = 32;

#[derive(Clone, Debug, Serialize)]
pub struct CountSummary {
    pub rays: usize,
    pub nodes_per_ray: f64,
    pub triangles_per_ray: f64,
    pub alpha_tests_per_ray: f64,
    /// Bytes of node and triangle (and instance) data read.
    pub bytes_per_ray: f64,
    pub triangles_p99: u32,
    pub triangles_max: u32,
    pub warp32_nodes: f64,
    pub warp32_triangles: f64,
}

/// Each ray set's summary (`shadow` is `null` where the scene has no light to aim at).
#[derive(Clone, Debug, Serialize)]
pub struct RaySetCounters {
    pub primary: CountSummary,
    pub shadow: Option<CountSummary>,
    pub indirect: CountSummary,
}

pub fn summarise(counts: &[RayCounts]) -> CountSummary {
    let n = counts.len().max(1) as f64;
    let mean = |f: fn(&RayCounts) -> u32| counts.iter().map(|c| f64::from(f(c))).sum::<f64>() / n;
    let mut triangles: Vec<u32> = counts.iter().map(|c| c.triangles).collect();
    triangles.sort_unstable();
    let p99 = triangles
        .get(((triangles.len().max(1) - 1) as f64 * 0.99) as usize)
        .copied()
        .unwrap_or(0);
    let groups = counts.len().div_ceil(WARP).max(1) as f64;
    let warp = |f: fn(&RayCounts) -> u32| {
        counts
            .chunks(WARP)
            .map(|g| f64::from(g.iter().map(f).max().unwrap_or(0)))
            .sum::<f64>()
            / groups
    };
    CountSummary {
        rays: counts.len(),
        nodes_per_ray: mean(|c| c.nodes),
        triangles_per_ray: mean(|c| c.triangles),
        alpha_tests_per_ray: mean(|c| c.alpha_tests),
        bytes_per_ray: mean(|c| c.bytes),
        triangles_p99: p99,
        triangles_max: triangles.last().copied().unwrap_or(0),
        warp32_nodes: warp(|c| c.nodes),
        warp32_triangles: warp(|c| c.triangles),
    }
}

/// Counts the three ray sets with `scene`'s traversal (shadow rays any-hit).
pub fn count_sets(
    caster: &mut RayCaster,
    scene: &GpuScene,
    primary: &[RayGpu],
    shadow: &[RayGpu],
    indirect: &[RayGpu],
) -> Result<RaySetCounters> {
    let mut count = |rays: &[RayGpu], any_hit: bool| -> Result<CountSummary> {
        Ok(summarise(&caster.trace_counted(scene, rays, any_hit)?.1))
    };
    Ok(RaySetCounters {
        primary: count(primary, false)?,
        shadow: if shadow.is_empty() {
            None
        } else {
            Some(count(shadow, true)?)
        },
        indirect: count(indirect, false)?,
    })
}

pub fn print(scene: &str, (w, h): (u32, u32), builder: &str, traversal: &str, c: &RaySetCounters) {
    let line = |set: &str, s: &CountSummary| {
        println!(
            "{scene} {w}×{h} [{builder}, {traversal} traversal] {set} counters per ray: {:.1} nodes, {:.1} triangles (p99 {}, max {}), {:.2} alpha tests, {:.0} bytes; per 32-ray group's slowest: {:.1} nodes, {:.1} triangles",
            s.nodes_per_ray,
            s.triangles_per_ray,
            s.triangles_p99,
            s.triangles_max,
            s.alpha_tests_per_ray,
            s.bytes_per_ray,
            s.warp32_nodes,
            s.warp32_triangles
        )
    };
    line("primary", &c.primary);
    if let Some(s) = &c.shadow {
        line("shadow", s);
    }
    line("indirect", &c.indirect);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summary_means_percentiles_and_groups() {
        let counts: Vec<RayCounts> = (0..64u32)
            .map(|i| RayCounts {
                nodes: i,
                triangles: if i == 5 { 100 } else { 1 },
                alpha_tests: i % 2,
                bytes: 10 * i,
            })
            .collect();
        let s = summarise(&counts);
        assert_eq!(s.rays, 64);
        assert_eq!(s.nodes_per_ray, 31.5);
        assert_eq!(s.triangles_per_ray, (63.0 + 100.0) / 64.0);
        assert_eq!(s.alpha_tests_per_ray, 0.5);
        assert_eq!(s.bytes_per_ray, 315.0);
        assert_eq!((s.triangles_p99, s.triangles_max), (1, 100));
        // Groups 0..32 and 32..64: slowest nodes 31 and 63; triangles 100 and 1.
        assert_eq!(s.warp32_nodes, 47.0);
        assert_eq!(s.warp32_triangles, 50.5);
    }
}
