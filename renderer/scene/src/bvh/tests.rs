use super::*;
use crate::intersect::{brute_force, Hit, Ray};
use crate::test_util::*;

const SPATIAL: BvhBuilder = BvhBuilder {
    spatial_budget: Some(0.5),
    ..BvhBuilder::BINNED
};

/// Every node reachable exactly once; every child box contains its subtree; leaves ≤ 8. Binned:
/// every triangle in exactly one leaf, inside the leaf box. Spatial: every triangle in at least
/// one leaf, the references within the budget, and every point of every triangle (a grid of
/// barycentric points, in f64) inside one of that triangle's leaf boxes (the clipped parts cover
/// the triangle).
fn check_invariants(bvh: &Bvh, tris: &[[Vec3; 3]], builder: BvhBuilder) {
    let mut leaf_boxes: Vec<Vec<Aabb>> = vec![Vec::new(); tris.len()];
    let mut stack = vec![0u32];
    let mut visited_nodes = 0;
    while let Some(node) = stack.pop() {
        visited_nodes += 1;
        let n = &bvh.nodes[node as usize];
        for slot in 0..2 {
            if n.is_empty_child(slot) {
                assert!(
                    n.child_bounds(slot).is_empty(),
                    "an empty child has the inverted box"
                );
                continue;
            }
            let bounds = n.child_bounds(slot);
            if n.child_count[slot] > 0 {
                assert!(
                    n.child_count[slot] as usize <= LEAF_MAX,
                    "leaf of {} triangles",
                    n.child_count[slot]
                );
                let start = n.child_ref[slot] as usize;
                for &t in &bvh.tri_order[start..start + n.child_count[slot] as usize] {
                    leaf_boxes[t as usize].push(bounds);
                }
            } else {
                let child = &bvh.nodes[n.child_ref[slot] as usize];
                for s in (0..2).filter(|&s| !child.is_empty_child(s)) {
                    let inner = child.child_bounds(s);
                    assert!(
                        bounds.contains_point(inner.min) && bounds.contains_point(inner.max),
                        "child box contains grandchildren"
                    );
                }
                stack.push(n.child_ref[slot]);
            }
        }
    }
    assert_eq!(
        visited_nodes,
        bvh.nodes.len(),
        "every node is reachable exactly once"
    );
    assert_eq!(
        leaf_boxes.iter().map(Vec::len).sum::<usize>(),
        bvh.tri_order.len(),
        "every reference is in a leaf"
    );
    match builder.spatial_budget {
        None => {
            assert!(
                leaf_boxes.iter().all(|b| b.len() == 1),
                "every triangle in exactly one leaf"
            );
            for (t, boxes) in tris.iter().zip(&leaf_boxes) {
                t.iter().for_each(|&p| {
                    assert!(
                        boxes[0].contains_point(p),
                        "leaf box contains its triangles"
                    )
                });
            }
        }
        Some(budget) => {
            assert!(
                leaf_boxes.iter().all(|b| !b.is_empty()),
                "every triangle in some leaf"
            );
            let limit = tris.len() + (tris.len() as f64 * budget as f64) as usize;
            assert!(
                bvh.tri_order.len() <= limit,
                "{} references over the budget's {limit}",
                bvh.tri_order.len()
            );
            const STEPS: usize = 8;
            for (i, (t, boxes)) in tris.iter().zip(&leaf_boxes).enumerate() {
                let v = t.map(|p| [p.x as f64, p.y as f64, p.z as f64]);
                for a in 0..=STEPS {
                    for b in 0..=STEPS - a {
                        let (wa, wb) = (a as f64 / STEPS as f64, b as f64 / STEPS as f64);
                        let wc = 1.0 - wa - wb;
                        let p: [f64; 3] =
                            std::array::from_fn(|k| v[0][k] * wa + v[1][k] * wb + v[2][k] * wc);
                        let inside = |bx: &Aabb| {
                            (0..3).all(|k| {
                                let tol = 1e-9 * (p[k].abs() + 1.0);
                                p[k] >= bx.min[k] as f64 - tol && p[k] <= bx.max[k] as f64 + tol
                            })
                        };
                        assert!(
                            boxes.iter().any(inside),
                            "triangle {i}: point {p:?} in none of its {} leaf boxes",
                            boxes.len()
                        );
                    }
                }
            }
        }
    }
}

