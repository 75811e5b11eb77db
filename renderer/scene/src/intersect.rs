//! The CPU ray–triangle reference: the watertight test of Woop, Benthin & Wald, "Watertight
//! Ray/Triangle Intersection", JCGT 2(1), 2013, in the same single-precision form the GLSL tracer
//! uses (no double-precision fallback for edge functions that are exactly 0: an edge-on hit then
//! counts as inside on both triangles sharing the edge, which keeps the test watertight).
//!
//! Hits are accepted for `0 < t < t_max`, two-sided (no back-face culling).
//!
//! **Ties.** The closest hit is the smallest `(t, triangle index)` pair: among hits at exactly the
//! same `t` (a ray through a shared edge or vertex) the lowest original triangle index wins. Both
//! [`brute_force`] and [`crate::bvh::Bvh::intersect`] follow this rule, so they agree exactly; the
//! GPU traversal should compare `t < best_t || (t == best_t && id < best_id)` to match.

use glam::Vec3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    /// Need not be normalised; `t` is measured in units of `dir`.
    pub dir: Vec3,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    /// Original triangle index (the input order of the triangle array).
    pub triangle: u32,
    /// Barycentric weight of v1.
    pub u: f32,
    /// Barycentric weight of v2.
    pub v: f32,
}

impl Hit {
    /// The closest-hit order: smaller t first, then smaller triangle index.
    pub fn is_closer_than(&self, other: &Hit) -> bool {
        self.t < other.t || (self.t == other.t && self.triangle < other.triangle)
    }
}

/// Per-ray constants of the watertight test (axis permutation and shear), computed once per ray.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay {
    origin: Vec3,
    kx: usize,
    ky: usize,
    kz: usize,
    sx: f32,
    sy: f32,
    sz: f32,
}

impl WatertightRay {
    pub fn new(ray: &Ray) -> WatertightRay {
        let d = ray.dir;
        let abs = d.abs();
        // kz: the dimension where |dir| is largest; kx, ky follow cyclically. Ties resolve exactly
        // as in shaders/common/bvh.glsl (strict comparisons), so both pick the same permutation.
        let kz = if abs.x > abs.y {
            if abs.x > abs.z {
                0
            } else {
                2
            }
        } else if abs.y > abs.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky); // preserve the winding of the triangle's edges
        }
        WatertightRay {
            origin: ray.origin,
            kx,
            ky,
            kz,
            sx: d[kx] / d[kz],
            sy: d[ky] / d[kz],
            sz: 1.0 / d[kz],
        }
    }

    /// Returns `(t, u, v)` with u, v the barycentric weights of v1 and v2.
    #[inline]
    pub fn intersect(&self, v0: Vec3, v1: Vec3, v2: Vec3, t_max: f32) -> Option<(f32, f32, f32)> {
        let (kx, ky, kz) = (self.kx, self.ky, self.kz);
        let a = v0 - self.origin;
        let b = v1 - self.origin;
        let c = v2 - self.origin;
        // Shear and scale the vertices into ray space (the ray becomes the +z axis).
        let ax = a[kx] - self.sx * a[kz];
        let ay = a[ky] - self.sy * a[kz];
        let bx = b[kx] - self.sx * b[kz];
        let by = b[ky] - self.sy * b[kz];
        let cx = c[kx] - self.sx * c[kz];
        let cy = c[ky] - self.sy * c[kz];
        // Scaled barycentrics (edge functions): eu weights v0, ev weights v1, ew weights v2.
        let eu = cx * by - cy * bx;
        let ev = ax * cy - ay * cx;
        let ew = bx * ay - by * ax;
        if (eu < 0.0 || ev < 0.0 || ew < 0.0) && (eu > 0.0 || ev > 0.0 || ew > 0.0) {
            return None;
        }
        let det = eu + ev + ew;
        if det == 0.0 {
            return None;
        }
        // Same operation order as the GLSL (Sz applied after the sum), so t rounds the same way.
        let t_scaled = self.sz * (eu * a[kz] + ev * b[kz] + ew * c[kz]);
        let rcp = 1.0 / det;
        let t = t_scaled * rcp;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        Some((t, ev * rcp, ew * rcp))
    }
}

