//! Compressed 8-wide BVH, the layout of the GPU-shaped traversal (after Ylitie, Karras, Laine
//! 2017, "Efficient Incoherent Ray Traversal on GPUs Through Compressed Wide BVHs").
//!
//! **Collapse.** The binary tree ([`Bvh`], SBVH or binned) is collapsed by the paper's dynamic
//! programme: for every binary node and every number of slots 1..=8 the cheapest way (by SAH,
//! [`CollapseCosts`]) to spread its subtree over that many child slots, each slot an 8-wide node
//! or a leaf of at most [`LEAF_MAX`] triangles. Binary leaves of more than three references are
//! first split into single references (their boxes clipped to the leaf's box, which keeps an
//! SBVH's clipped leaves correct), so the programme also chooses how to group them.
//!
//! **Node** (80 bytes, 5 × uvec4, [`Bvh8::node_words`]): the node box's origin p (3 × f32), one
//! power-of-two scale per axis as a biased exponent (3 × u8), the mask of interior slots (u8), the
//! index of the first child node, the index of the first leaf triangle, 8 meta bytes and 8-bit
//! child boxes (6 × 8 bytes). A child's box decodes to `p + q · 2^e` per plane; the builder picks
//! p a multiple of 2^e and 2^e at least twice the float spacing at the node's coordinates, so the
//! decoded planes are exact floats on every device and the slab test is the existing conservative
//! one ([`slab_test`]) on a box that contains the child's.
//!
//! **Children.** A node's interior children are consecutive nodes from `child_base` in slot order;
//! its leaves' triangles are consecutive entries from `triangle_base` (≤ 24 per node). Meta byte:
//! 0 empty; interior `0b001_11sss` (24 + slot); leaf `unary(count) << 5 | offset`. Slots are
//! ordered by octant (Ylitie et al. §3.2): slot s holds the child lying farthest against the
//! direction of a ray of octant s, so that visiting slots in the order `octant ^ k` is nearest
//! first when entry distances tie (rays starting inside several boxes).
//!
//! **Traversal** ([`Bvh8::walk`], the CPU twin of `bvh8_walk` in shaders/common/bvh.glsl): fully
//! ordered. Opening a node slab-tests its eight children, sorts the reached ones by entry distance
//! (a 19-comparator network, [`SORT8`]), visits the nearest and pushes the others with their entry
//! distance; a leaf slot is an entry like a node (its ≤ 3 triangles are tested when it is popped),
//! and a popped entry farther than the closest hit so far is skipped. Measured against the
//! paper's unsorted octant-ordered node groups, this reads about a third fewer bytes per ray on
//! Sponza and the Breakfast Room (docs/performance.md), for a stack of (entry, distance) pairs of
//! at most [`Bvh8::max_stack`] entries instead of one group per level.
//!
//! **Triangles** ([`Bvh8::triangle_words`]): 48 bytes per leaf entry, (v0, bits(original index)),
//! (v1, bits(flags)), (v2, 0); flag [`TRIANGLE_ALPHA_TESTED`] marks the triangles whose material
//! is alpha-masked or blended, so opaque ones never reach the alpha test.

use super::traverse::{safe_inverse_dir, SLAB_SLACK};
use super::{Bvh, TraceState};
use crate::intersect::{Hit, Ray, WatertightRay};
use crate::Aabb;
use glam::Vec3;

pub const WIDTH: usize = 8;
/// Triangles in one leaf slot (the meta byte's 3-bit unary count).
pub const LEAF_MAX: usize = 3;
/// Bytes the traversal reads per node opened and per leaf triangle tested.
pub const NODE_BYTES: u64 = 80;
pub const TRIANGLE_BYTES: u64 = 48;
/// Flag bit in a leaf triangle's second word: its material needs the alpha test.
pub const TRIANGLE_ALPHA_TESTED: u32 = 1;

/// One compressed node (see the module doc).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Bvh8Node {
    pub origin: [f32; 3],
    /// Per axis, the exponent e of the scale 2^e, biased by 127 (an f32's exponent field).
    pub exponent: [u8; 3],
    /// Bit s set: slot s is an interior child.
    pub imask: u8,
    pub child_base: u32,
    pub triangle_base: u32,
    pub meta: [u8; WIDTH],
    /// Quantised child boxes per axis and slot.
    pub lo: [[u8; WIDTH]; 3],
    pub hi: [[u8; WIDTH]; 3],
}

