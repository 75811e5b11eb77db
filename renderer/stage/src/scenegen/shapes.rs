//! Procedural meshes (positions, normals, UV0, triangle indices) and a seeded RNG.

use glam::{Mat3, Mat4, Vec2, Vec3};
use std::f32::consts::{PI, TAU};

#[derive(Clone, Debug, Default)]
pub struct MeshData {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub uvs: Vec<Vec2>,
    pub indices: Vec<u32>,
}

impl MeshData {
    /// Appends `other` transformed by `m` (normals by the inverse transpose).
    pub fn append(&mut self, other: &MeshData, m: Mat4) {
        let base = self.positions.len() as u32;
        let normal_matrix = Mat3::from_mat4(m).inverse().transpose();
        self.positions
            .extend(other.positions.iter().map(|&p| m.transform_point3(p)));
        self.normals.extend(
            other
                .normals
                .iter()
                .map(|&n| (normal_matrix * n).normalize()),
        );
        self.uvs.extend(&other.uvs);
        self.indices.extend(other.indices.iter().map(|i| i + base));
    }

    /// A grid of (rows+1)×(cols+1) vertices from `point(u, v)` with u, v in [0, 1]; triangles are
    /// wound so that `normal` (at each vertex) is the front side when ∂p/∂u × ∂p/∂v points along it.
    fn grid(
        rows: u32,
        cols: u32,
        uv_scale: Vec2,
        mut point: impl FnMut(f32, f32) -> (Vec3, Vec3),
    ) -> MeshData {
        let mut mesh = MeshData::default();
        for r in 0..=rows {
            for c in 0..=cols {
                let (u, v) = (c as f32 / cols as f32, r as f32 / rows as f32);
                let (p, n) = point(u, v);
                mesh.positions.push(p);
                mesh.normals.push(n);
                mesh.uvs.push(Vec2::new(u, v) * uv_scale);
            }
        }
        let stride = cols + 1;
        for r in 0..rows {
            for c in 0..cols {
                let i = r * stride + c;
                mesh.indices
                    .extend([i, i + 1, i + stride + 1, i, i + stride + 1, i + stride]);
            }
        }
        mesh
    }
}

/// Quad from `corner` spanning `u` and `v`, front side along u × v, `segments` per side.
pub fn quad(corner: Vec3, u: Vec3, v: Vec3, segments: u32, uv_scale: Vec2) -> MeshData {
    let n = u.cross(v).normalize();
    MeshData::grid(segments, segments, uv_scale, |a, b| {
        (corner + u * a + v * b, n)
    })
}

/// Axis-aligned box centred at the origin with outward faces (24 vertices, 12 triangles).
pub fn cuboid(size: Vec3) -> MeshData {
    let h = size * 0.5;
    let mut mesh = MeshData::default();
    let (x, y, z) = (Vec3::X * size.x, Vec3::Y * size.y, Vec3::Z * size.z);
    let faces = [
        (Vec3::new(h.x, -h.y, h.z), -z, y),  // +X
        (Vec3::new(-h.x, -h.y, -h.z), z, y), // −X
        (Vec3::new(-h.x, h.y, h.z), x, -z),  // +Y
        (Vec3::new(-h.x, -h.y, -h.z), x, z), // −Y
        (Vec3::new(-h.x, -h.y, h.z), x, y),  // +Z
        (Vec3::new(h.x, -h.y, -h.z), -x, y), // −Z
    ];
    for (corner, u, v) in faces {
        mesh.append(&quad(corner, u, v, 1, Vec2::ONE), Mat4::IDENTITY);
    }
    mesh
}

/// Cylinder along +Y from y = 0 to `height`, without caps; `flutes` > 0 carves that many
/// vertical grooves (classical column shafts) of relative depth `flute_depth`.
pub fn cylinder(
    radius: f32,
    height: f32,
    segments: u32,
    rings: u32,
    flutes: u32,
    flute_depth: f32,
) -> MeshData {
    let r_at = |a: f32| radius * (1.0 - flute_depth * (0.5 - 0.5 * (a * flutes as f32).cos()));
    MeshData::grid(
        rings,
        segments,
        Vec2::new(4.0, height / radius / 4.0),
        |u, v| {
            let a = -u * TAU; // negative so that ∂p/∂u × ∂p/∂v points outwards
            let r = r_at(a);
            let p = Vec3::new(r * a.cos(), v * height, r * a.sin());
            // Outward normal of the (possibly fluted) profile: rotate the profile tangent by 90°.
            let dr = (r_at(a + 1e-3) - r_at(a - 1e-3)) / 2e-3;
            let tangent = Vec3::new(dr * a.cos() - r * a.sin(), 0.0, dr * a.sin() + r * a.cos());
            (p, Vec3::Y.cross(tangent).normalize())
        },
    )
}