/// The 4-wide tree holds exactly the binary tree's leaves; every node is reachable once, every
/// child box contains its children's boxes, every node but a lone root has ≥ 2 children, and
/// there are fewer wide nodes than binary ones.
fn check_wide(bvh: &Bvh, wide: &wide::Bvh4) {
    let leaves = |list: &mut Vec<(u32, u32, [u32; 6])>, min: Vec3, max: Vec3, r: u32, c: u32| {
        list.push((
            r,
            c,
            [min.x, min.y, min.z, max.x, max.y, max.z].map(f32::to_bits),
        ));
    };
    let mut binary = Vec::new();
    for n in &bvh.nodes {
        for s in (0..2).filter(|&s| n.child_count[s] > 0) {
            leaves(
                &mut binary,
                n.child_min[s],
                n.child_max[s],
                n.child_ref[s],
                n.child_count[s],
            );
        }
    }
    let (mut four, mut visited, mut stack) = (Vec::new(), 0, vec![0u32]);
    while let Some(node) = stack.pop() {
        visited += 1;
        let n = &wide.nodes[node as usize];
        let used = (0..wide::WIDTH).filter(|&s| !n.is_empty_child(s)).count();
        assert!(
            used >= 2 || (node == 0 && bvh.nodes.len() == 1),
            "node {node} has {used} children"
        );
        for s in (0..wide::WIDTH).filter(|&s| !n.is_empty_child(s)) {
            if n.child_count[s] > 0 {
                leaves(
                    &mut four,
                    n.child_min[s],
                    n.child_max[s],
                    n.child_ref[s],
                    n.child_count[s],
                );
            } else {
                let (outer, child) = (n.child_bounds(s), &wide.nodes[n.child_ref[s] as usize]);
                for g in (0..wide::WIDTH).filter(|&g| !child.is_empty_child(g)) {
                    let inner = child.child_bounds(g);
                    assert!(
                        outer.contains_point(inner.min) && outer.contains_point(inner.max),
                        "wide child box contains its children"
                    );
                }
                stack.push(n.child_ref[s]);
            }
        }
    }
    assert_eq!(
        visited,
        wide.nodes.len(),
        "every wide node reachable exactly once"
    );
    binary.sort_unstable();
    four.sort_unstable();
    assert_eq!(binary, four, "the wide tree has the binary tree's leaves");
    assert_eq!(wide.tri_order, bvh.tri_order);
    assert!(
        wide.nodes.len() < bvh.nodes.len() || bvh.nodes.len() == 1,
        "{} wide nodes for {} binary",
        wide.nodes.len(),
        bvh.nodes.len()
    );
}

/// The BVH must report the brute-force hit. When a ray passes exactly through an edge or vertex,
/// both neighbours may report a hit at the same t and box culling can hide the lower-indexed one
/// from the BVH; then the BVH's triangle must be a genuine tie (hit by the ray at the same t).
fn assert_same_hit(
    name: &str,
    tris: &[[Vec3; 3]],
    ray: &Ray,
    t_max: f32,
    got: Option<Hit>,
    expected: Option<Hit>,
) {
    match (got, expected) {
        (Some(g), Some(e)) if g.triangle != e.triangle => {
            let [a, b, c] = tris[g.triangle as usize];
            let tie = crate::intersect::intersect_triangle(ray, a, b, c, t_max);
            assert!(
                tie.is_some_and(|(t, _, _)| (t - e.t).abs() <= 1e-6 * e.t),
                "{name}: {ray:?}: BVH {g:?}, brute force {e:?}"
            );
        }
        _ => assert_eq!(got, expected, "{name}: {ray:?} t_max {t_max}"),
    }
}