impl Bvh8Node {
    /// The decoded box of `slot` (exact in f32, containing the child's box).
    pub fn child_bounds(&self, slot: usize) -> Aabb {
        let plane = |axis: usize, q: u8| {
            let scale = f32::from_bits(u32::from(self.exponent[axis]) << 23);
            self.origin[axis] + f32::from(q) * scale
        };
        Aabb {
            min: Vec3::new(
                plane(0, self.lo[0][slot]),
                plane(1, self.lo[1][slot]),
                plane(2, self.lo[2][slot]),
            ),
            max: Vec3::new(
                plane(0, self.hi[0][slot]),
                plane(1, self.hi[1][slot]),
                plane(2, self.hi[2][slot]),
            ),
        }
    }

    pub fn is_interior(&self, slot: usize) -> bool {
        self.imask & (1 << slot) != 0
    }

    /// Leaf slot: (first entry relative to `triangle_base`, count); `None` for interior or empty.
    pub fn leaf(&self, slot: usize) -> Option<(u32, u32)> {
        let meta = self.meta[slot];
        (meta != 0 && !self.is_interior(slot))
            .then(|| (u32::from(meta & 0x1f), (meta >> 5).count_ones()))
    }
}

/// The SAH weights of the collapse: a node visit against one triangle test (Ylitie et al. use
/// 1 and 0.3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CollapseCosts {
    pub node: f32,
    pub triangle: f32,
}

impl Default for CollapseCosts {
    fn default() -> CollapseCosts {
        CollapseCosts {
            node: 1.0,
            triangle: 0.3,
        }
    }
}

#[derive(Clone, Debug, Default)]
pub struct Bvh8 {
    pub nodes: Vec<Bvh8Node>,
    /// Leaf entries in node order (original triangle indices; an SBVH repeats some).
    pub tri_order: Vec<u32>,
}

/// A binary node of the collapse's input: the builder's tree with its big leaves split.
struct Item {
    bounds: Aabb,
    /// Triangle references below it.
    count: u32,
    kind: ItemKind,
}

enum ItemKind {
    /// References `refs[start .. start + count]`.
    Leaf(u32),
    Inner(u32, u32),
}

#[derive(Clone, Copy, PartialEq)]
enum Choice {
    /// The subtree as one leaf slot.
    Leaf,
    /// The subtree as one 8-wide node.
    Node,
    /// The subtree's two children over (left, right) slots.
    Split(u8, u8),
}

struct Collapse {
    items: Vec<Item>,
    refs: Vec<u32>,
    /// Per item, for 1..=8 slots: the least cost and how it is reached.
    cost: Vec<[f32; WIDTH]>,
    choice: Vec<[Choice; WIDTH]>,
    /// Per interior item: its children's slots when it becomes a node.
    node_split: Vec<(u8, u8)>,
}

impl Collapse {
    /// The builder's tree as items (parents before children), leaves over three references
    /// split into single ones.
    fn new(bvh: &Bvh, tris: &[[Vec3; 3]]) -> Option<Collapse> {
        let root = &bvh.nodes[0];
        let root_children: Vec<usize> = (0..2).filter(|&c| !root.is_empty_child(c)).collect();
        if root_children.is_empty() {
            return None;
        }
        let mut c = Collapse {
            items: Vec::new(),
            refs: Vec::new(),
            cost: Vec::new(),
            choice: Vec::new(),
            node_split: Vec::new(),
        };
        // (item to fill, binary child: bounds, ref, count)
        let mut work: Vec<(usize, Aabb, u32, u32)> = Vec::new();
        let child = |n: u32, s: usize| {
            let node = &bvh.nodes[n as usize];
            (node.child_bounds(s), node.child_ref[s], node.child_count[s])
        };
        if root_children.len() == 1 {
            let (b, r, n) = child(0, root_children[0]);
            c.items.push(c.placeholder(b));
            work.push((0, b, r, n));
        } else {
            let bounds = root.child_bounds(0).union(&root.child_bounds(1));
            c.items.push(c.placeholder(bounds));
            work.push((0, bounds, 0, 0));
        }
        while let Some((item, bounds, node_ref, count)) = work.pop() {
            if count > 0 {
                let leaf = &bvh.tri_order[node_ref as usize..(node_ref + count) as usize];
                c.fill_leaf(item, bounds, leaf, tris);
                continue;
            }
            let node = &bvh.nodes[node_ref as usize];
            let kids: Vec<usize> = (0..2).filter(|&s| !node.is_empty_child(s)).collect();
            if kids.len() == 1 {
                // A lone child stands for its parent (only a degenerate root has one).
                let (_, r, n) = child(node_ref, kids[0]);
                work.push((item, bounds, r, n));
                continue;
            }
            let first = c.items.len();
            for &s in &kids {
                let (b, r, n) = child(node_ref, s);
                c.items.push(c.placeholder(b));
                work.push((c.items.len() - 1, b, r, n));
            }
            c.items[item].kind = ItemKind::Inner(first as u32, first as u32 + 1);
        }
        c.count_references();
        Some(c)
    }

