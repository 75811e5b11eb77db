//! Spatial splits (SBVH; Stich, Friedrich, Dietrich, "Spatial Splits in Bounding Volume
//! Hierarchies", HPG 2009) for the same node format as the object-split builder.
//!
//! Each node weighs the best binned object split (16 bins on the centroids of its references)
//! against the best spatial split (16 equal slabs of the node box on each axis; a reference
//! spanning several slabs is clipped to each, its triangle cut by the slab planes, "chopped
//! binning"). Spatial splits are only tried where the object split's children overlap by more than
//! `ALPHA` of the root's area, and only while the references stay within the memory budget
//! (`budget` × triangles extra). A straddling reference is split in two or, when that is cheaper
//! by SAH, kept whole on one side ("reference unsplitting"). A triangle may then sit in several
//! leaves; each leaf box holds the part of the triangle inside it (clipped in f64, rounded
//! outwards), so every point of every triangle lies in some leaf box on its root path.

use super::{Box3, Bvh, BvhBuilder, BvhNode, BINS, LEAF_MAX};
use glam::{Vec3, Vec3A};

/// Spatial splits are tried where λ(object split) / area(root) exceeds this (the paper's α).
/// Measured on Sponza / the Breakfast Room (SAH cost, build s, references): the paper's 1e-5 gave
/// 64.7 / 27.4, 4.5 / 3.6 s, +30 / +50 %; 1e-4 gives 64.8 / 26.4 in half the time with +21 / +18 %;
/// 1e-3 66.5 / 29.9; 1e-2 67.7 / 32.8 (binned: 79.3 / 32.5).
const ALPHA: f32 = 1e-4;

/// A triangle is a sliver to cut before the build when its box's half area exceeds this many
/// times its area, into at most [`SLIVER_PARTS`] references, using at most
/// [`SLIVER_BUDGET_SHARE`] of the reference budget. Spatial splits are only tried where children
/// overlap by `ALPHA` of the root's area, which small objects in a large room never reach: the
/// Breakfast Room's chair legs (96k of its 263k triangles, their boxes 155× their area on
/// average) took 4.7 of the 8.9 triangle tests of a primary ray while 2.7 % of the rays hit them.
/// Measured with primary rays of the scene's camera at 160×180 (compressed tree, triangles tested
/// / bytes per ray): 8.9 / 962 without; with 8 parts and a quarter of the budget 6.1 / 834, half
/// 5.0 / 770, all 4.7 / 755; 16 parts deepen `large`'s tree from 11 to 20 compressed levels (its
/// stack bound past the GPU traversal's 128), and more than a quarter of the budget loses to
/// spatial splits on a floor of slivers (`spatial_splits_lower_the_sah_cost_of_slivers`). Sponza
/// and `large` change by less than 0.1 triangle per ray.
const SLIVER_RATIO: f32 = 64.0;
const SLIVER_PARTS: usize = 8;
const SLIVER_BUDGET_SHARE: f32 = 0.25;

/// Ranges of at most `leaf_target` references still split when the best object split costs
/// less than this share of testing them all (SAH, node cost included): the room's walls and
/// ceiling, a few huge triangles, would otherwise share one leaf whose box every ray inside the
/// room enters.
const SMALL_SPLIT_GAIN: f32 = 0.75;

#[derive(Clone, Copy)]
struct Ref {
    prim: u32,
    bounds: Box3,
}

#[derive(Clone, Copy)]
struct Bin {
    bounds: Box3,
    /// References that start here (object bins: the references binned here).
    enter: u32,
    /// References that end here (object bins: the same as `enter`).
    exit: u32,
}

const EMPTY_BIN: Bin = Bin {
    bounds: Box3::EMPTY,
    enter: 0,
    exit: 0,
};

struct Candidate {
    cost: f32,
    axis: usize,
    /// First bin on the right.
    split: usize,
    left: Box3,
    right: Box3,
    /// Spatial candidates: estimated counts per side (straddlers on both).
    counts: (u32, u32),
}

enum Plan {
    Leaf(Vec<Ref>),
    Split(Vec<Ref>, Box3, Vec<Ref>, Box3),
}

struct Builder<'a> {
    options: BvhBuilder,
    tris: &'a [[Vec3; 3]],
    root_area: f32,
    /// References beyond one per triangle that may still be made.
    spare_refs: usize,
    order: Vec<u32>,
}

