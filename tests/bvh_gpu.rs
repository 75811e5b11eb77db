//! GPU BVH traversal (shaders/common/bvh.glsl) equals the CPU brute-force watertight intersector
//! on thousands of random rays over several meshes: hit/miss, distance, primitive and
//! barycentrics, for both traversals (the CPU driver's 4-wide one and the GPU's compressed 8-wide
//! one); and the counting kernel counts what the CPU twin of each traversal reads.

use fovea_renderer::gpu_scene::GpuScene;
use fovea_renderer::layouts::RayGpu;
use fovea_renderer::passes::raycast::{RayCaster, RayCounts};
use fovea_renderer::traversal::Traversal;
use fovea_scene::bvh::compressed::Bvh8;
use fovea_scene::bvh::wide::Bvh4;
use fovea_scene::bvh::{Bvh, BvhBuilder, TraceState};
use fovea_scene::intersect::{brute_force, Ray};
use fovea_scene::{Material, Scene};
use fovea_tests::scenes::add_flat_triangle;
use fovea_tests::{assert_clean, gpu};
use glam::Vec3;

/// A deterministic generator (no external RNG needed for the test data).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32) / (1u64 << 24) as f32
    }
    fn in_box(&mut self, lo: Vec3, hi: Vec3) -> Vec3 {
        lo + (hi - lo) * Vec3::new(self.next(), self.next(), self.next())
    }
    fn direction(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(self.next(), self.next(), self.next()) * 2.0 - 1.0;
            if v.length_squared() > 1e-4 && v.length_squared() <= 1.0 {
                return v.normalize();
            }
        }
    }
}

fn scene_from_triangles(tris: &[[Vec3; 3]]) -> Scene {
    let mut scene = Scene {
        materials: vec![Material::default()],
        mesh_names: vec!["mesh".into()],
        ..Default::default()
    };
    for t in tris {
        add_flat_triangle(&mut scene, *t, 0);
    }
    scene
}

fn sphere(rings: u32, segments: u32, radius: f32, centre: Vec3) -> Vec<[Vec3; 3]> {
    let p = |r: u32, s: u32| {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        let phi = std::f32::consts::TAU * s as f32 / segments as f32;
        centre
            + radius
                * Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                )
    };
    let mut tris = Vec::new();
    for r in 0..rings {
        for s in 0..segments {
            let (a, b, c, d) = (p(r, s), p(r + 1, s), p(r + 1, s + 1), p(r, s + 1));
            tris.push([a, b, c]);
            tris.push([a, c, d]);
        }
    }
    tris
}

fn soup(rng: &mut Lcg, count: usize) -> Vec<[Vec3; 3]> {
    (0..count)
        .map(|_| {
            let c = rng.in_box(Vec3::splat(-2.0), Vec3::splat(2.0));
            [
                c + rng.direction() * 0.3,
                c + rng.direction() * 0.3,
                c + rng.direction() * 0.3,
            ]
        })
        .collect()
}

/// A grid of axis-aligned unit squares: rays through shared edges and vertices must not leak.
fn grid(n: u32) -> Vec<[Vec3; 3]> {
    let mut tris = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let (x, y) = (i as f32 - n as f32 / 2.0, j as f32 - n as f32 / 2.0);
            let q = [
                Vec3::new(x, y, 0.0),
                Vec3::new(x + 1.0, y, 0.0),
                Vec3::new(x + 1.0, y + 1.0, 0.0),
                Vec3::new(x, y + 1.0, 0.0),
            ];
            tris.push([q[0], q[1], q[2]]);
            tris.push([q[0], q[2], q[3]]);
        }
    }
    tris
}

fn bunny() -> Option<Vec<[Vec3; 3]>> {
    let path = fovea_tests::shared_data("bunny.ply")?;
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    let mut lines = text.lines();
    let (mut vertices, mut faces) = (0usize, 0usize);
    for line in lines.by_ref() {
        if let Some(n) = line.strip_prefix("element vertex ") {
            vertices = n.trim().parse().expect("bunny.ply: vertex count");
        } else if let Some(n) = line.strip_prefix("element face ") {
            faces = n.trim().parse().expect("bunny.ply: face count");
        } else if line == "end_header" {
            break;
        }
    }
    let pts: Vec<Vec3> = lines
        .by_ref()
        .take(vertices)
        .map(|l| {
            let v: Vec<f32> = l
                .split_whitespace()
                .take(3)
                .filter_map(|x| x.parse().ok())
                .collect();
            Vec3::new(v[0], v[1], v[2]) * 10.0
        })
        .collect();
    Some(
        lines
            .take(faces)
            .map(|l| {
                let i: Vec<usize> = l
                    .split_whitespace()
                    .skip(1)
                    .take(3)
                    .filter_map(|x| x.parse().ok())
                    .collect();
                [pts[i[0]], pts[i[1]], pts[i[2]]]
            })
            .collect(),
    )
}