/// The compressed tree: the binary tree's references, every node reached once from its parent's
/// child base, leaf slots of ≤ 3 consecutive entries within the node's ≤ 24, the slot meta and
/// interior mask agreeing, and (binned trees, whose leaves hold whole triangles) every leaf
/// triangle inside the decoded box of its slot and of every ancestor's slot. The stack bound is
/// at least the depth below the root.
fn check_compressed(bvh: &Bvh, tris: &[[Vec3; 3]], eight: &compressed::Bvh8, builder: BvhBuilder) {
    use compressed::{LEAF_MAX as SLOT_MAX, WIDTH as W8};
    let sorted = |v: &[u32]| {
        let mut v = v.to_vec();
        v.sort_unstable();
        v
    };
    assert_eq!(
        sorted(&eight.tri_order),
        sorted(&bvh.tri_order),
        "the same leaf references"
    );
    let mut reached = vec![0u32; eight.nodes.len()];
    reached[0] = 1;
    let mut entries_seen = 0usize;
    let mut stack: Vec<(u32, Vec<Aabb>)> = vec![(0, Vec::new())];
    while let Some((node, ancestors)) = stack.pop() {
        let n = &eight.nodes[node as usize];
        let mut rank = 0;
        let mut next_offset = 0;
        for slot in 0..W8 {
            let meta = n.meta[slot];
            assert_eq!(
                n.is_interior(slot),
                meta == 0x20 | (24 + slot as u8),
                "node {node} slot {slot}: meta {meta:#x}, imask {:#b}",
                n.imask
            );
            let bounds = n.child_bounds(slot);
            let mut chain = ancestors.clone();
            chain.push(bounds);
            if n.is_interior(slot) {
                let child = n.child_base + rank;
                rank += 1;
                reached[child as usize] += 1;
                stack.push((child, chain));
            } else if let Some((offset, count)) = n.leaf(slot) {
                assert!((1..=SLOT_MAX as u32).contains(&count));
                assert_eq!(offset, next_offset, "node {node}: leaf entries consecutive");
                next_offset += count;
                for e in offset..offset + count {
                    let tri = eight.tri_order[(n.triangle_base + e) as usize];
                    entries_seen += 1;
                    if builder.spatial_budget.is_none() {
                        let b = Aabb::of_points(&tris[tri as usize]);
                        for outer in &chain {
                            assert!(
                                outer.contains_point(b.min) && outer.contains_point(b.max),
                                "triangle {tri} outside a decoded box {outer:?}"
                            );
                        }
                    }
                }
            } else {
                assert_eq!(meta, 0, "node {node} slot {slot} is empty");
            }
        }
        assert!(next_offset <= 24);
    }
    assert!(
        reached.iter().all(|&r| r == 1),
        "every node reached exactly once"
    );
    assert_eq!(entries_seen, eight.tri_order.len());
    assert!(eight.max_stack() >= eight.depth().saturating_sub(1));
}

#[test]
fn quantised_boxes_decode_exactly_and_contain_the_child() {
    let mut rng = TestRng::new(11);
    for i in 0..4000 {
        // Boxes from 1e-6 to 1e5 wide anywhere from the origin to 1e6 away from it.
        let scale = 10f32.powf(rng.range(-6.0, 5.0));
        let offset = rng.vec3(-1.0, 1.0) * 10f32.powf(rng.range(-3.0, 6.0));
        let tris: Vec<[Vec3; 3]> = (0..6)
            .map(|_| {
                let c = offset + rng.vec3(-scale, scale);
                [
                    c,
                    c + rng.vec3(0.0, scale * 0.1),
                    c - rng.vec3(0.0, scale * 0.1),
                ]
            })
            .collect();
        let bvh = Bvh::build_with(&tris, BvhBuilder::BINNED);
        let eight = compressed::Bvh8::from_binary(&bvh, &tris);
        for n in &eight.nodes {
            for slot in (0..compressed::WIDTH).filter(|&s| n.meta[s] != 0) {
                let b = n.child_bounds(slot);
                for axis in 0..3 {
                    let scale = 2f64.powi(i32::from(n.exponent[axis]) - 127);
                    for (q, plane) in [
                        (n.lo[axis][slot], b.min[axis]),
                        (n.hi[axis][slot], b.max[axis]),
                    ] {
                        let exact = f64::from(n.origin[axis]) + f64::from(q) * scale;
                        assert_eq!(f64::from(plane), exact, "box {i}: plane not exact");
                    }
                }
            }
        }
        check_compressed(&bvh, &tris, &eight, BvhBuilder::BINNED);
    }
}