/// Builds the tree over `tris`, allowing up to `budget × tris.len()` extra references.
pub(super) fn build(tris: &[[Vec3; 3]], budget: f32, options: BvhBuilder) -> Bvh {
    let mut refs: Vec<Ref> = tris
        .iter()
        .enumerate()
        .map(|(i, t)| Ref {
            prim: i as u32,
            bounds: t.iter().fold(Box3::EMPTY, |b, &p| b.grow(p.into())),
        })
        .collect();
    let root = bounds_of(&refs);
    let mut spare_refs = (tris.len() as f64 * budget.max(0.0) as f64) as usize;
    split_slivers(tris, &mut refs, &mut spare_refs);
    let mut b = Builder {
        options,
        tris,
        root_area: root.half_area().max(f32::MIN_POSITIVE),
        spare_refs,
        order: Vec::with_capacity(tris.len()),
    };
    let mut nodes = vec![BvhNode::EMPTY];
    let (left, lb, right, rb) = match b.plan(refs, root) {
        Plan::Leaf(refs) => {
            if !refs.is_empty() {
                nodes[0].set_child(0, &root.to_aabb(), 0, refs.len() as u32);
            }
            b.order.extend(refs.iter().map(|r| r.prim));
            return Bvh {
                nodes,
                tri_order: b.order,
            };
        }
        Plan::Split(l, lb, r, rb) => (l, lb, r, rb),
    };
    // Explicit work list (node, slot, references, their bounds); left children first in memory.
    let mut work = vec![(0usize, 1usize, right, rb), (0usize, 0usize, left, lb)];
    while let Some((node, slot, refs, bounds)) = work.pop() {
        match b.plan(refs, bounds) {
            Plan::Leaf(refs) => {
                let start = b.order.len();
                b.order.extend(refs.iter().map(|r| r.prim));
                nodes[node].set_child(slot, &bounds.to_aabb(), start as u32, refs.len() as u32);
            }
            Plan::Split(l, lb, r, rb) => {
                let child = nodes.len();
                nodes.push(BvhNode::EMPTY);
                nodes[node].set_child(slot, &bounds.to_aabb(), child as u32, 0);
                work.push((child, 1, r, rb));
                work.push((child, 0, l, lb));
            }
        }
    }
    Bvh {
        nodes,
        tri_order: b.order,
    }
}

/// Early split clipping of slivers (Ernst and Greiner, "Early Split Clipping for Bounding Volume
/// Hierarchies", 2007), before the build: a triangle whose box's half area exceeds
/// [`SLIVER_RATIO`] times its own area is cut at the middle of its box's longest axis, each part's
/// box clipped to the triangle, again while a part's box stays that much larger than its share of
/// the triangle, into at most [`SLIVER_PARTS`] references. The worst slivers go first while their
/// share of the budget ([`SLIVER_BUDGET_SHARE`]) lasts; the rest serves the spatial splits.
fn split_slivers(tris: &[[Vec3; 3]], refs: &mut Vec<Ref>, spare_refs: &mut usize) {
    let granted = (*spare_refs as f32 * SLIVER_BUDGET_SHARE) as usize;
    let mut allowance = granted;
    // Worst slivers first, so the allowance goes where it helps most.
    let mut candidates: Vec<(f32, usize)> = refs
        .iter()
        .enumerate()
        .filter_map(|(i, r)| {
            let t = &tris[r.prim as usize];
            let a = 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
            let q = r.bounds.half_area() / a.max(f32::MIN_POSITIVE);
            (q > SLIVER_RATIO).then_some((q, i))
        })
        .collect();
    candidates.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut extra = Vec::new();
    for (_, i) in candidates {
        if allowance == 0 {
            break;
        }
        let r = refs[i];
        let t = &tris[r.prim as usize];
        let area = 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
        let full = r.bounds.max - r.bounds.min;
        let full_long = full.max_element();
        let mut parts = vec![r];
        let mut done = Vec::new();
        while let Some(p) = parts.pop() {
            let e = p.bounds.max - p.bounds.min;
            let long = e.max_element();
            let own = area * long / full_long.max(f32::MIN_POSITIVE);
            if parts.len() + done.len() + 1 >= SLIVER_PARTS
                || allowance == 0
                || p.bounds.half_area() <= SLIVER_RATIO * own
            {
                done.push(p);
                continue;
            }
            let axis = if e.x >= e.y && e.x >= e.z {
                0
            } else if e.y >= e.z {
                1
            } else {
                2
            };
            let mid = (p.bounds.min[axis] + p.bounds.max[axis]) * 0.5;
            let lo = intersect(clip_triangle(t, axis, f32::NEG_INFINITY, mid), p.bounds);
            let hi = intersect(clip_triangle(t, axis, mid, f32::INFINITY), p.bounds);
            match (is_empty(lo), is_empty(hi)) {
                (false, false) => {
                    allowance -= 1;
                    parts.push(Ref {
                        prim: p.prim,
                        bounds: lo,
                    });
                    parts.push(Ref {
                        prim: p.prim,
                        bounds: hi,
                    });
                }
                _ => done.push(p),
            }
        }
        refs[i] = done[0];
        extra.extend_from_slice(&done[1..]);
    }
    *spare_refs -= granted - allowance;
    refs.extend(extra);
}

