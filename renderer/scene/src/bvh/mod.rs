//! A binary BVH built with binned SAH (optionally with spatial splits), collapsed to 4-wide nodes
//! for GPU traversal ([`wide`]).
//!
//! We build our own rather than use a crate (e.g. `obvhs`): the GPU node format is fixed by the
//! GLSL traversal (measured fastest on lavapipe, see build-notes.md), the builders are a few
//! hundred lines, and owning them means the layout, leaf sizes and tie rules are tested here.
//!
//! Binary node format: each [`BvhNode`] holds the boxes of BOTH children (64 bytes).
//! `child_count == 0` marks an interior child (`child_ref` = node index); `child_count > 0` a leaf
//! with triangles `tri_order[child_ref .. child_ref + count]`. Node 0 is the root. A scene that
//! fits one leaf gets a root whose child 1 is empty (an inverted box that every slab test misses,
//! count 0, ref 0). The GPU gets [`wide::Bvh4`], collapsed from this tree with the same leaves;
//! [`Bvh::intersect`] and [`wide::Bvh4::intersect`] are the CPU references.
//!
//! Builders ([`BvhBuilder`]): single-threaded, 16 bins on each axis, leaves of ≤ 4 triangles, ≤ 8
//! when no split is cheaper by SAH (more than 8 forces an object-median split).
//! - `binned`: object splits only; every triangle in exactly one leaf (≈ 1–2.6 M triangles/s).
//! - `sbvh` ([`sbvh`], Stich et al. 2009): object or spatial splits, at most `budget` × triangles
//!   extra leaf references; a triangle may sit in several leaves, each leaf box bounding only its
//!   clipped part. About 6–8× slower to build (Sponza: 1.18 s vs 0.19 s) for a tree of 18 % lower
//!   SAH cost on Sponza and 19 % on the Breakfast Room, +21 / +18 % references, and 1.5–1.6× their
//!   primary-ray rate (`fovea bench --bvh sbvh,binned`, docs/performance.md). The default.
//!
//! [`Bvh::stats`] reports what a tree looks like (depth, leaf sizes, SAH cost, child overlap,
//! long thin and large triangles); `fovea bench` prints it for each scene and builder.
//!
//! Two GPU layouts are made from the binary tree, one per traversal: [`wide::Bvh4`] (the
//! traversal shaped for CPU drivers such as lavapipe) and [`compressed::Bvh8`] (the one shaped for
//! GPUs: compressed 8-wide nodes).

pub mod compressed;
pub mod instanced;
mod sbvh;
#[cfg(test)]
mod tests;
mod traverse;
pub mod wide;

use crate::intersect::Hit;
use crate::Aabb;
use glam::{Vec3, Vec3A};

/// What a traversal read: nodes opened, leaf triangles tested and the bytes of node and triangle
/// data fetched for them (the CPU references count what the GPU kernels count).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraversalCounts {
    pub nodes: u64,
    pub triangles: u64,
    pub bytes: u64,
}

/// What a traversal carries from tree to tree (the world tree, then instances): the closest hit
/// so far and the counts.
#[derive(Clone, Copy, Debug, Default)]
pub struct TraceState {
    pub best: Option<Hit>,
    pub counts: TraversalCounts,
}

/// One BVH node with the boxes of all its `W` children, so a traversal tests them per node fetch
/// (see the module doc for the meaning of the fields): [`BvhNode`] (binary, what the builders
/// make) and [`wide::Bvh4Node`] (what the GPU traverses).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeOf<const W: usize> {
    pub child_min: [Vec3; W],
    pub child_max: [Vec3; W],
    /// Interior child: its node index; leaf: first entry in `tri_order`.
    pub child_ref: [u32; W],
    /// 0: interior child (or empty when `child_ref` is 0 too); > 0: leaf of that many triangles.
    pub child_count: [u32; W],
}

/// One BVH2 node with both children's boxes.
pub type BvhNode = NodeOf<2>;

impl<const W: usize> NodeOf<W> {
    const EMPTY: NodeOf<W> = NodeOf {
        child_min: [Aabb::EMPTY.min; W],
        child_max: [Aabb::EMPTY.max; W],
        child_ref: [0; W],
        child_count: [0; W],
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
        Aabb {
            min: self.child_min[slot],
            max: self.child_max[slot],
        }
    }
}