#[test]
fn compressed_tree_of_nothing_and_of_one_triangle() {
    let ray = Ray {
        origin: Vec3::new(0.2, 0.2, 1.0),
        dir: Vec3::NEG_Z,
    };
    let empty = compressed::Bvh8::from_binary(&Bvh::build(&[]), &[]);
    assert_eq!(empty.nodes.len(), 1);
    assert!(empty.intersect(&[], &ray, f32::INFINITY, false).is_none());
    let one = [[Vec3::ZERO, Vec3::X, Vec3::Y]];
    let eight = compressed::Bvh8::from_binary(&Bvh::build(&one), &one);
    assert_eq!(
        (eight.nodes.len(), eight.tri_order.as_slice()),
        (1, &[0u32][..])
    );
    assert_eq!(
        eight
            .intersect(&one, &ray, f32::INFINITY, false)
            .map(|h| h.triangle),
        Some(0)
    );
    assert_eq!(eight.depth(), 1);
}

/// On the same rays the compressed tree reads fewer bytes than the 4-wide one (80-byte nodes,
/// fewer of them) and opens fewer nodes: what the GPU-shaped traversal is for.
#[test]
fn compressed_tree_reads_fewer_bytes_than_the_four_wide_one() {
    let tris = sphere(Vec3::ZERO, 1.0, 64, 128);
    let bvh = Bvh::build(&tris);
    let (four, eight) = (
        wide::Bvh4::from_binary(&bvh),
        compressed::Bvh8::from_binary(&bvh, &tris),
    );
    let mut rng = TestRng::new(12);
    let (mut s4, mut s8) = (TraceState::default(), TraceState::default());
    for _ in 0..2000 {
        let origin = rng.unit_vector() * 3.0;
        let ray = Ray {
            origin,
            dir: rng.vec3(-0.5, 0.5) - origin,
        };
        s4.best = None;
        s8.best = None;
        four.intersect_into(&tris, &ray, f32::INFINITY, false, 0, &mut s4);
        eight.intersect_into(&tris, &ray, f32::INFINITY, false, 0, &mut s8);
        assert_eq!(s4.best.map(|h| h.t), s8.best.map(|h| h.t));
    }
    assert!(
        s8.counts.nodes < s4.counts.nodes,
        "{:?} vs {:?}",
        s8.counts,
        s4.counts
    );
    assert!(
        s8.counts.bytes < s4.counts.bytes,
        "{:?} vs {:?}",
        s8.counts,
        s4.counts
    );
}

/// Random rays that mostly point at the mesh, plus a few random ones.
fn compare_with_brute_force(name: &str, tris: &[[Vec3; 3]], rays: usize, seed: u64) {
    for builder in [BvhBuilder::BINNED, SPATIAL] {
        compare_builder_with_brute_force(name, tris, rays, seed, builder);
    }
}