pub fn uv_sphere(radius: f32, rings: u32, segments: u32) -> MeshData {
    MeshData::grid(rings, segments, Vec2::new(2.0, 1.0), |u, v| {
        let (theta, phi) = (v * PI, -u * TAU);
        let n = Vec3::new(
            theta.sin() * phi.cos(),
            -theta.cos(),
            theta.sin() * phi.sin(),
        );
        (n * radius, n)
    })
}

/// Torus around +Y; `sweep` < 2π gives an arch (a partial torus) starting on +X.
pub fn torus(
    major: f32,
    minor: f32,
    major_segments: u32,
    minor_segments: u32,
    sweep: f32,
) -> MeshData {
    MeshData::grid(
        major_segments,
        minor_segments,
        Vec2::new(1.0, 4.0),
        |u, v| {
            let (a, b) = (v * sweep, -u * TAU);
            let centre = Vec3::new(a.cos(), 0.0, -a.sin()) * major;
            let n = Vec3::new(b.cos() * a.cos(), b.sin(), -b.cos() * a.sin());
            (centre + n * minor, n)
        },
    )
}

/// A sphere with smooth random bumps: a stand-in for organic scanned meshes (bunny-like blobs).
pub fn blob(radius: f32, rings: u32, segments: u32, rng: &mut SplitMix64) -> MeshData {
    let bumps: Vec<(Vec3, f32)> = (0..6)
        .map(|_| (rng.unit_vector(), rng.range(0.1, 0.35)))
        .collect();
    let height = |n: Vec3| {
        1.0 + bumps
            .iter()
            .map(|(d, h)| h * n.dot(*d).max(0.0).powi(3))
            .sum::<f32>()
    };
    let mut mesh = uv_sphere(1.0, rings, segments);
    for p in &mut mesh.positions {
        *p = *p * height(p.normalize()) * radius;
    }
    recompute_normals(&mut mesh);
    mesh
}

/// Smooth area-weighted normals (after displacing vertices).
pub fn recompute_normals(mesh: &mut MeshData) {
    let mut normals = vec![Vec3::ZERO; mesh.positions.len()];
    for t in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| mesh.positions[i as usize]);
        let n = (b - a).cross(c - a);
        t.iter().for_each(|&i| normals[i as usize] += n);
    }
    mesh.normals = normals
        .into_iter()
        .map(|n| n.normalize_or(Vec3::Y))
        .collect();
}

/// SplitMix64: a tiny seeded generator, so generated scenes are reproducible without a dependency.
pub struct SplitMix64(u64);

impl SplitMix64 {
    pub fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    pub fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f32()
    }
    pub fn unit_vector(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            if (1e-4..=1.0).contains(&v.length_squared()) {
                return v.normalize();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every generated triangle's winding agrees with its vertex normals (front = outward).
    #[test]
    fn windings_match_normals() {
        let mut rng = SplitMix64::new(1);
        let meshes = [
            ("quad", quad(Vec3::ZERO, Vec3::X, Vec3::Y, 3, Vec2::ONE)),
            ("cuboid", cuboid(Vec3::new(1.0, 2.0, 3.0))),
            ("cylinder", cylinder(0.3, 2.0, 24, 4, 8, 0.1)),
            ("sphere", uv_sphere(1.0, 12, 24)),
            ("torus", torus(1.0, 0.2, 24, 12, TAU)),
            ("blob", blob(1.0, 16, 32, &mut rng)),
        ];
        for (name, m) in meshes {
            for t in m.indices.chunks_exact(3) {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| m.positions[i as usize]);
                let geometric = (b - a).cross(c - a);
                if geometric.length() < 1e-5 {
                    continue; // poles of UV spheres
                }
                let shading: Vec3 = t.iter().map(|&i| m.normals[i as usize]).sum();
                assert!(
                    geometric.dot(shading) > 0.0,
                    "{name}: triangle {t:?} is wound against its normals"
                );
            }
        }
    }
}
