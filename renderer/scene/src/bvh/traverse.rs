//! Triangle texel packing and the binary tree's CPU traversal (the 4-wide tree the GPU traverses
//! has its own, `wide::Bvh4::intersect`, with the GLSL's algorithm).

use super::{Bvh, BvhNode};
use crate::intersect::{Hit, Ray, WatertightRay};
use glam::Vec3;

/// Conservative slack for the slab test, 1 + 2·γ(3) (Ize, "Robust BVH Ray Traversal", JCGT 2013):
/// without it, a triangle lying exactly on a box face can be culled by rounding.
pub const SLAB_SLACK: f32 =
    1.0 + 2.0 * (3.0 * f32::EPSILON * 0.5) / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// A zero direction component would make `(plane − origin) · (1/0)` NaN when the origin lies on
/// the plane; a tiny signed component gives the same answer without NaN (the GPU does the same).
pub fn safe_inverse_dir(dir: Vec3) -> Vec3 {
    let fix = |d: f32| {
        if d == 0.0 {
            1.0 / 1e-30f32.copysign(d)
        } else {
            1.0 / d
        }
    };
    Vec3::new(fix(dir.x), fix(dir.y), fix(dir.z))
}

/// Entry distance into the box if the ray overlaps it within `[0, t_limit]` (conservatively).
#[inline]
pub fn slab_test(min: Vec3, max: Vec3, origin: Vec3, inv_dir: Vec3, t_limit: f32) -> Option<f32> {
    let t0 = (min - origin) * inv_dir;
    let t1 = (max - origin) * inv_dir;
    let near = t0.min(t1);
    let far = t0.max(t1);
    let t_near = near.x.max(near.y).max(near.z).max(0.0);
    let t_far = far.x.min(far.y).min(far.z) * SLAB_SLACK;
    (t_near <= t_far && t_near <= t_limit * SLAB_SLACK).then_some(t_near)
}

/// Tests a leaf's triangles (original indices) for `0 < t < t_max`: with `any_hit` the first
/// hit is returned at once; otherwise the closest so far (ties by [`crate::intersect`]'s rule) is
/// kept in `best` and `None` returned.
/// Hits carry `id_base` + the triangle's index (an instance's placed ids, 0 for the world tree).
pub(super) fn test_leaf(
    tris: &[[Vec3; 3]],
    leaf: &[u32],
    wray: &WatertightRay,
    t_max: f32,
    any_hit: bool,
    id_base: u32,
    best: &mut Option<Hit>,
) -> Option<Hit> {
    for &tri in leaf {
        let [a, b, c] = tris[tri as usize];
        if let Some((t, u, v)) = wray.intersect(a, b, c, t_max) {
            let hit = Hit {
                t,
                triangle: id_base + tri,
                u,
                v,
            };
            if any_hit {
                return Some(hit);
            }
            if best.is_none_or(|b| hit.is_closer_than(&b)) {
                *best = Some(hit);
            }
        }
    }
    None
}

/// 3 texels per leaf entry in `order`: (v0, bits(original index)), (v1, bits(flags)), (v2, 0),
/// the flag [`super::compressed::TRIANGLE_ALPHA_TESTED`] where `alpha_tested(original index)`.
pub(super) fn triangle_texels(
    order: &[u32],
    tris: &[[Vec3; 3]],
    alpha_tested: &dyn Fn(u32) -> bool,
) -> Vec<[f32; 4]> {
    let flag = |i: u32| {
        f32::from_bits(if alpha_tested(i) {
            super::compressed::TRIANGLE_ALPHA_TESTED
        } else {
            0
        })
    };
    order
        .iter()
        .flat_map(|&i| {
            let [a, b, c] = tris[i as usize];
            [
                [a.x, a.y, a.z, f32::from_bits(i)],
                [b.x, b.y, b.z, flag(i)],
                [c.x, c.y, c.z, 0.0],
            ]
        })
        .collect()
}

impl Bvh {
    /// 3 texels per triangle in `tri_order` order: (v0, bits(original index)), (v1, 0), (v2, 0).
    pub fn triangle_texels(&self, tris: &[[Vec3; 3]]) -> Vec<[f32; 4]> {
        triangle_texels(&self.tri_order, tris, &|_| false)
    }

    /// Closest hit (ties by the rule in [`crate::intersect`]) or, with `any_hit`, the first hit
    /// found, for `0 < t < t_max`. `tris` must be the array the tree was built from.
    pub fn intersect(
        &self,
        tris: &[[Vec3; 3]],
        ray: &Ray,
        t_max: f32,
        any_hit: bool,
    ) -> Option<Hit> {
        let wray = WatertightRay::new(ray);
        let inv_dir = safe_inverse_dir(ray.dir);
        let mut best: Option<Hit> = None;
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        let mut node = 0u32;
        loop {
            let n: &BvhNode = &self.nodes[node as usize];
            let limit = best.map_or(t_max, |h| h.t);
            let near = [0, 1].map(|c| {
                if n.is_empty_child(c) {
                    None
                } else {
                    slab_test(n.child_min[c], n.child_max[c], ray.origin, inv_dir, limit)
                }
            });
            // Visit the nearer child first; leaves are tested on the spot, interior children queued.
            let first = if let (Some(a), Some(b)) = (near[0], near[1]) {
                usize::from(b < a)
            } else {
                0
            };
            let mut next: [Option<u32>; 2] = [None, None];
            for (k, c) in [first, 1 - first].into_iter().enumerate() {
                if near[c].is_none() {
                    continue;
                }
                if n.child_count[c] == 0 {
                    next[k] = Some(n.child_ref[c]);
                    continue;
                }
                let start = n.child_ref[c] as usize;
                if let Some(hit) = test_leaf(
                    tris,
                    &self.tri_order[start..start + n.child_count[c] as usize],
                    &wray,
                    t_max,
                    any_hit,
                    0,
                    &mut best,
                ) {
                    return Some(hit);
                }
            }
            match next {
                [Some(a), Some(b)] => {
                    stack.push(b);
                    node = a;
                }
                [Some(a), None] | [None, Some(a)] => node = a,
                [None, None] => match stack.pop() {
                    Some(a) => node = a,
                    None => return best,
                },
            }
        }
    }
}