fn compare_builder_with_brute_force(
    name: &str,
    tris: &[[Vec3; 3]],
    rays: usize,
    seed: u64,
    builder: BvhBuilder,
) {
    let bvh = Bvh::build_with(tris, builder);
    check_invariants(&bvh, tris, builder);
    let wide = wide::Bvh4::from_binary(&bvh);
    check_wide(&bvh, &wide);
    let eight = compressed::Bvh8::from_binary(&bvh, tris);
    check_compressed(&bvh, tris, &eight, builder);
    let name = &format!("{name} ({})", builder.name());
    let bounds = Aabb::of_points(&tris.iter().flatten().copied().collect::<Vec<_>>());
    let (center, radius) = (bounds.center(), bounds.bounding_sphere_radius().max(1e-3));
    let mut rng = TestRng::new(seed);
    let mut hits = 0;
    for i in 0..rays {
        let origin = center + rng.unit_vector() * radius * rng.range(0.2, 2.0);
        let target = center + rng.vec3(-radius, radius) * 0.5;
        let dir = if i % 8 == 0 {
            rng.unit_vector()
        } else {
            target - origin
        };
        let ray = Ray { origin, dir };
        let t_max = if i % 5 == 0 {
            rng.range(0.1, 1.0)
        } else {
            f32::INFINITY
        };
        let expected = brute_force(tris, &ray, t_max, false);
        let got = bvh.intersect(tris, &ray, t_max, false);
        assert_same_hit(name, tris, &ray, t_max, got, expected);
        assert_same_hit(
            &format!("{name} 4-wide"),
            tris,
            &ray,
            t_max,
            wide.intersect(tris, &ray, t_max, false),
            expected,
        );
        assert_same_hit(
            &format!("{name} 8-wide"),
            tris,
            &ray,
            t_max,
            eight.intersect(tris, &ray, t_max, false),
            expected,
        );
        for any in [
            bvh.intersect(tris, &ray, t_max, true),
            wide.intersect(tris, &ray, t_max, true),
            eight.intersect(tris, &ray, t_max, true),
        ] {
            assert_eq!(any.is_some(), expected.is_some(), "{name}: any-hit ray {i}");
            if let Some(h) = any {
                assert!(h.t > 0.0 && h.t < t_max);
            }
        }
        hits += expected.is_some() as usize;
    }
    assert!(
        hits > rays / 20,
        "{name}: only {hits} of {rays} rays hit; the test would prove little"
    );
}

#[test]
fn bvh_equals_brute_force_on_a_sphere() {
    compare_with_brute_force(
        "sphere",
        &sphere(Vec3::new(0.3, -0.2, 1.0), 1.5, 24, 48),
        3000,
        1,
    );
}

#[test]
fn bvh_equals_brute_force_on_a_triangle_soup() {
    let mut rng = TestRng::new(2);
    compare_with_brute_force("soup", &triangle_soup(&mut rng, 3000, 2.0, 0.3), 3000, 3);
}

#[test]
fn bvh_equals_brute_force_on_slivers() {
    let mut rng = TestRng::new(4);
    compare_with_brute_force("slivers", &slivers(&mut rng, 20000), 3000, 5);
}

#[test]
fn bvh_equals_brute_force_on_the_bunny() {
    if let Some(bunny) = bunny() {
        assert_eq!(bunny.len(), 3674);
        compare_with_brute_force("bunny", &bunny, 3000, 6);
    }
}

#[test]
fn bvh_handles_coincident_and_tiny_inputs() {
    let same = vec![[Vec3::ZERO, Vec3::X, Vec3::Y]; 40]; // identical centroids force median splits
    compare_with_brute_force("coincident", &same, 200, 7);
    let empty = Bvh::build(&[]);
    assert_eq!(empty.nodes.len(), 1);
    assert!(empty
        .intersect(
            &[],
            &Ray {
                origin: Vec3::ZERO,
                dir: Vec3::X
            },
            f32::INFINITY,
            false
        )
        .is_none());
    let one = [[Vec3::ZERO, Vec3::X, Vec3::Y]];
    let bvh = Bvh::build(&one);
    assert_eq!(
        (
            bvh.nodes.len(),
            bvh.nodes[0].child_count,
            bvh.nodes[0].child_ref
        ),
        (1, [1, 0], [0, 0])
    );
    assert_eq!(bvh.nodes[0].child_min[1], Vec3::splat(1e30));
    assert_eq!(bvh.nodes[0].child_max[1], Vec3::splat(-1e30));
    assert_eq!(bvh.depth(), 1);
}

/// Rays aimed exactly at grid vertices and edges of a tessellated plane, from many directions,
/// including axis-parallel ones: a watertight test never lets one through.
#[test]
fn rays_through_shared_edges_and_vertices_never_leak() {
    let n = 8;
    let tris = quad_grid(n);
    for builder in [BvhBuilder::BINNED, SPATIAL] {
        edges_and_vertices_never_leak(&tris, builder, n);
    }
}