    fn placeholder(&self, bounds: Aabb) -> Item {
        Item {
            bounds,
            count: 0,
            kind: ItemKind::Leaf(0),
        }
    }

    /// A binary leaf: kept when it fits a slot, else split into single references (halved along
    /// the longest axis of their clipped boxes' centroids).
    fn fill_leaf(&mut self, item: usize, bounds: Aabb, leaf: &[u32], tris: &[[Vec3; 3]]) {
        if leaf.len() <= LEAF_MAX {
            self.items[item].kind = ItemKind::Leaf(self.refs.len() as u32);
            self.items[item].count = leaf.len() as u32;
            self.refs.extend_from_slice(leaf);
            return;
        }
        // Each reference's box clipped to the leaf's (an SBVH leaf bounds only its part of a
        // triangle; a hit inside the leaf's box lies in the clipped box too).
        let mut parts: Vec<(u32, Aabb)> = leaf
            .iter()
            .map(|&t| {
                let b = Aabb::of_points(&tris[t as usize]);
                let clipped = Aabb {
                    min: b.min.max(bounds.min),
                    max: b.max.min(bounds.max),
                };
                let inverted = clipped.min.cmpgt(clipped.max).any();
                (t, if inverted { bounds } else { clipped })
            })
            .collect();
        // (item, range of parts) split until single references.
        let mut work = vec![(item, 0usize, parts.len())];
        while let Some((at, start, end)) = work.pop() {
            let range = &mut parts[start..end];
            let bounds = range.iter().fold(Aabb::EMPTY, |b, p| b.union(&p.1));
            self.items[at].bounds = bounds;
            if range.len() == 1 {
                self.items[at].kind = ItemKind::Leaf(self.refs.len() as u32);
                self.items[at].count = 1;
                self.refs.push(range[0].0);
                continue;
            }
            let extent = bounds.max - bounds.min;
            let axis = if extent.x >= extent.y && extent.x >= extent.z {
                0
            } else if extent.y >= extent.z {
                1
            } else {
                2
            };
            range.sort_by(|a, b| a.1.center()[axis].total_cmp(&b.1.center()[axis]));
            let mid = start + range.len() / 2;
            let first = self.items.len();
            self.items.push(self.placeholder(bounds));
            self.items.push(self.placeholder(bounds));
            self.items[at].kind = ItemKind::Inner(first as u32, first as u32 + 1);
            work.push((first, start, mid));
            work.push((first + 1, mid, end));
        }
    }

    /// Fills `count` bottom-up (children come after their parents).
    fn count_references(&mut self) {
        for i in (0..self.items.len()).rev() {
            if let ItemKind::Inner(l, r) = self.items[i].kind {
                self.items[i].count = self.items[l as usize].count + self.items[r as usize].count;
            }
        }
    }