#[derive(Clone, Debug, Default)]
pub struct Bvh {
    pub nodes: Vec<BvhNode>,
    /// Original triangle indices in leaf order.
    pub tri_order: Vec<u32>,
}

const BINS: usize = 16;
const LEAF_MAX: usize = 8;

/// Builder-internal box on SIMD vectors (the build is bound by these unions).
#[derive(Clone, Copy)]
struct Box3 {
    min: Vec3A,
    max: Vec3A,
}

impl Box3 {
    const EMPTY: Box3 = Box3 {
        min: Vec3A::splat(1e30),
        max: Vec3A::splat(-1e30),
    };
    #[inline]
    fn union(self, o: Box3) -> Box3 {
        Box3 {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }
    #[inline]
    fn grow(self, p: Vec3A) -> Box3 {
        Box3 {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }
    #[inline]
    fn half_area(self) -> f32 {
        let d = (self.max - self.min).max(Vec3A::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }
    fn to_aabb(self) -> Aabb {
        Aabb {
            min: self.min.into(),
            max: self.max.into(),
        }
    }
}

/// A range's triangle bounds and centroid bounds.
#[derive(Clone, Copy)]
struct RangeBounds {
    bounds: Box3,
    centroids: Box3,
}

impl RangeBounds {
    const EMPTY: RangeBounds = RangeBounds {
        bounds: Box3::EMPTY,
        centroids: Box3::EMPTY,
    };
    fn union(self, o: RangeBounds) -> RangeBounds {
        RangeBounds {
            bounds: self.bounds.union(o.bounds),
            centroids: self.centroids.union(o.centroids),
        }
    }
}

enum Plan {
    Leaf,
    /// Partition point plus both halves' bounds (from the bins, so no second pass is needed).
    Split(usize, RangeBounds, RangeBounds),
}

#[derive(Clone, Copy)]
struct Bin {
    range: RangeBounds,
    count: u32,
}

struct Builder {
    options: BvhBuilder,
    prim_bounds: Vec<Box3>,
    centroids: Vec<Vec3A>,
    order: Vec<u32>,
}

/// Which builder makes the tree, and its knobs (`fovea bench --bvh` compares them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhBuilder {
    /// `None`: object splits only (binned SAH), every triangle in exactly one leaf. `Some(b)`:
    /// object and spatial splits (SBVH), at most `b` × triangles extra leaf references.
    pub spatial_budget: Option<f32>,
    /// Ranges of at most this many triangles become leaves (larger ones up to 8 when no split is
    /// cheaper by SAH; the SBVH splits small ranges too where an object split costs less than
    /// three quarters of the leaf).
    pub leaf_target: usize,
    /// Cost of one node visit relative to one triangle test, in the SAH.
    pub node_cost: f32,
}

impl BvhBuilder {
    pub const BINNED: BvhBuilder = BvhBuilder {
        spatial_budget: None,
        leaf_target: 4,
        node_cost: 1.0,
    };
    pub const SBVH: BvhBuilder = BvhBuilder {
        spatial_budget: Some(0.5),
        ..BvhBuilder::BINNED
    };
    /// What [`Bvh::build`] (and so every scene upload) uses.
    pub const DEFAULT: BvhBuilder = BvhBuilder::SBVH;

    /// `binned` or `sbvh[:BUDGET]` (budget 0.5 when not given), optionally followed by
    /// `/leafN` (leaf target, 1 to 8) and `/costC` (node cost, 0.1 to 10).
    pub fn parse(s: &str) -> Result<BvhBuilder, String> {
        let err = || {
            format!("unknown BVH builder '{s}': binned or sbvh[:BUDGET] (0 to 4), then optionally /leafN (1 to 8), /costC (0.1 to 10)")
        };
        let mut parts = s.split('/');
        let mut b = match parts.next().unwrap_or("") {
            "binned" => BvhBuilder::BINNED,
            "sbvh" => BvhBuilder::SBVH,
            kind => match kind.strip_prefix("sbvh:").map(str::parse::<f32>) {
                Some(Ok(budget)) if (0.0..=4.0).contains(&budget) => BvhBuilder {
                    spatial_budget: Some(budget),
                    ..BvhBuilder::BINNED
                },
                _ => return Err(err()),
            },
        };
        for part in parts {
            if let Some(Ok(n)) = part.strip_prefix("leaf").map(str::parse::<usize>) {
                b.leaf_target = n;
            } else if let Some(Ok(c)) = part.strip_prefix("cost").map(str::parse::<f32>) {
                b.node_cost = c;
            } else {
                return Err(err());
            }
        }
        if !(1..=LEAF_MAX).contains(&b.leaf_target) || !(0.1..=10.0).contains(&b.node_cost) {
            return Err(err());
        }
        Ok(b)
    }

    pub fn name(&self) -> String {
        let mut name = match self.spatial_budget {
            None => "binned".to_string(),
            Some(budget) => format!("sbvh:{budget}"),
        };
        if self.leaf_target != BvhBuilder::BINNED.leaf_target {
            name += &format!("/leaf{}", self.leaf_target);
        }
        if self.node_cost != BvhBuilder::BINNED.node_cost {
            name += &format!("/cost{}", self.node_cost);
        }
        name
    }
}

impl Bvh {
    /// Builds the tree over `tris` (world-space corners, by triangle index) with
    /// [`BvhBuilder::DEFAULT`].
    pub fn build(tris: &[[Vec3; 3]]) -> Bvh {
        Bvh::build_with(tris, BvhBuilder::DEFAULT)
    }

    pub fn build_with(tris: &[[Vec3; 3]], builder: BvhBuilder) -> Bvh {
        match builder.spatial_budget {
            None => Bvh::build_binned(tris, builder),
            Some(budget) => sbvh::build(tris, budget, builder),
        }
    }

    fn build_binned(tris: &[[Vec3; 3]], options: BvhBuilder) -> Bvh {
        let prim_bounds: Vec<Box3> = tris
            .iter()
            .map(|t| t.iter().fold(Box3::EMPTY, |b, &p| b.grow(p.into())))
            .collect();
        let centroids = prim_bounds.iter().map(|b| (b.min + b.max) * 0.5).collect();
        let mut b = Builder {
            prim_bounds,
            centroids,
            order: (0..tris.len() as u32).collect(),
            options,
        };
        let n = tris.len();
        let mut nodes = vec![BvhNode::EMPTY];
        let root = b.range_bounds(0, n);
        let (mid, left, right) = match b.plan(0, n, root) {
            Plan::Leaf => {
                if n > 0 {
                    nodes[0].set_child(0, &root.bounds.to_aabb(), 0, n as u32);
                }
                return Bvh {
                    nodes,
                    tri_order: b.order,
                };
            }
            Plan::Split(mid, left, right) => (mid, left, right),
        };
        // Explicit work list instead of recursion: degenerate inputs can make deep trees.
        let mut work = vec![(0usize, (0, mid, left), (mid, n, right))];
        while let Some((node, left, right)) = work.pop() {
            for (slot, (start, end, range)) in [(0, left), (1, right)] {
                let bounds = range.bounds.to_aabb();
                match b.plan(start, end, range) {
                    Plan::Leaf => {
                        nodes[node].set_child(slot, &bounds, start as u32, (end - start) as u32)
                    }
                    Plan::Split(mid, l, r) => {
                        let child = nodes.len();
                        nodes.push(BvhNode::EMPTY);
                        nodes[node].set_child(slot, &bounds, child as u32, 0);
                        work.push((child, (start, mid, l), (mid, end, r)));
                    }
                }
            }
        }
        Bvh {
            nodes,
            tri_order: b.order,
        }
    }

    /// Longest root-to-leaf path counted in nodes (the root alone is depth 1). The binary
    /// traversal's stack never holds more than `depth()` entries (the GPU's: [`wide::Bvh4::max_stack`]).
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

    /// Bytes of this binary tree at 64 per node plus 48 per leaf reference; the GPU holds the
    /// 4-wide tree instead ([`wide::Bvh4::memory_bytes`]).
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * 64 + self.tri_order.len() * 48
    }
}

/// What a tree looks like, for `fovea bench` and for tuning the builder (see [`Bvh::stats`]).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct BvhStats {
    pub nodes: usize,
    pub leaves: usize,
    /// Leaf references (`tri_order.len()`): the triangle count plus any duplicates.
    pub references: usize,
    pub depth: u32,
    /// Mean depth of the leaves weighted by their triangles (a ray's path length to a leaf).
    pub mean_leaf_depth: f64,
    pub mean_leaf_size: f64,
    /// Leaves by triangle count: `leaf_sizes[k]` leaves hold `k` triangles (index 0 unused).
    pub leaf_sizes: Vec<usize>,
    /// SAH cost of the tree relative to the root box (node visit 1, triangle test 1): the expected
    /// number of node and triangle tests of a ray that crosses the root box, uniformly.
    pub sah_cost: f64,
    /// The node part of `sah_cost` (box tests: both children of a visited node count once).
    pub sah_node_cost: f64,
    /// Mean over interior nodes of area(left ∩ right) / area(parent): 0 for disjoint children.
    pub mean_child_overlap: f64,
    /// Triangles whose box is more than 10× as long as the triangle is wide (long thin ones) ...
    pub thin_triangles: usize,
    /// ... and triangles whose box has more than 1/100 of the scene box's surface area.
    pub large_triangles: usize,
}