/// Both builders' trees: the binned one (one leaf per triangle) and the SBVH (triangles split
/// across leaves, leaf boxes holding only their clipped parts); each traversal.
fn check_mesh(name: &str, tris: &[[Vec3; 3]], rays: &[Ray], any_hit: bool) {
    for builder in [
        BvhBuilder::BINNED,
        BvhBuilder {
            spatial_budget: Some(0.5),
            ..BvhBuilder::BINNED
        },
    ] {
        for traversal in Traversal::ALL {
            check_mesh_with(
                &format!(
                    "{name} ({}, {} traversal)",
                    builder.name(),
                    traversal.name()
                ),
                tris,
                rays,
                any_hit,
                builder,
                traversal,
            );
        }
    }
}

/// What the CPU twin of `traversal` reads for each ray (closest or any hit, `0 < t < 1e30`).
fn cpu_counts(
    traversal: Traversal,
    bvh: &Bvh,
    tris: &[[Vec3; 3]],
    rays: &[Ray],
    any_hit: bool,
) -> Vec<RayCounts> {
    let (four, eight) = match traversal {
        Traversal::CpuDriver => (Some(Bvh4::from_binary(bvh)), None),
        Traversal::Gpu => (None, Some(Bvh8::from_binary(bvh, tris))),
    };
    rays.iter()
        .map(|ray| {
            let mut state = TraceState::default();
            if let Some(four) = &four {
                four.intersect_into(tris, ray, 1e30, any_hit, 0, &mut state);
            }
            if let Some(eight) = &eight {
                eight.intersect_into(tris, ray, 1e30, any_hit, 0, &mut state);
            }
            RayCounts {
                nodes: state.counts.nodes as u32,
                triangles: state.counts.triangles as u32,
                alpha_tests: 0,
                bytes: state.counts.bytes as u32,
            }
        })
        .collect()
}