    /// The dynamic programme, children before parents.
    fn solve(&mut self, costs: CollapseCosts) {
        let n = self.items.len();
        self.cost = vec![[f32::INFINITY; WIDTH]; n];
        self.choice = vec![[Choice::Leaf; WIDTH]; n];
        self.node_split = vec![(0, 0); n];
        for i in (0..n).rev() {
            let item = &self.items[i];
            let area = item.bounds.surface_area().max(0.0);
            let leaf_cost = if item.count as usize <= LEAF_MAX {
                area * costs.triangle * item.count as f32
            } else {
                f32::INFINITY
            };
            let ItemKind::Inner(l, r) = item.kind else {
                self.cost[i] = [leaf_cost; WIDTH];
                continue;
            };
            let (l, r) = (l as usize, r as usize);
            // Both children over j slots: dist[j] = (cost, left slots, right slots).
            let mut dist = [(f32::INFINITY, 0u8, 0u8); WIDTH + 1];
            for (j, d) in dist.iter_mut().enumerate().skip(2) {
                for k in 1..j {
                    let c = self.cost[l][k - 1] + self.cost[r][j - k - 1];
                    if c < d.0 {
                        *d = (c, k as u8, (j - k) as u8);
                    }
                }
            }
            let node_cost = area * costs.node + dist[WIDTH].0;
            self.node_split[i] = (dist[WIDTH].1, dist[WIDTH].2);
            let (mut best, mut how) = if leaf_cost <= node_cost {
                (leaf_cost, Choice::Leaf)
            } else {
                (node_cost, Choice::Node)
            };
            self.cost[i][0] = best;
            self.choice[i][0] = how;
            for (j, &(cost, a, b)) in dist.iter().enumerate().skip(2) {
                if cost < best {
                    best = cost;
                    how = Choice::Split(a, b);
                }
                self.cost[i][j - 1] = best;
                self.choice[i][j - 1] = how;
            }
        }
    }

    /// The slots item `i` spreads over with at most `slots` of them: (item, is a leaf).
    fn gather(&self, i: usize, slots: usize, out: &mut Vec<(usize, bool)>) {
        match self.choice[i][slots - 1] {
            Choice::Leaf => out.push((i, true)),
            Choice::Node => out.push((i, false)),
            Choice::Split(a, b) => {
                let ItemKind::Inner(l, r) = self.items[i].kind else {
                    unreachable!("only interior items split")
                };
                self.gather(l as usize, a as usize, out);
                self.gather(r as usize, b as usize, out);
            }
        }
    }

    /// Item `i`'s references in leaf order.
    fn references(&self, i: usize, out: &mut Vec<u32>) {
        let mut stack = vec![i];
        while let Some(i) = stack.pop() {
            match self.items[i].kind {
                ItemKind::Leaf(start) => {
                    let n = self.items[i].count as usize;
                    out.extend_from_slice(&self.refs[start as usize..start as usize + n]);
                }
                ItemKind::Inner(l, r) => {
                    stack.push(r as usize);
                    stack.push(l as usize);
                }
            }
        }
    }

    /// The slots of item `i` as a node: its children's gathered slots (the root's lone leaf
    /// stands alone).
    fn node_slots(&self, i: usize) -> Vec<(usize, bool)> {
        let mut out = Vec::with_capacity(WIDTH);
        match self.items[i].kind {
            ItemKind::Leaf(_) => out.push((i, true)),
            ItemKind::Inner(l, r) => {
                let (a, b) = self.node_split[i];
                self.gather(l as usize, a as usize, &mut out);
                self.gather(r as usize, b as usize, &mut out);
            }
        }
        out
    }
}

/// Per axis of a node's box: the origin (a multiple of the scale) and the biased exponent of a
/// scale that spans the box in 255 steps and makes every decoded plane an exact f32.
fn quantisation(lo: f32, hi: f32) -> (f32, u8) {
    let magnitude = f64::from(lo.abs().max(hi.abs()));
    // Twice the spacing of floats at the box's coordinates: origin / 2^e + q stays below 2^24.
    let spacing_exp = if magnitude > 0.0 {
        magnitude.log2().floor() as i32 - 22
    } else {
        -126
    };
    let extent = f64::from(hi) - f64::from(lo);
    let extent_exp = if extent > 0.0 {
        (extent / 254.0).log2().ceil() as i32
    } else {
        -126
    };
    let mut e = spacing_exp.max(extent_exp).max(-100);
    loop {
        let scale = 2f64.powi(e);
        let origin = (f64::from(lo) / scale).floor() * scale;
        if ((f64::from(hi) - origin) / scale).ceil() <= 255.0 || e >= 127 {
            return (origin as f32, (e + 127) as u8);
        }
        e += 1;
    }
}