impl Bvh {
    /// Counts and costs of the tree over `tris` (the array it was built from).
    pub fn stats(&self, tris: &[[Vec3; 3]]) -> BvhStats {
        let mut s = BvhStats {
            nodes: self.nodes.len(),
            references: self.tri_order.len(),
            ..Default::default()
        };
        let area = |b: &Aabb| b.surface_area() as f64;
        let root = (0..2)
            .filter(|&c| !self.nodes[0].is_empty_child(c))
            .fold(Aabb::EMPTY, |b, c| b.union(&self.nodes[0].child_bounds(c)));
        let root_area = area(&root).max(f64::MIN_POSITIVE);
        let (mut overlap_sum, mut interior, mut leaf_depth_sum) = (0.0, 0usize, 0.0);
        // (node, depth, area of the node's own box)
        let mut stack = vec![(0u32, 1u32, root_area)];
        while let Some((node, depth, node_area)) = stack.pop() {
            s.depth = s.depth.max(depth);
            s.sah_node_cost += node_area / root_area;
            let n = &self.nodes[node as usize];
            interior += 1;
            if !n.is_empty_child(0) && !n.is_empty_child(1) {
                let (a, b) = (n.child_bounds(0), n.child_bounds(1));
                let inter = Aabb {
                    min: a.min.max(b.min),
                    max: a.max.min(b.max),
                };
                overlap_sum += area(&inter) / node_area.max(f64::MIN_POSITIVE);
            }
            for c in (0..2).filter(|&c| !n.is_empty_child(c)) {
                let b = n.child_bounds(c);
                let count = n.child_count[c] as usize;
                if count == 0 {
                    stack.push((n.child_ref[c], depth + 1, area(&b)));
                } else {
                    s.leaves += 1;
                    if s.leaf_sizes.len() <= count {
                        s.leaf_sizes.resize(count + 1, 0);
                    }
                    s.leaf_sizes[count] += 1;
                    s.sah_cost += area(&b) / root_area * count as f64;
                    leaf_depth_sum += (depth + 1) as f64 * count as f64;
                }
            }
        }
        s.sah_cost += s.sah_node_cost;
        s.mean_child_overlap = overlap_sum / interior.max(1) as f64;
        s.mean_leaf_size = s.references as f64 / s.leaves.max(1) as f64;
        s.mean_leaf_depth = leaf_depth_sum / s.references.max(1) as f64;
        let scene_area = area(&Aabb::of_points(
            &tris.iter().flatten().copied().collect::<Vec<_>>(),
        ));
        for t in tris {
            let b = Aabb::of_points(t);
            let d = b.max - b.min;
            let (longest, [e0, e1, e2]) =
                (d.max_element(), [t[1] - t[0], t[2] - t[1], t[0] - t[2]]);
            // Width: twice the area over the longest edge (the triangle's height on it).
            let edge = e0.length().max(e1.length()).max(e2.length());
            let width = e0.cross(-e2).length() / edge.max(f32::MIN_POSITIVE);
            if longest > 10.0 * width {
                s.thin_triangles += 1;
            }
            if area(&b) > scene_area / 100.0 {
                s.large_triangles += 1;
            }
        }
        s
    }
}