fn bounds_of(refs: &[Ref]) -> Box3 {
    refs.iter().fold(Box3::EMPTY, |b, r| b.union(r.bounds))
}

fn centroid(r: &Ref) -> Vec3A {
    (r.bounds.min + r.bounds.max) * 0.5
}

fn intersect(a: Box3, b: Box3) -> Box3 {
    Box3 {
        min: a.min.max(b.min),
        max: a.max.min(b.max),
    }
}

fn is_empty(b: Box3) -> bool {
    b.min.cmpgt(b.max).any()
}

/// Half area of a box that may be empty (0 then).
fn area(b: Box3) -> f32 {
    if is_empty(b) {
        0.0
    } else {
        b.half_area()
    }
}

/// The box of the part of triangle `t` with `lo ≤ p[axis] ≤ hi`: its corners inside the slab and
/// its edges' crossings of the two planes, computed in f64 and rounded outwards to f32 (empty when
/// the triangle misses the slab).
pub(super) fn clip_triangle(t: &[Vec3; 3], axis: usize, lo: f32, hi: f32) -> Box3 {
    let v = t.map(|p| [p.x as f64, p.y as f64, p.z as f64]);
    let (lo64, hi64) = (lo as f64, hi as f64);
    let mut min = [f64::INFINITY; 3];
    let mut max = [f64::NEG_INFINITY; 3];
    let mut grow = |p: [f64; 3]| {
        for k in 0..3 {
            min[k] = min[k].min(p[k]);
            max[k] = max[k].max(p[k]);
        }
    };
    for i in 0..3 {
        let (a, b) = (v[i], v[(i + 1) % 3]);
        if a[axis] >= lo64 && a[axis] <= hi64 {
            grow(a);
        }
        for plane in [lo64, hi64] {
            if (a[axis] < plane && b[axis] > plane) || (a[axis] > plane && b[axis] < plane) {
                let s = (plane - a[axis]) / (b[axis] - a[axis]);
                let mut p = [
                    a[0] + (b[0] - a[0]) * s,
                    a[1] + (b[1] - a[1]) * s,
                    a[2] + (b[2] - a[2]) * s,
                ];
                p[axis] = plane;
                grow(p);
            }
        }
    }
    if min[0] > max[0] {
        return Box3::EMPTY;
    }
    let down = |x: f64| {
        let f = x as f32;
        if f as f64 > x {
            step(f, -1.0)
        } else {
            f
        }
    };
    let up = |x: f64| {
        let f = x as f32;
        if (f as f64) < x {
            step(f, 1.0)
        } else {
            f
        }
    };
    let mut b = Box3 {
        min: Vec3A::new(down(min[0]), down(min[1]), down(min[2])),
        max: Vec3A::new(up(max[0]), up(max[1]), up(max[2])),
    };
    // On the split axis the planes themselves bound the part (they are f32 already).
    b.min[axis] = b.min[axis].max(lo);
    b.max[axis] = b.max[axis].min(hi);
    b
}

/// The next f32 after finite `f` toward the sign of `dir` (`f32::next_up`/`next_down`, which
/// need Rust 1.86; the workspace's MSRV is 1.85).
pub(super) fn step(f: f32, dir: f32) -> f32 {
    if f == 0.0 {
        return f32::from_bits(1).copysign(dir);
    }
    let bits = f.to_bits();
    // Away from zero is one more in the bit pattern, toward zero one less, for either sign.
    f32::from_bits(if (f > 0.0) == (dir > 0.0) {
        bits + 1
    } else {
        bits - 1
    })
}