fn edges_and_vertices_never_leak(tris: &[[Vec3; 3]], builder: BvhBuilder, n: u32) {
    let bvh = Bvh::build_with(tris, builder);
    check_invariants(&bvh, tris, builder);
    let wide = wide::Bvh4::from_binary(&bvh);
    check_wide(&bvh, &wide);
    let eight = compressed::Bvh8::from_binary(&bvh, tris);
    check_compressed(&bvh, tris, &eight, builder);
    let mut rng = TestRng::new(8);
    let mut tested = 0;
    for gy in 1..n * 2 {
        for gx in 1..n * 2 {
            // Half-integer steps: grid vertices, edge midpoints and quad centres (diagonals).
            let target = Vec3::new(gx as f32 * 0.5, gy as f32 * 0.5, 0.0);
            for k in 0..6 {
                let dir = match k {
                    0 => Vec3::new(0.0, 0.0, -1.0),
                    1 => Vec3::new(0.0, 0.0, 1.0),
                    _ => {
                        let mut d = rng.unit_vector();
                        d.z = -d.z.abs().max(0.05);
                        d
                    }
                };
                let origin = target - dir * rng.range(0.5, 4.0);
                let ray = Ray { origin, dir };
                let expected = brute_force(tris, &ray, f32::INFINITY, false);
                assert!(expected.is_some(), "leak at {target:?} dir {dir:?}");
                assert_same_hit(
                    "grid",
                    tris,
                    &ray,
                    f32::INFINITY,
                    bvh.intersect(tris, &ray, f32::INFINITY, false),
                    expected,
                );
                assert_same_hit(
                    "grid 4-wide",
                    tris,
                    &ray,
                    f32::INFINITY,
                    wide.intersect(tris, &ray, f32::INFINITY, false),
                    expected,
                );
                assert_same_hit(
                    "grid 8-wide",
                    tris,
                    &ray,
                    f32::INFINITY,
                    eight.intersect(tris, &ray, f32::INFINITY, false),
                    expected,
                );
                tested += 1;
            }
        }
    }
    assert!(tested > 1000);
}

#[test]
fn texels_follow_the_gpu_layout() {
    let tris = sphere(Vec3::ZERO, 1.0, 8, 16);
    let bvh = Bvh::build_with(&tris, BvhBuilder::BINNED);
    let tex = bvh.triangle_texels(&tris);
    assert_eq!(tex.len(), tris.len() * 3);
    for (k, &orig) in bvh.tri_order.iter().enumerate() {
        assert_eq!(tex[k * 3][3].to_bits(), orig);
        for c in 0..3 {
            assert_eq!(&tex[k * 3 + c][..3], &tris[orig as usize][c].to_array()[..]);
        }
    }
    assert_eq!(bvh.memory_bytes(), bvh.nodes.len() * 64 + tris.len() * 48);
    let wide = wide::Bvh4::from_binary(&bvh);
    let texels = wide.node_texels();
    assert_eq!(texels.len(), wide.nodes.len() * 8);
    for (i, n) in wide.nodes.iter().enumerate() {
        let t = &texels[i * 8..i * 8 + 8];
        for (c, (lo, hi)) in n.child_min.iter().zip(&n.child_max).enumerate() {
            assert_eq!([t[0][c], t[1][c], t[2][c]], lo.to_array());
            assert_eq!([t[3][c], t[4][c], t[5][c]], hi.to_array());
            assert_eq!(
                [t[6][c].to_bits(), t[7][c].to_bits()],
                [n.child_ref[c], n.child_count[c]]
            );
        }
    }
    assert_eq!(
        wide.memory_bytes(),
        wide.nodes.len() * 128 + tris.len() * 48
    );
    assert!(
        wide.max_stack() >= wide.depth() - 1 && wide.max_stack() <= 3 * (wide.depth() - 1),
        "{} {}",
        wide.max_stack(),
        wide.depth()
    );
    assert!(wide.depth() < bvh.depth());
}