/// Which slot each child takes (Ylitie et al. §3.2): slot s is first for rays of octant s, so it
/// takes the child farthest along that octant's reversed direction; greedy over the cheapest
/// (child, slot) pairs.
fn octant_slots(parent: &Aabb, children: &[Aabb]) -> [Option<usize>; WIDTH] {
    let centre = parent.center();
    let mut pairs: Vec<(f32, usize, usize)> = Vec::with_capacity(children.len() * WIDTH);
    for (c, b) in children.iter().enumerate() {
        let offset = b.center() - centre;
        for s in 0..WIDTH {
            // The direction of a ray of octant s (bit 2: x negative, bit 1: y, bit 0: z).
            let d = Vec3::new(
                if s & 4 != 0 { -1.0 } else { 1.0 },
                if s & 2 != 0 { -1.0 } else { 1.0 },
                if s & 1 != 0 { -1.0 } else { 1.0 },
            );
            pairs.push((offset.dot(d), c, s));
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut slot_of = [None; WIDTH];
    let mut taken = [false; WIDTH];
    let mut placed = vec![false; children.len()];
    for (_, c, s) in pairs {
        if !taken[s] && !placed[c] {
            slot_of[s] = Some(c);
            taken[s] = true;
            placed[c] = true;
        }
    }
    slot_of
}

/// A ray's octant: bit 2 x negative, bit 1 y, bit 0 z (as the GLSL computes it).
pub fn octant(dir: Vec3) -> u32 {
    (u32::from(dir.x < 0.0) << 2) | (u32::from(dir.y < 0.0) << 1) | u32::from(dir.z < 0.0)
}

impl Bvh8 {
    /// Collapses `bvh` (built over `tris`) with [`CollapseCosts::default`].
    pub fn from_binary(bvh: &Bvh, tris: &[[Vec3; 3]]) -> Bvh8 {
        Bvh8::from_binary_with(bvh, tris, CollapseCosts::default())
    }

    pub fn from_binary_with(bvh: &Bvh, tris: &[[Vec3; 3]], costs: CollapseCosts) -> Bvh8 {
        let Some(mut c) = Collapse::new(bvh, tris) else {
            return Bvh8 {
                nodes: vec![Bvh8Node::default()],
                tri_order: Vec::new(),
            };
        };
        c.solve(costs);
        let mut out = Bvh8 {
            nodes: vec![Bvh8Node::default()],
            tri_order: Vec::new(),
        };
        // Breadth first: (node to fill, item it stands for).
        let mut queue = std::collections::VecDeque::from([(0usize, 0usize)]);
        while let Some((at, item)) = queue.pop_front() {
            let slots = c.node_slots(item);
            let boxes: Vec<Aabb> = slots.iter().map(|&(i, _)| c.items[i].bounds).collect();
            let parent = boxes.iter().fold(Aabb::EMPTY, |b, c| b.union(c));
            let order = octant_slots(&parent, &boxes);
            let mut node = Bvh8Node {
                child_base: out.nodes.len() as u32,
                triangle_base: out.tri_order.len() as u32,
                ..Default::default()
            };
            for axis in 0..3 {
                let (origin, exponent) = quantisation(parent.min[axis], parent.max[axis]);
                node.origin[axis] = origin;
                node.exponent[axis] = exponent;
            }
            let mut offset = 0u8;
            for (slot, child) in order.iter().enumerate() {
                let Some(k) = *child else { continue };
                let (i, leaf) = slots[k];
                let b = c.items[i].bounds;
                for axis in 0..3 {
                    let scale = 2f64.powi(i32::from(node.exponent[axis]) - 127);
                    let origin = f64::from(node.origin[axis]);
                    let lo = ((f64::from(b.min[axis]) - origin) / scale).floor();
                    let hi = ((f64::from(b.max[axis]) - origin) / scale).ceil();
                    node.lo[axis][slot] = lo.clamp(0.0, 255.0) as u8;
                    node.hi[axis][slot] = hi.clamp(0.0, 255.0) as u8;
                }
                if leaf {
                    let start = out.tri_order.len();
                    c.references(i, &mut out.tri_order);
                    let count = (out.tri_order.len() - start) as u8;
                    node.meta[slot] = (((1u8 << count) - 1) << 5) | offset;
                    offset += count;
                } else {
                    node.imask |= 1 << slot;
                    node.meta[slot] = (1 << 5) | (24 + slot as u8);
                    queue.push_back((out.nodes.len(), i));
                    out.nodes.push(Bvh8Node::default());
                }
            }
            out.nodes[at] = node;
        }
        out
    }

    /// Longest root-to-leaf path in nodes (the root alone is depth 1).
    pub fn depth(&self) -> u32 {
        let mut depth = vec![0u32; self.nodes.len()];
        depth[0] = 1;
        // Children always follow their parent (breadth-first order).
        for (i, n) in self.nodes.iter().enumerate() {
            for rank in 0..n.imask.count_ones() {
                depth[(n.child_base + rank) as usize] = depth[i] + 1;
            }
        }
        depth.into_iter().max().unwrap_or(0)
    }

    /// 5 uvec4 per node, see the module doc.
    pub fn node_words(&self) -> Vec<[u32; 4]> {
        let bytes4 = |b: &[u8]| u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        self.nodes
            .iter()
            .flat_map(|n| {
                let e = n.exponent;
                let packed = u32::from(e[0])
                    | u32::from(e[1]) << 8
                    | u32::from(e[2]) << 16
                    | u32::from(n.imask) << 24;
                let half = |axis: &[u8; WIDTH]| [bytes4(&axis[..4]), bytes4(&axis[4..])];
                let [lx0, lx1] = half(&n.lo[0]);
                let [ly0, ly1] = half(&n.lo[1]);
                let [lz0, lz1] = half(&n.lo[2]);
                let [hx0, hx1] = half(&n.hi[0]);
                let [hy0, hy1] = half(&n.hi[1]);
                let [hz0, hz1] = half(&n.hi[2]);
                [
                    [
                        n.origin[0].to_bits(),
                        n.origin[1].to_bits(),
                        n.origin[2].to_bits(),
                        packed,
                    ],
                    [
                        n.child_base,
                        n.triangle_base,
                        bytes4(&n.meta[..4]),
                        bytes4(&n.meta[4..]),
                    ],
                    [lx0, lx1, ly0, ly1],
                    [lz0, lz1, hx0, hx1],
                    [hy0, hy1, hz0, hz1],
                ]
            })
            .collect()
    }

    /// 3 vec4 per leaf entry: (v0, bits(original index)), (v1, bits(flags)), (v2, 0), with
    /// [`TRIANGLE_ALPHA_TESTED`] where `alpha_tested(original index)`.
    pub fn triangle_words(
        &self,
        tris: &[[Vec3; 3]],
        alpha_tested: &dyn Fn(u32) -> bool,
    ) -> Vec<[f32; 4]> {
        super::traverse::triangle_texels(&self.tri_order, tris, alpha_tested)
    }

    /// GPU bytes: 80 per node plus 48 per leaf entry.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * NODE_BYTES as usize + self.tri_order.len() * TRIANGLE_BYTES as usize
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

    /// [`Bvh8::intersect`] continuing from `state.best`, hit ids offset by `id_base`, the nodes
    /// opened and triangles tested counted as `bvh8_walk` counts them; returns the any-hit answer.
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
        self.walk(ray, t_max, state, |tri, state| {
            state.counts.triangles += 1;
            state.counts.bytes += TRIANGLE_BYTES;
            let [a, b, c] = tris[tri as usize];
            let (t, u, v) = wray.intersect(a, b, c, t_max)?;
            let hit = Hit {
                t,
                triangle: id_base + tri,
                u,
                v,
            };
            if any_hit {
                return Some(hit);
            }
            if state.best.is_none_or(|b| hit.is_closer_than(&b)) {
                state.best = Some(hit);
            }
            None
        })
    }

    /// The traversal with `leaf_entry(tri_order value, state)` called for each leaf entry whose
    /// slot the ray reaches (a triangle, or an instance in a top level); an entry's `Some` ends
    /// the walk with it (any hit).
    pub fn walk(
        &self,
        ray: &Ray,
        t_max: f32,
        state: &mut TraceState,
        mut leaf_entry: impl FnMut(u32, &mut TraceState) -> Option<Hit>,
    ) -> Option<Hit> {
        let inv_dir = safe_inverse_dir(ray.dir);
        let octant = octant(ray.dir) as usize;
        let mut stack: Vec<(u32, f32)> = Vec::with_capacity(STACK_SIZE);
        let mut next = Some(0u32);
        loop {
            let limit = state.best.map_or(t_max, |h| h.t) * SLAB_SLACK;
            let entry = match next.take() {
                Some(e) => e,
                // Entries whose box the ray enters beyond the closest hit so far are skipped.
                None => loop {
                    let (e, enter) = stack.pop()?;
                    if enter <= limit {
                        break e;
                    }
                },
            };
            if entry & LEAF_ENTRY != 0 {
                let first = (entry & !LEAF_ENTRY) >> 2;
                for e in first..first + (entry & 3) {
                    let item = self.tri_order[e as usize];
                    if let Some(hit) = leaf_entry(item, state) {
                        return Some(hit);
                    }
                }
                continue;
            }
            let n = &self.nodes[entry as usize];
            state.counts.nodes += 1;
            state.counts.bytes += NODE_BYTES;
            // The children in octant order (slot octant ^ k at k), keyed by entry distance
            // (+∞: missed or empty), then sorted nearest first by the GLSL's network.
            let mut keyed: [(f32, u32); WIDTH] = std::array::from_fn(|k| {
                let slot = octant ^ k;
                let meta = u32::from(n.meta[slot]);
                let b = n.child_bounds(slot);
                let enter = slab_enter(b.min, b.max, ray.origin, inv_dir, limit);
                let entry = if n.is_interior(slot) {
                    n.child_base + (u32::from(n.imask) & ((1 << slot) - 1)).count_ones()
                } else {
                    LEAF_ENTRY | (n.triangle_base + (meta & 0x1f)) << 2 | (meta >> 5).count_ones()
                };
                (enter.filter(|_| meta != 0).unwrap_or(f32::INFINITY), entry)
            });
            for (a, b) in SORT8 {
                if keyed[b].0 < keyed[a].0 {
                    keyed.swap(a, b);
                }
            }
            let reached = keyed.iter().filter(|k| k.0 != f32::INFINITY).count();
            if reached > 0 {
                next = Some(keyed[0].1);
                stack.extend(keyed[1..reached].iter().rev().map(|&(t, e)| (e, t)));
            }
        }
    }

    /// Most entries the traversal stack can hold: at a node with k reached children the nearest
    /// is visited and k − 1 pushed, so the worst path sums k − 1 over its nodes.
    pub fn max_stack(&self) -> u32 {
        let mut most = 0;
        let mut stack = vec![(0u32, 0u32)];
        while let Some((node, below)) = stack.pop() {
            let n = &self.nodes[node as usize];
            let children = n.meta.iter().filter(|&&m| m != 0).count() as u32;
            let held = below + children.saturating_sub(1);
            most = most.max(held);
            for rank in 0..n.imask.count_ones() {
                stack.push((n.child_base + rank, held));
            }
        }
        most
    }
}

/// The entry distance of the slab test (`slab_test`) against an already slackened `limit`, as
/// the GLSL computes it for eight children at once.
fn slab_enter(min: Vec3, max: Vec3, origin: Vec3, inv_dir: Vec3, limit: f32) -> Option<f32> {
    let t0 = (min - origin) * inv_dir;
    let t1 = (max - origin) * inv_dir;
    let near = t0.min(t1);
    let far = t0.max(t1);
    let enter = near.x.max(near.y).max(near.z).max(0.0);
    let leave = far.x.min(far.y).min(far.z) * SLAB_SLACK;
    (enter <= leave && enter <= limit).then_some(enter)
}

/// Stack and child entries: bit 31 marks a leaf slot, `(first entry << 2) | count`; otherwise a
/// node index.
pub const LEAF_ENTRY: u32 = 0x8000_0000;
/// The GLSL's stack size (BVH8_STACK_SIZE): uploads refuse trees whose [`Bvh8::max_stack`]
/// exceeds it. The real scenes need up to 91 (the Breakfast Room's SBVH, depth 13); 128 entries
/// of 8 bytes leave room for deeper trees at no cost to the rays that push fewer.
pub const STACK_SIZE: usize = 128;
/// Batcher's odd–even merge sort of 8 keys (19 compare-exchanges), as in the GLSL.
pub const SORT8: [(usize, usize); 19] = [
    (0, 1),
    (2, 3),
    (4, 5),
    (6, 7),
    (0, 2),
    (1, 3),
    (4, 6),
    (5, 7),
    (1, 2),
    (5, 6),
    (0, 4),
    (3, 7),
    (1, 5),
    (2, 6),
    (1, 4),
    (3, 6),
    (2, 4),
    (3, 5),
    (3, 4),
];