impl Builder<'_> {
    /// Leaf or split of `refs` (whose union is `bounds`).
    fn plan(&mut self, mut refs: Vec<Ref>, bounds: Box3) -> Plan {
        let count = refs.len();
        if count < 2 {
            return Plan::Leaf(refs);
        }
        let parent_area = bounds.half_area().max(f32::MIN_POSITIVE);
        let centroids = refs.iter().fold(Box3::EMPTY, |b, r| b.grow(centroid(r)));
        let object = self.object_split(&refs, centroids, parent_area);
        // Few references become a leaf unless splitting them is much cheaper (SMALL_SPLIT_GAIN).
        if count <= self.options.leaf_target
            && object
                .as_ref()
                .is_none_or(|o| o.cost >= SMALL_SPLIT_GAIN * count as f32)
        {
            return Plan::Leaf(refs);
        }
        let mut spatial = None;
        if let Some(o) = &object {
            let overlap = area(intersect(o.left, o.right));
            if self.spare_refs > 0 && overlap / self.root_area > ALPHA {
                spatial = self
                    .spatial_split(&refs, bounds, parent_area)
                    .filter(|s| s.cost < o.cost);
            }
        }
        let best_cost = spatial.as_ref().or(object.as_ref()).map(|c| c.cost);
        if count <= LEAF_MAX && best_cost.is_none_or(|c| c >= count as f32) {
            return Plan::Leaf(refs);
        }
        if let Some(s) = spatial {
            if let Some(plan) = self.apply_spatial(&refs, bounds, &s) {
                return plan;
            }
        }
        if let Some(o) = object {
            let lo = centroids.min[o.axis];
            let scale = BINS as f32 / (centroids.max[o.axis] - lo);
            let (left, right): (Vec<Ref>, Vec<Ref>) = refs.iter().partition(|r| {
                (((centroid(r)[o.axis] - lo) * scale) as usize).min(BINS - 1) < o.split
            });
            if !left.is_empty() && !right.is_empty() {
                return Plan::Split(left, o.left, right, o.right);
            }
        }
        // No useful split of a range too big for one leaf: halve it along the widest centroid axis.
        let extent = centroids.max - centroids.min;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        let mid = count / 2;
        refs.select_nth_unstable_by(mid, |a, b| centroid(a)[axis].total_cmp(&centroid(b)[axis]));
        let right = refs.split_off(mid);
        let (lb, rb) = (bounds_of(&refs), bounds_of(&right));
        Plan::Split(refs, lb, right, rb)
    }

    fn object_split(&self, refs: &[Ref], centroids: Box3, parent_area: f32) -> Option<Candidate> {
        let lo = centroids.min;
        let extent = centroids.max - lo;
        let scale = Vec3A::select(
            extent.cmpgt(Vec3A::ZERO),
            Vec3A::splat(BINS as f32) / extent,
            Vec3A::ZERO,
        );
        let mut bins = [[EMPTY_BIN; BINS]; 3];
        for r in refs {
            let k = ((centroid(r) - lo) * scale).min(Vec3A::splat((BINS - 1) as f32));
            for axis in 0..3 {
                let bin = &mut bins[axis][k[axis] as usize];
                bin.bounds = bin.bounds.union(r.bounds);
                bin.enter += 1;
                bin.exit += 1;
            }
        }
        let mut best: Option<Candidate> = None;
        for axis in (0..3).filter(|&a| extent[a] > 0.0) {
            self.sweep(&bins[axis], axis, parent_area, |_, _| true, &mut best);
        }
        best
    }

    /// The SAH sweep over one axis' bins: every boundary with references on both sides (left:
    /// those entering a bin left of it, right: those leaving one right of it) that `allowed`
    /// accepts by (left, right) counts, kept in `best` when cheaper.
    fn sweep(
        &self,
        bins: &[Bin; BINS],
        axis: usize,
        parent_area: f32,
        allowed: impl Fn(u32, u32) -> bool,
        best: &mut Option<Candidate>,
    ) {
        let mut right = [(Box3::EMPTY, 0u32); BINS];
        let (mut acc, mut n) = (Box3::EMPTY, 0u32);
        for i in (1..BINS).rev() {
            acc = acc.union(bins[i].bounds);
            n += bins[i].exit;
            right[i] = (acc, n);
        }
        let (mut acc, mut n) = (Box3::EMPTY, 0u32);
        for split in 1..BINS {
            acc = acc.union(bins[split - 1].bounds);
            n += bins[split - 1].enter;
            let (rb, rn) = right[split];
            if n == 0 || rn == 0 || !allowed(n, rn) {
                continue;
            }
            let cost = self.options.node_cost
                + (area(acc) * n as f32 + area(rb) * rn as f32) / parent_area;
            if best.as_ref().is_none_or(|b| cost < b.cost) {
                *best = Some(Candidate {
                    cost,
                    axis,
                    split,
                    left: acc,
                    right: rb,
                    counts: (n, rn),
                });
            }
        }
    }

    /// The split plane of spatial bin boundary `split` on `axis` of `bounds`.
    fn plane(bounds: Box3, axis: usize, split: usize) -> f32 {
        let (lo, hi) = (bounds.min[axis], bounds.max[axis]);
        if split == BINS {
            hi
        } else {
            lo + (hi - lo) * (split as f32 / BINS as f32)
        }
    }

    fn spatial_split(&self, refs: &[Ref], bounds: Box3, parent_area: f32) -> Option<Candidate> {
        let mut best: Option<Candidate> = None;
        for axis in 0..3 {
            let (lo, hi) = (bounds.min[axis], bounds.max[axis]);
            if hi <= lo {
                continue;
            }
            let scale = BINS as f32 / (hi - lo);
            let bin_of = |x: f32| (((x - lo) * scale).max(0.0) as usize).min(BINS - 1);
            let mut bins = [EMPTY_BIN; BINS];
            for r in refs {
                let (first, last) = (bin_of(r.bounds.min[axis]), bin_of(r.bounds.max[axis]));
                bins[first].enter += 1;
                bins[last].exit += 1;
                if first == last {
                    bins[first].bounds = bins[first].bounds.union(r.bounds);
                    continue;
                }
                let tri = &self.tris[r.prim as usize];
                for (k, bin) in bins.iter_mut().enumerate().take(last + 1).skip(first) {
                    let part = intersect(
                        clip_triangle(
                            tri,
                            axis,
                            Self::plane(bounds, axis, k),
                            Self::plane(bounds, axis, k + 1),
                        ),
                        r.bounds,
                    );
                    if !is_empty(part) {
                        bin.bounds = bin.bounds.union(part);
                    }
                }
            }
            // A reference straddling the plane sits on both sides: within the spare budget only.
            self.sweep(
                &bins,
                axis,
                parent_area,
                |n, rn| (n + rn) as usize - refs.len() <= self.spare_refs,
                &mut best,
            );
        }
        best
    }

    /// Splits the references at the candidate's plane; `None` when one side would be empty.
    fn apply_spatial(&mut self, refs: &[Ref], bounds: Box3, s: &Candidate) -> Option<Plan> {
        let (axis, plane) = (s.axis, Self::plane(bounds, s.axis, s.split));
        let (mut left, mut right) = (
            Vec::with_capacity(s.counts.0 as usize),
            Vec::with_capacity(s.counts.1 as usize),
        );
        let (la, ra) = (area(s.left), area(s.right));
        let (nl, nr) = (s.counts.0 as f32, s.counts.1 as f32);
        for r in refs {
            if r.bounds.max[axis] <= plane {
                left.push(*r);
            } else if r.bounds.min[axis] >= plane {
                right.push(*r);
            } else {
                let tri = &self.tris[r.prim as usize];
                let lpart = intersect(clip_triangle(tri, axis, f32::NEG_INFINITY, plane), r.bounds);
                let rpart = intersect(clip_triangle(tri, axis, plane, f32::INFINITY), r.bounds);
                match (is_empty(lpart), is_empty(rpart)) {
                    (false, true) => left.push(Ref {
                        prim: r.prim,
                        bounds: lpart,
                    }),
                    (true, false) => right.push(Ref {
                        prim: r.prim,
                        bounds: rpart,
                    }),
                    _ => {
                        // Reference unsplitting (Stich et al. §4.3): keep it whole where cheaper.
                        let split = la * nl + ra * nr;
                        let all_left = area(s.left.union(r.bounds)) * nl + ra * (nr - 1.0);
                        let all_right = la * (nl - 1.0) + area(s.right.union(r.bounds)) * nr;
                        if all_left < split && all_left <= all_right {
                            left.push(*r);
                        } else if all_right < split {
                            right.push(*r);
                        } else if self.spare_refs > 0 {
                            self.spare_refs -= 1;
                            left.push(Ref {
                                prim: r.prim,
                                bounds: lpart,
                            });
                            right.push(Ref {
                                prim: r.prim,
                                bounds: rpart,
                            });
                        } else if area(lpart) >= area(rpart) {
                            left.push(*r);
                        } else {
                            right.push(*r);
                        }
                    }
                }
            }
        }
        if left.is_empty() || right.is_empty() {
            return None;
        }
        let (lb, rb) = (bounds_of(&left), bounds_of(&right));
        Some(Plan::Split(left, lb, right, rb))
    }
}