/// Build rate on ≥ 250k triangles. Timing is printed, not asserted (shared machine); run with
/// `cargo test -p fovea-scene --release -- --ignored --nocapture bvh_build_rate`.
#[test]
#[ignore]
fn bvh_build_rate() {
    let mut tris = Vec::new();
    for i in 0..64 {
        tris.extend(sphere(
            Vec3::new((i % 8) as f32 * 3.0, 0.0, (i / 8) as f32 * 3.0),
            1.0,
            45,
            45,
        ));
    }
    let mut rng = TestRng::new(9);
    tris.extend(triangle_soup(&mut rng, 10_000, 12.0, 0.2));
    let start = std::time::Instant::now();
    let bvh = Bvh::build(&tris);
    let secs = start.elapsed().as_secs_f64();
    println!(
        "BVH: {} triangles in {:.3} s = {:.2} M tris/s; {} nodes, depth {}, {:.1} MiB on the GPU",
        tris.len(),
        secs,
        tris.len() as f64 / secs / 1e6,
        bvh.nodes.len(),
        bvh.depth(),
        bvh.memory_bytes() as f64 / (1 << 20) as f64
    );
    check_invariants(&bvh, &tris, BvhBuilder::DEFAULT);
}

#[test]
fn stats_count_the_tree() {
    let one = [[Vec3::ZERO, Vec3::X, Vec3::Y]];
    let s = Bvh::build(&one).stats(&one);
    assert_eq!(
        (
            s.nodes,
            s.leaves,
            s.references,
            s.depth,
            s.leaf_sizes.clone()
        ),
        (1, 1, 1, 1, vec![0, 1])
    );
    // The root node's visit (1) plus one triangle test in a leaf as large as the root.
    assert!(
        (s.sah_cost - 2.0).abs() < 1e-9 && (s.sah_node_cost - 1.0).abs() < 1e-9,
        "{s:?}"
    );
    assert_eq!(
        (s.thin_triangles, s.large_triangles, s.mean_child_overlap),
        (0, 1, 0.0)
    );
    let thin = [
        [Vec3::ZERO, Vec3::new(100.0, 0.0, 0.0), Vec3::Y],
        [Vec3::ZERO, Vec3::X, Vec3::Y],
    ];
    assert_eq!(Bvh::build(&thin).stats(&thin).thin_triangles, 1);

    let tris = sphere(Vec3::ZERO, 1.0, 24, 48);
    let bvh = Bvh::build_with(&tris, BvhBuilder::BINNED);
    let s = bvh.stats(&tris);
    assert_eq!(
        (s.nodes, s.references, s.depth),
        (bvh.nodes.len(), tris.len(), bvh.depth())
    );
    assert_eq!(s.leaf_sizes.iter().sum::<usize>(), s.leaves);
    assert_eq!(
        s.leaf_sizes
            .iter()
            .enumerate()
            .map(|(k, n)| k * n)
            .sum::<usize>(),
        s.references
    );
    assert!(
        s.leaves > tris.len() / LEAF_MAX
            && s.mean_leaf_depth > 2.0
            && s.mean_leaf_depth <= s.depth as f64 + 1.0
    );
    assert!(
        s.sah_node_cost > 1.0
            && s.sah_cost > s.sah_node_cost
            && s.mean_child_overlap > 0.0
            && s.mean_child_overlap < 1.0
    );
}