/// Watertight, two-sided ray–triangle test; `(t, u, v)` for a hit with `0 < t < t_max`.
pub fn intersect_triangle(
    ray: &Ray,
    v0: Vec3,
    v1: Vec3,
    v2: Vec3,
    t_max: f32,
) -> Option<(f32, f32, f32)> {
    WatertightRay::new(ray).intersect(v0, v1, v2, t_max)
}

/// Tests every triangle. Closest hit by the tie rule in the module doc; with `any_hit` the first
/// hit in index order (any hit is a correct answer for a shadow ray).
pub fn brute_force(tris: &[[Vec3; 3]], ray: &Ray, t_max: f32, any_hit: bool) -> Option<Hit> {
    let wray = WatertightRay::new(ray);
    let mut best: Option<Hit> = None;
    for (i, tri) in tris.iter().enumerate() {
        if let Some((t, u, v)) = wray.intersect(tri[0], tri[1], tri[2], t_max) {
            let hit = Hit {
                t,
                triangle: i as u32,
                u,
                v,
            };
            if any_hit {
                return Some(hit);
            }
            if best.is_none_or(|b| hit.is_closer_than(&b)) {
                best = Some(hit);
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    const TRI: [Vec3; 3] = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];

    #[test]
    fn hit_distance_and_barycentrics_from_both_sides() {
        for (origin, dir) in [
            (Vec3::new(0.25, 0.5, 2.0), Vec3::new(0.0, 0.0, -1.0)),
            (Vec3::new(0.25, 0.5, -4.0), Vec3::new(0.0, 0.0, 2.0)),
        ] {
            let ray = Ray { origin, dir };
            let (t, u, v) =
                intersect_triangle(&ray, TRI[0], TRI[1], TRI[2], f32::INFINITY).expect("hit");
            assert!((t - 2.0).abs() < 1e-6, "t = {t}");
            assert!(
                (u - 0.25).abs() < 1e-6 && (v - 0.5).abs() < 1e-6,
                "u = {u}, v = {v}"
            );
        }
    }

    #[test]
    fn misses_outside_behind_and_beyond_t_max() {
        let down = Vec3::new(0.0, 0.0, -1.0);
        let outside = Ray {
            origin: Vec3::new(0.75, 0.75, 1.0),
            dir: down,
        };
        assert!(intersect_triangle(&outside, TRI[0], TRI[1], TRI[2], f32::INFINITY).is_none());
        let behind = Ray {
            origin: Vec3::new(0.2, 0.2, -1.0),
            dir: down,
        };
        assert!(intersect_triangle(&behind, TRI[0], TRI[1], TRI[2], f32::INFINITY).is_none());
        let short = Ray {
            origin: Vec3::new(0.2, 0.2, 1.0),
            dir: down,
        };
        assert!(
            intersect_triangle(&short, TRI[0], TRI[1], TRI[2], 1.0).is_none(),
            "t == t_max is a miss"
        );
        assert!(intersect_triangle(&short, TRI[0], TRI[1], TRI[2], 1.0001).is_some());
        let parallel = Ray {
            origin: Vec3::new(-1.0, 0.2, 0.0),
            dir: Vec3::X,
        };
        assert!(intersect_triangle(&parallel, TRI[0], TRI[1], TRI[2], f32::INFINITY).is_none());
    }

    #[test]
    fn shared_edge_ties_resolve_to_the_lower_triangle_index() {
        // Two triangles sharing the diagonal of the unit square; the ray hits the diagonal exactly.
        let tris = [
            [
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::ZERO,
            ],
            [
                Vec3::ZERO,
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
        ];
        let ray = Ray {
            origin: Vec3::new(0.5, 0.5, 1.0),
            dir: Vec3::new(0.0, 0.0, -1.0),
        };
        let hit =
            brute_force(&tris, &ray, f32::INFINITY, false).expect("an edge hit must not leak");
        assert_eq!(hit.triangle, 0);
        let reversed = [tris[1], tris[0]];
        assert_eq!(
            brute_force(&reversed, &ray, f32::INFINITY, false)
                .unwrap()
                .triangle,
            0
        );
    }
}
