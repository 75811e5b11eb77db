//! 4-wide BVH collapsed from the binary tree, the layout the GPU traverses.
//!
//! Collapse (as in Ylitie, Karras, Laine 2017, with SAH-free greedy choice): a wide node takes its
//! binary node's two children and, while it has fewer than 4, replaces the interior child of
//! largest surface area by that child's two children. Leaves and `tri_order` are the binary
//! tree's, unchanged. Node 0 is the root; unused slots are empty children (count 0, ref 0,
//! inverted box).
//!
//! GPU layout, 8 RGBA32F texels per node, one component per child (structure of arrays, so the
//! traversal tests the four boxes as vec4 operations): min.x, min.y, min.z, max.x, max.y, max.z,
//! bits(child_ref), bits(child_count).

use super::traverse::{safe_inverse_dir, slab_test, test_leaf};
use super::{Bvh, BvhNode, NodeOf, TraceState};
use crate::intersect::{Hit, Ray, WatertightRay};
use crate::Aabb;
use glam::Vec3;

pub const WIDTH: usize = 4;
/// Bytes the traversal reads per node visited and per leaf triangle tested (texel buffers).
pub const NODE_BYTES: u64 = 128;
pub const TRIANGLE_BYTES: u64 = 48;

/// One 4-wide node: the four children's boxes, refs and counts (as [`BvhNode`]'s two).
pub type Bvh4Node = NodeOf<WIDTH>;

#[derive(Clone, Debug, Default)]
pub struct Bvh4 {
    pub nodes: Vec<Bvh4Node>,
    /// The binary tree's leaf order (original triangle indices, duplicates for an SBVH).
    pub tri_order: Vec<u32>,
}

/// A binary child: (bounds, ref, count), count 0 = interior node `ref`.
type Child = (Aabb, u32, u32);

impl Bvh4 {
    pub fn from_binary(bvh: &Bvh) -> Bvh4 {
        let children_of = |node: u32| -> Vec<Child> {
            let n: &BvhNode = &bvh.nodes[node as usize];
            (0..2)
                .filter(|&c| !n.is_empty_child(c))
                .map(|c| (n.child_bounds(c), n.child_ref[c], n.child_count[c]))
                .collect()
        };
        let mut nodes = vec![Bvh4Node::EMPTY];
        // (wide node to fill, binary node whose children it takes)
        let mut work = vec![(0usize, 0u32)];
        while let Some((wide, binary)) = work.pop() {
            let mut children = children_of(binary);
            while children.len() < WIDTH {
                let widest = children
                    .iter()
                    .enumerate()
                    .filter(|(_, c)| c.2 == 0)
                    .max_by(|a, b| a.1 .0.surface_area().total_cmp(&b.1 .0.surface_area()))
                    .map(|(i, _)| i);
                let Some(i) = widest else { break };
                let (_, node, _) = children.swap_remove(i);
                children.extend(children_of(node));
            }
            for (slot, &(bounds, child_ref, count)) in children.iter().enumerate() {
                nodes[wide].set_child(slot, &bounds, child_ref, count);
                if count == 0 {
                    let child = nodes.len();
                    nodes.push(Bvh4Node::EMPTY);
                    nodes[wide].child_ref[slot] = child as u32;
                    work.push((child, child_ref));
                }
            }
        }
        Bvh4 {
            nodes,
            tri_order: bvh.tri_order.clone(),
        }
    }

    /// Longest root-to-leaf path in nodes (the root alone is depth 1).
    pub fn depth(&self) -> u32 {
        let mut deepest = 0;
        let mut stack = vec![(0u32, 1u32)];
        while let Some((node, depth)) = stack.pop() {
            deepest = deepest.max(depth);
            let n = &self.nodes[node as usize];
            for slot in (0..WIDTH).filter(|&s| n.child_count[s] == 0 && !n.is_empty_child(s)) {
                stack.push((n.child_ref[slot], depth + 1));
            }
        }
        deepest
    }

    /// Most entries the traversal stack can ever hold: at a node with k interior children the
    /// k − 1 not visited first are pushed, so the worst path sums k − 1 over its nodes (whichever
    /// child a ray visits first).
    pub fn max_stack(&self) -> u32 {
        let mut most = 0;
        let mut stack = vec![(0u32, 0u32)];
        while let Some((node, entries)) = stack.pop() {
            let n = &self.nodes[node as usize];
            let inner: Vec<u32> = (0..WIDTH)
                .filter(|&s| n.child_count[s] == 0 && !n.is_empty_child(s))
                .map(|s| n.child_ref[s])
                .collect();
            let below = entries + (inner.len() as u32).saturating_sub(1);
            most = most.max(if inner.is_empty() { entries } else { below });
            stack.extend(inner.iter().map(|&c| (c, below)));
        }
        most
    }

