//! A binary BVH built with binned SAH, laid out for GPU traversal.
//!
//! We build our own rather than use a crate (e.g. `obvhs`): the GPU node format below is fixed by
//! the GLSL traversal (measured fastest on lavapipe, see build-notes.md), the builder is ~200
//! lines, and owning it means the layout, leaf sizes and tie rules are tested here, not adapted.
//!
//! Node format: each [`BvhNode`] holds the boxes of BOTH children, so the traversal tests two
//! boxes per node fetch (64 bytes). `child_count == 0` marks an interior child (`child_ref` = node
//! index); `child_count > 0` a leaf with triangles `tri_order[child_ref .. child_ref + count]`.
//! Node 0 is the root. A scene that fits one leaf gets a root whose child 1 is empty (an inverted
//! box that every slab test misses, count 0, ref 0).
//!
//! Build: single-threaded, 16 bins on each axis, leaves of ≤ 4 triangles, ≤ 8 when no split is
//! cheaper by SAH (more than 8 forces an object-median split).

mod traverse;
#[cfg(test)]
mod tests;

use crate::Aabb;
use glam::Vec3;

/// One BVH2 node with both children's boxes (see the module doc for the meaning of the fields).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhNode {
    pub child_min: [Vec3; 2],
    pub child_max: [Vec3; 2],
    pub child_ref: [u32; 2],
    pub child_count: [u32; 2],
}

impl BvhNode {
    const EMPTY: BvhNode = BvhNode {
        child_min: [Aabb::EMPTY.min; 2],
        child_max: [Aabb::EMPTY.max; 2],
        child_ref: [0; 2],
        child_count: [0; 2],
    };

    fn set_child(&mut self, slot: usize, bounds: &Aabb, child_ref: u32, count: u32) {
        self.child_min[slot] = bounds.min;
        self.child_max[slot] = bounds.max;
        self.child_ref[slot] = child_ref;
        self.child_count[slot] = count;
    }

    /// The "no child" sentinel: count 0 and ref 0 (node 0 is the root, never anyone's child).
    /// Traversals must test this rather than rely on the inverted box alone: a slab test that
    /// orders each axis' entry/exit with min/max turns the box [+1e30, −1e30] into [−1e30, +1e30]
    /// and would enter it; only a test that picks planes by the sign of the direction misses it.
    pub fn is_empty_child(&self, slot: usize) -> bool {
        self.child_count[slot] == 0 && self.child_ref[slot] == 0
    }

    pub fn child_bounds(&self, slot: usize) -> Aabb {
        Aabb { min: self.child_min[slot], max: self.child_max[slot] }
    }
}

#[derive(Clone, Debug, Default)]
pub struct Bvh {
    pub nodes: Vec<BvhNode>,
    /// Original triangle indices in leaf order.
    pub tri_order: Vec<u32>,
}

const BINS: usize = 16;
const LEAF_TARGET: usize = 4;
const LEAF_MAX: usize = 8;
/// Cost of one node visit relative to one triangle test, in the SAH.
const TRAVERSAL_COST: f32 = 1.0;

enum Plan {
    Leaf,
    Split(usize),
}

#[derive(Clone, Copy)]
struct Bin {
    bounds: Aabb,
    count: u32,
}

struct Builder {
    prim_bounds: Vec<Aabb>,
    centroids: Vec<Vec3>,
    order: Vec<u32>,
}

impl Bvh {
    /// Builds the tree over `tris` (world-space corners, by triangle index).
    pub fn build(tris: &[[Vec3; 3]]) -> Bvh {
        let prim_bounds: Vec<Aabb> = tris.iter().map(|t| Aabb::of_points(t)).collect();
        let centroids = prim_bounds.iter().map(Aabb::center).collect();
        let mut b = Builder { prim_bounds, centroids, order: (0..tris.len() as u32).collect() };
        let n = tris.len();
        let mut nodes = vec![BvhNode::EMPTY];
        let (root_bounds, root_centroids) = b.range_bounds(0, n);
        let (left, right) = match b.plan(0, n, &root_bounds, &root_centroids) {
            Plan::Leaf => {
                if n > 0 {
                    nodes[0].set_child(0, &root_bounds, 0, n as u32);
                }
                return Bvh { nodes, tri_order: b.order };
            }
            Plan::Split(mid) => ((0, mid), (mid, n)),
        };
        // Explicit work list instead of recursion: degenerate inputs can make deep trees.
        let mut work = vec![(0usize, left, right)];
        while let Some((node, left, right)) = work.pop() {
            for (slot, (start, end)) in [(0, left), (1, right)] {
                let (bounds, centroid_bounds) = b.range_bounds(start, end);
                match b.plan(start, end, &bounds, &centroid_bounds) {
                    Plan::Leaf => nodes[node].set_child(slot, &bounds, start as u32, (end - start) as u32),
                    Plan::Split(mid) => {
                        let child = nodes.len();
                        nodes.push(BvhNode::EMPTY);
                        nodes[node].set_child(slot, &bounds, child as u32, 0);
                        work.push((child, (start, mid), (mid, end)));
                    }
                }
            }
        }
        Bvh { nodes, tri_order: b.order }
    }