impl Builder {
    fn range_bounds(&self, start: usize, end: usize) -> RangeBounds {
        self.order[start..end]
            .iter()
            .fold(RangeBounds::EMPTY, |r, &p| RangeBounds {
                bounds: r.bounds.union(self.prim_bounds[p as usize]),
                centroids: r.centroids.grow(self.centroids[p as usize]),
            })
    }

    /// Decides leaf or split for `order[start..end]`, partitioning the range for a split.
    fn plan(&mut self, start: usize, end: usize, range: RangeBounds) -> Plan {
        let count = end - start;
        if count <= self.options.leaf_target {
            return Plan::Leaf;
        }
        let lo = range.centroids.min;
        let extent = range.centroids.max - lo;
        // Bin all three axes in one pass over the triangles (one centroid load for three bins).
        let scale = Vec3A::select(
            extent.cmpgt(Vec3A::ZERO),
            Vec3A::splat(BINS as f32) / extent,
            Vec3A::ZERO,
        );
        let mut bins = [[Bin {
            range: RangeBounds::EMPTY,
            count: 0,
        }; BINS]; 3];
        for &p in &self.order[start..end] {
            let (c, pb) = (self.centroids[p as usize], self.prim_bounds[p as usize]);
            let k = bin_index(c, lo, scale);
            for axis in 0..3 {
                let bin = &mut bins[axis][k[axis]];
                bin.range.bounds = bin.range.bounds.union(pb);
                bin.range.centroids = bin.range.centroids.grow(c);
                bin.count += 1;
            }
        }
        let parent_area = range.bounds.half_area().max(f32::MIN_POSITIVE);
        let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, first bin on the right)
        for axis in (0..3).filter(|&a| extent[a] > 0.0) {
            let bins = &bins[axis];
            // Right-to-left sweep for the right side's area·count, then left-to-right for the cost.
            let mut right_cost = [0.0f32; BINS];
            let (mut acc, mut n) = (Box3::EMPTY, 0u32);
            for i in (1..BINS).rev() {
                acc = acc.union(bins[i].range.bounds);
                n += bins[i].count;
                right_cost[i] = acc.half_area() * n as f32;
            }
            let (mut acc, mut n) = (Box3::EMPTY, 0u32);
            for split in 1..BINS {
                acc = acc.union(bins[split - 1].range.bounds);
                n += bins[split - 1].count;
                if n == 0 || n as usize == count {
                    continue;
                }
                let cost = self.options.node_cost
                    + (acc.half_area() * n as f32 + right_cost[split]) / parent_area;
                if best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, axis, split));
                }
            }
        }
        match best {
            Some((cost, _, _)) if cost >= count as f32 && count <= LEAF_MAX => Plan::Leaf,
            None if count <= LEAF_MAX => Plan::Leaf,
            Some((_, axis, split)) => {
                let (lo, scale) = (lo[axis], scale[axis]);
                let centroids = &self.centroids;
                let mid = start
                    + partition(&mut self.order[start..end], |p| {
                        bin_of(centroids[p as usize][axis], lo, scale) < split
                    });
                let union = |bins: &[Bin]| {
                    bins.iter()
                        .fold(RangeBounds::EMPTY, |r, b| r.union(b.range))
                };
                if mid == start || mid == end {
                    self.median_split(start, end, range)
                } else {
                    Plan::Split(
                        mid,
                        union(&bins[axis][..split]),
                        union(&bins[axis][split..]),
                    )
                }
            }
            None => self.median_split(start, end, range),
        }
    }

    /// Fallback when SAH finds no useful split of a range too big for one leaf: halve it along the
    /// widest centroid axis (by index when all centroids coincide).
    fn median_split(&mut self, start: usize, end: usize, range: RangeBounds) -> Plan {
        let extent = range.centroids.max - range.centroids.min;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        let mid = (end - start) / 2;
        if extent[axis] > 0.0 {
            let centroids = &self.centroids;
            self.order[start..end].select_nth_unstable_by(mid, |&a, &b| {
                centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
            });
        }
        let mid = start + mid;
        Plan::Split(
            mid,
            self.range_bounds(start, mid),
            self.range_bounds(mid, end),
        )
    }
}

#[inline]
fn bin_index(c: Vec3A, lo: Vec3A, scale: Vec3A) -> [usize; 3] {
    let k = ((c - lo) * scale).min(Vec3A::splat((BINS - 1) as f32));
    [k.x as usize, k.y as usize, k.z as usize]
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