    /// 8 texels per node, see the module doc.
    pub fn node_texels(&self) -> Vec<[f32; 4]> {
        let bits = f32::from_bits;
        self.nodes
            .iter()
            .flat_map(|n| {
                let (lo, hi) = (&n.child_min, &n.child_max);
                [
                    lo.map(|v| v.x),
                    lo.map(|v| v.y),
                    lo.map(|v| v.z),
                    hi.map(|v| v.x),
                    hi.map(|v| v.y),
                    hi.map(|v| v.z),
                    n.child_ref.map(bits),
                    n.child_count.map(bits),
                ]
            })
            .collect()
    }

    /// 128 bytes per node plus 48 per leaf reference (the texel buffers).
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * 128 + self.tri_order.len() * 48
    }

    /// The GPU traversal's algorithm on the CPU: closest hit (ties as in [`crate::intersect`])
    /// or, with `any_hit`, the first hit found, for `0 < t < t_max`.
    pub fn intersect(
        &self,
        tris: &[[Vec3; 3]],
        ray: &Ray,
        t_max: f32,
        any_hit: bool,
    ) -> Option<Hit> {
        let mut state = TraceState::default();
        self.intersect_into(tris, ray, t_max, any_hit, 0, &mut state)
            .or(state.best)
    }

    /// [`Bvh4::intersect`] continuing from `state.best` (boxes beyond it are skipped, closer hits
    /// replace it), hit ids offset by `id_base` (an instance's BLAS), nodes and triangles counted
    /// as `bvh_walk` in shaders/common/bvh.glsl counts them; returns the any-hit answer.
    pub fn intersect_into(
        &self,
        tris: &[[Vec3; 3]],
        ray: &Ray,
        t_max: f32,
        any_hit: bool,
        id_base: u32,
        state: &mut TraceState,
    ) -> Option<Hit> {
        let wray = WatertightRay::new(ray);
        let inv_dir = safe_inverse_dir(ray.dir);
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        let mut node = 0u32;
        loop {
            let n = &self.nodes[node as usize];
            state.counts.nodes += 1;
            state.counts.bytes += NODE_BYTES;
            let limit = state.best.map_or(t_max, |h| h.t);
            let near: [Option<f32>; WIDTH] = std::array::from_fn(|c| {
                if n.is_empty_child(c) {
                    None
                } else {
                    slab_test(n.child_min[c], n.child_max[c], ray.origin, inv_dir, limit)
                }
            });
            for c in (0..WIDTH).filter(|&c| near[c].is_some() && n.child_count[c] > 0) {
                let start = n.child_ref[c] as usize;
                // One at a time, so an any-hit walk counts only the triangles it tested.
                for tri in self.tri_order[start..start + n.child_count[c] as usize].chunks(1) {
                    state.counts.triangles += 1;
                    state.counts.bytes += TRIANGLE_BYTES;
                    if let Some(hit) =
                        test_leaf(tris, tri, &wray, t_max, any_hit, id_base, &mut state.best)
                    {
                        return Some(hit);
                    }
                }
            }
            // Interior children nearest first, ordered by the GLSL's comparator network (so equal
            // entry distances come out in the same order): the farther ones are pushed,
            // farthest deepest.
            let mut keyed: [(f32, u32); WIDTH] = std::array::from_fn(|c| match near[c] {
                Some(t) if n.child_count[c] == 0 => (t, n.child_ref[c]),
                _ => (1e30, n.child_ref[c]),
            });
            let inner = (0..WIDTH)
                .filter(|&c| near[c].is_some() && n.child_count[c] == 0)
                .count();
            for (a, b) in [(0, 1), (2, 3), (0, 2), (1, 3), (1, 2)] {
                if keyed[b].0 < keyed[a].0 {
                    keyed.swap(a, b);
                }
            }
            if inner == 0 {
                match stack.pop() {
                    Some(a) => node = a,
                    None => return None,
                }
            } else {
                stack.extend(keyed[1..inner].iter().rev().map(|c| c.1));
                node = keyed[0].1;
            }
        }
    }

    /// 3 texels per leaf reference in leaf order, flagged where `alpha_tested(original index)`
    /// (see [`super::compressed::Bvh8::triangle_words`], the same format).
    pub fn triangle_texels(
        &self,
        tris: &[[Vec3; 3]],
        alpha_tested: &dyn Fn(u32) -> bool,
    ) -> Vec<[f32; 4]> {
        super::traverse::triangle_texels(&self.tri_order, tris, alpha_tested)
    }
}