/// Long thin triangles lying diagonally in one plane (a floor of slivers) are where spatial
/// splits pay: the SBVH must duplicate some references (within the budget) and find a tree of
/// lower SAH cost than object splits.
#[test]
fn spatial_splits_lower_the_sah_cost_of_slivers() {
    let mut rng = TestRng::new(10);
    let tris: Vec<[Vec3; 3]> = (0..3000)
        .map(|_| {
            let c = Vec3::new(rng.range(-5.0, 5.0), rng.range(-5.0, 5.0), 0.0);
            let d = Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), 0.0)
                .normalize_or(Vec3::X)
                * 2.0;
            [c - d, c + d, c + Vec3::new(-d.y, d.x, 0.0) * 0.01]
        })
        .collect();
    let binned = Bvh::build_with(&tris, BvhBuilder::BINNED).stats(&tris);
    let spatial_bvh = Bvh::build_with(&tris, SPATIAL);
    check_invariants(&spatial_bvh, &tris, SPATIAL);
    let spatial = spatial_bvh.stats(&tris);
    assert!(spatial.references > tris.len(), "no reference was split");
    assert!(
        spatial.sah_cost < binned.sah_cost * 0.9,
        "SAH cost {} (SBVH) vs {} (binned)",
        spatial.sah_cost,
        binned.sah_cost
    );
    // No budget, no duplicates: the spatial builder then makes a plain object-split tree.
    let none = BvhBuilder {
        spatial_budget: Some(0.0),
        ..BvhBuilder::BINNED
    };
    let bvh = Bvh::build_with(&tris, none);
    check_invariants(&bvh, &tris, none);
    let mut order = bvh.tri_order.clone();
    order.sort_unstable();
    assert_eq!(order, (0..tris.len() as u32).collect::<Vec<_>>());
}

#[test]
fn clipping_rounds_outwards() {
    for f in [1.0f32, -1.0, 0.0, 3.5e-3, -7.25e8] {
        assert!(sbvh::step(f, 1.0) > f && sbvh::step(f, -1.0) < f, "{f}");
        assert_eq!(sbvh::step(sbvh::step(f, 1.0), -1.0), f, "{f}");
    }
    // A triangle cut by the plane x = 0.3 at irrational-ish points: the f32 box must contain the
    // f64 crossing points.
    let t = [
        Vec3::new(0.0, 0.1, 0.7),
        Vec3::new(1.0, 0.35, -0.2),
        Vec3::new(0.6, 0.9, 0.33),
    ];
    let left = sbvh::clip_triangle(&t, 0, f32::NEG_INFINITY, 0.3);
    let (a, b) = ([0.0f64, 0.1, 0.7], [1.0f64, 0.35, -0.2]);
    let s = (0.3f32 as f64 - a[0]) / (b[0] - a[0]);
    let p = [a[1] + (b[1] - a[1]) * s, a[2] + (b[2] - a[2]) * s];
    assert!(left.max.x == 0.3 && left.min.x == 0.0);
    assert!(
        (left.min.y as f64) <= p[0]
            && (left.max.y as f64) >= p[0]
            && (left.min.z as f64) <= p[1]
            && (left.max.z as f64) >= p[1]
    );
    assert!(
        sbvh::clip_triangle(&t, 0, 2.0, 3.0).min.x > sbvh::clip_triangle(&t, 0, 2.0, 3.0).max.x,
        "a missed slab is empty"
    );
}

#[test]
fn builder_names_parse() {
    let leaf2 = BvhBuilder {
        spatial_budget: Some(0.25),
        leaf_target: 2,
        node_cost: 1.5,
    };
    for b in [
        BvhBuilder::BINNED,
        BvhBuilder {
            spatial_budget: Some(0.25),
            ..BvhBuilder::BINNED
        },
        leaf2,
    ] {
        assert_eq!(BvhBuilder::parse(&b.name()), Ok(b));
    }
    assert_eq!(leaf2.name(), "sbvh:0.25/leaf2/cost1.5");
    assert_eq!(BvhBuilder::parse("sbvh"), Ok(SPATIAL));
    for bad in [
        "",
        "sah",
        "sbvh:",
        "sbvh:-1",
        "sbvh:9",
        "sbvh:nan",
        "binned/leaf0",
        "binned/leaf9",
        "binned/cost0",
        "binned/x",
    ] {
        assert!(BvhBuilder::parse(bad).is_err(), "{bad}");
    }
}

/// The traversal's sorting network sorts every input (0–1 principle: all 256 binary inputs).
#[test]
fn sort8_network_sorts() {
    for bits in 0u32..256 {
        let mut keys: [u32; 8] = std::array::from_fn(|i| (bits >> i) & 1);
        for (a, b) in compressed::SORT8 {
            if keys[b] < keys[a] {
                keys.swap(a, b);
            }
        }
        assert!(
            keys.windows(2).all(|w| w[0] <= w[1]),
            "{bits:#010b} → {keys:?}"
        );
    }
}