    /// Longest root-to-leaf path counted in nodes (the root alone is depth 1). The GPU traversal
    /// stack never holds more than `depth()` entries.
    pub fn depth(&self) -> u32 {
        let mut deepest = 0;
        let mut stack = vec![(0u32, 1u32)];
        while let Some((node, depth)) = stack.pop() {
            deepest = deepest.max(depth);
            let n = &self.nodes[node as usize];
            for slot in 0..2 {
                if n.child_count[slot] == 0 && !n.is_empty_child(slot) {
                    stack.push((n.child_ref[slot], depth + 1));
                }
            }
        }
        deepest
    }

    /// Bytes the GPU holds for this BVH: 64 per node plus 48 per triangle (the texel buffers).
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * 64 + self.tri_order.len() * 48
    }
}

impl Builder {
    fn range_bounds(&self, start: usize, end: usize) -> (Aabb, Aabb) {
        let (mut bounds, mut centroid_bounds) = (Aabb::EMPTY, Aabb::EMPTY);
        for &p in &self.order[start..end] {
            bounds = bounds.union(&self.prim_bounds[p as usize]);
            centroid_bounds.grow(self.centroids[p as usize]);
        }
        (bounds, centroid_bounds)
    }

    /// Decides leaf or split for `order[start..end]`, partitioning the range for a split.
    fn plan(&mut self, start: usize, end: usize, bounds: &Aabb, centroid_bounds: &Aabb) -> Plan {
        let count = end - start;
        if count <= LEAF_TARGET {
            return Plan::Leaf;
        }
        let extent = centroid_bounds.max - centroid_bounds.min;
        let parent_area = bounds.surface_area().max(f32::MIN_POSITIVE);
        let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, first bin on the right)
        for axis in 0..3 {
            if extent[axis] <= 0.0 {
                continue;
            }
            let bins = self.fill_bins(start, end, axis, centroid_bounds.min[axis], extent[axis]);
            // Right-to-left sweep for the right side's area·count, then left-to-right for the cost.
            let mut right_cost = [0.0f32; BINS];
            let (mut acc, mut n) = (Aabb::EMPTY, 0u32);
            for i in (1..BINS).rev() {
                acc = acc.union(&bins[i].bounds);
                n += bins[i].count;
                right_cost[i] = acc.surface_area() * n as f32;
            }
            let (mut acc, mut n) = (Aabb::EMPTY, 0u32);
            for split in 1..BINS {
                acc = acc.union(&bins[split - 1].bounds);
                n += bins[split - 1].count;
                if n == 0 || n as usize == count {
                    continue;
                }
                let cost = TRAVERSAL_COST + (acc.surface_area() * n as f32 + right_cost[split]) / parent_area;
                if best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, axis, split));
                }
            }
        }
        let leaf_cost = count as f32;
        match best {
            Some((cost, _, _)) if cost >= leaf_cost && count <= LEAF_MAX => Plan::Leaf,
            None if count <= LEAF_MAX => Plan::Leaf,
            Some((_, axis, split)) => {
                let (lo, scale) = (centroid_bounds.min[axis], BINS as f32 / extent[axis]);
                let centroids = &self.centroids;
                let mid = start + partition(&mut self.order[start..end], |p| bin_of(centroids[p as usize][axis], lo, scale) < split);
                if mid == start || mid == end { self.median_split(start, end, centroid_bounds) } else { Plan::Split(mid) }
            }
            None => self.median_split(start, end, centroid_bounds),
        }
    }

    fn fill_bins(&self, start: usize, end: usize, axis: usize, lo: f32, extent: f32) -> [Bin; BINS] {
        let mut bins = [Bin { bounds: Aabb::EMPTY, count: 0 }; BINS];
        let scale = BINS as f32 / extent;
        for &p in &self.order[start..end] {
            let bin = &mut bins[bin_of(self.centroids[p as usize][axis], lo, scale)];
            bin.bounds = bin.bounds.union(&self.prim_bounds[p as usize]);
            bin.count += 1;
        }
        bins
    }

    /// Fallback when SAH finds no useful split of a range too big for one leaf: halve it along the
    /// widest centroid axis (by index when all centroids coincide).
    fn median_split(&mut self, start: usize, end: usize, centroid_bounds: &Aabb) -> Plan {
        let extent = centroid_bounds.max - centroid_bounds.min;
        let axis = if extent.x >= extent.y && extent.x >= extent.z { 0 } else if extent.y >= extent.z { 1 } else { 2 };
        let mid = (end - start) / 2;
        if extent[axis] > 0.0 {
            let centroids = &self.centroids;
            self.order[start..end].select_nth_unstable_by(mid, |&a, &b| {
                centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
            });
        }
        Plan::Split(start + mid)
    }
}

#[inline]
fn bin_of(c: f32, lo: f32, scale: f32) -> usize {
    (((c - lo) * scale) as usize).min(BINS - 1)
}

/// In-place partition; returns how many elements satisfy `left` (they come first).
fn partition(items: &mut [u32], left: impl Fn(u32) -> bool) -> usize {
    let mut first_right = 0;
    for i in 0..items.len() {
        if left(items[i]) {
            items.swap(i, first_right);
            first_right += 1;
        }
    }
    first_right
}