fn check_mesh_with(
    name: &str,
    tris: &[[Vec3; 3]],
    rays: &[Ray],
    any_hit: bool,
    builder: BvhBuilder,
    traversal: Traversal,
) {
    let ctx = gpu();
    let scene = scene_from_triangles(tris);
    let positions = scene.triangle_positions();
    let bvh = Bvh::build_with(&positions, builder);
    let gpu_scene = GpuScene::upload_for(&ctx, &scene, &positions, &bvh, traversal).unwrap();
    assert_eq!(gpu_scene.traversal, traversal);
    let mut caster = RayCaster::new(&ctx).unwrap();
    let gpu_rays: Vec<RayGpu> = rays
        .iter()
        .map(|r| RayGpu {
            origin_tmin: r.origin.extend(0.0),
            direction_tmax: r.dir.extend(1e30),
        })
        .collect();
    let (hits, _) = caster.trace(&gpu_scene, &gpu_rays, any_hit).unwrap();
    // The counting kernel finds the same hits and counts what the CPU twin reads, ray by ray
    // (the same algorithm on the same floats; a ray may differ where the device's arithmetic
    // rounds one box test the other way).
    let (counted_hits, counts) = caster
        .trace_counted(&gpu_scene, &gpu_rays, any_hit)
        .unwrap();
    assert_eq!(counted_hits, hits, "{name}: the counting kernel's hits");
    let expected = cpu_counts(traversal, &bvh, &positions, rays, any_hit);
    let differ = counts.iter().zip(&expected).filter(|(a, b)| a != b).count();
    assert!(
        differ * 200 <= rays.len(),
        "{name}: {differ} of {} rays count other reads than the CPU twin, e.g. {:?}",
        rays.len(),
        counts.iter().zip(&expected).find(|(a, b)| a != b)
    );
    let total = |c: &[RayCounts]| c.iter().map(|c| u64::from(c.nodes)).sum::<u64>();
    assert!(
        total(&counts) > rays.len() as u64,
        "{name}: nodes were counted"
    );
    let mut hit_count = 0;
    for (i, (ray, gpu_hit)) in rays.iter().zip(&hits).enumerate() {
        let cpu = brute_force(tris, ray, 1e30, false);
        let gpu_t = gpu_hit.t_u_v.x;
        match cpu {
            None => assert!(
                gpu_t < 0.0,
                "{name} ray {i}: GPU hit {gpu_t} where the CPU sees nothing"
            ),
            Some(h) => {
                hit_count += 1;
                assert!(
                    gpu_t >= 0.0,
                    "{name} ray {i}: GPU missed a hit at t = {}",
                    h.t
                );
                if any_hit {
                    continue; // any hit along the ray is a correct shadow answer
                }
                let tolerance = 1e-5 * h.t.max(1.0);
                assert!(
                    (gpu_t - h.t).abs() <= tolerance,
                    "{name} ray {i}: t {gpu_t} vs CPU {}",
                    h.t
                );
                let id = gpu_hit.triangle.x;
                if id == h.triangle {
                    let (u, v) = (gpu_hit.t_u_v.y, gpu_hit.t_u_v.z);
                    assert!(
                        (u - h.u).abs() <= 1e-5 && (v - h.v).abs() <= 1e-5,
                        "{name} ray {i}: barycentrics ({u}, {v}) vs CPU ({}, {})",
                        h.u,
                        h.v
                    );
                }
                if id != h.triangle {
                    // Equal distances may pick either triangle: the GPU's must be hit at that t too.
                    let other = brute_force(&tris[id as usize..id as usize + 1], ray, 1e30, false);
                    assert!(
                        other.is_some_and(|o| (o.t - h.t).abs() <= tolerance),
                        "{name} ray {i}: triangle {id} vs CPU {}",
                        h.triangle
                    );
                }
            }
        }
    }
    assert!(
        hit_count > rays.len() / 10,
        "{name}: too few hits ({hit_count}) for a meaningful test"
    );
    assert_clean(&ctx);
}

fn random_rays(rng: &mut Lcg, count: usize, origin_box: f32, aim_box: f32) -> Vec<Ray> {
    (0..count)
        .map(|_| {
            let origin = rng.in_box(Vec3::splat(-origin_box), Vec3::splat(origin_box));
            let target = rng.in_box(Vec3::splat(-aim_box), Vec3::splat(aim_box));
            Ray {
                origin,
                dir: (target - origin).normalize(),
            }
        })
        .collect()
}

#[test]
fn gpu_traversal_matches_brute_force_on_a_sphere() {
    let mut rng = Lcg(1);
    let rays = random_rays(&mut rng, 3000, 4.0, 1.0);
    check_mesh("sphere", &sphere(24, 48, 1.0, Vec3::ZERO), &rays, false);
}

#[test]
fn gpu_traversal_matches_brute_force_on_a_triangle_soup() {
    let mut rng = Lcg(2);
    let tris = soup(&mut rng, 2000);
    let rays = random_rays(&mut rng, 3000, 3.0, 2.0);
    check_mesh("soup", &tris, &rays, false);
    check_mesh("soup any-hit", &tris, &rays, true);
}

#[test]
fn gpu_traversal_is_watertight_on_shared_edges_and_vertices() {
    let tris = grid(8);
    let mut rays = Vec::new();
    for i in 0..=16 {
        for j in 0..=16 {
            // Aim exactly at edges and vertices of the grid, from above, straight and slanted.
            let target = Vec3::new(i as f32 * 0.5 - 4.0, j as f32 * 0.5 - 4.0, 0.0);
            for origin in [target + Vec3::Z * 3.0, target + Vec3::new(0.7, -0.4, 2.0)] {
                if target.x.abs() < 4.0 && target.y.abs() < 4.0 {
                    rays.push(Ray {
                        origin,
                        dir: (target - origin).normalize(),
                    });
                }
            }
        }
    }
    check_mesh("grid", &tris, &rays, false);
}

#[test]
fn gpu_traversal_matches_brute_force_on_the_bunny() {
    let Some(tris) = bunny() else {
        return;
    };
    assert_eq!(tris.len(), 3674, "the bunny of ../shared/data/README.md");
    let mut rng = Lcg(3);
    let rays = random_rays(&mut rng, 3000, 3.0, 0.8);
    check_mesh("bunny", &tris, &rays, false);
}
