//! Per-primitive vertex work: strip/fan conversion, flat normals when a primitive has none,
//! tangents when a normal map needs them, and the transform to world space.

use crate::Vertex;
use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};

/// One primitive's attributes as read from glTF (local space, indices already validated).
pub(crate) struct PrimitiveData {
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<Vec2>>,
    pub tangents: Option<Vec<Vec4>>,
    pub triangles: Vec<[u32; 3]>,
}

/// glTF §3.7.2.1: strip triangle i is (i, i+1+i%2, i+2−i%2), which keeps the winding consistent.
pub(crate) fn strip_to_triangles(indices: &[u32]) -> Vec<[u32; 3]> {
    (0..indices.len().saturating_sub(2))
        .map(|i| [indices[i], indices[i + 1 + i % 2], indices[i + 2 - i % 2]])
        .collect()
}

/// glTF §3.7.2.1: fan triangle i is (i+1, i+2, 0).
pub(crate) fn fan_to_triangles(indices: &[u32]) -> Vec<[u32; 3]> {
    (0..indices.len().saturating_sub(2))
        .map(|i| [indices[i + 1], indices[i + 2], indices[0]])
        .collect()
}

/// Builds world-space vertices and triangles (indices local to the returned vertex list).
pub(crate) fn build_world_vertices(
    data: PrimitiveData,
    needs_tangents: bool,
    world: Mat4,
) -> (Vec<Vertex>, Vec<[u32; 3]>) {
    let PrimitiveData {
        positions,
        normals,
        uvs,
        tangents,
        mut triangles,
    } = data;
    let n = positions.len();
    let mut vertices: Vec<Vertex> = (0..n)
        .map(|i| Vertex {
            position: positions[i],
            normal: normals.as_ref().map_or(Vec3::ZERO, |v| v[i]),
            uv: uvs.as_ref().map_or(Vec2::ZERO, |v| v[i]),
            tangent: tangents.as_ref().map_or(Vec4::ZERO, |v| v[i]),
        })
        .collect();
    if normals.is_none() {
        // Flat normals need one vertex per corner; un-welding is simplest and exact.
        let (v, t) = unweld_with_flat_normals(&vertices, &triangles);
        vertices = v;
        triangles = t;
    }
    for v in &mut vertices {
        v.normal = v.normal.normalize_or(Vec3::Z);
    }
    if tangents.is_none() {
        if needs_tangents {
            generate_tangents(&mut vertices, &triangles);
        } else {
            // Nothing samples a tangent frame without a normal map; any orthonormal one will do.
            vertices
                .iter_mut()
                .for_each(|v| v.tangent = any_perpendicular(v.normal).extend(1.0));
        }
    }
    to_world(&mut vertices, &mut triangles, world);
    (vertices, triangles)
}

fn unweld_with_flat_normals(
    vertices: &[Vertex],
    triangles: &[[u32; 3]],
) -> (Vec<Vertex>, Vec<[u32; 3]>) {
    let mut out = Vec::with_capacity(triangles.len() * 3);
    let mut tris = Vec::with_capacity(triangles.len());
    for t in triangles {
        let [a, b, c] = t.map(|i| vertices[i as usize]);
        let normal = (b.position - a.position)
            .cross(c.position - a.position)
            .normalize_or(Vec3::Z);
        let base = out.len() as u32;
        out.extend([a, b, c].map(|v| Vertex { normal, ..v }));
        tris.push([base, base + 1, base + 2]);
    }
    (out, tris)
}

/// Per-vertex tangents from accumulated per-triangle UV derivatives (Lengyel's method), made
/// orthogonal to the normal. Handedness follows glTF: bitangent = cross(N, T) · w points along +v.
fn generate_tangents(vertices: &mut [Vertex], triangles: &[[u32; 3]]) {
    let mut tan = vec![Vec3::ZERO; vertices.len()];
    let mut bitan = vec![Vec3::ZERO; vertices.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| vertices[i as usize]);
        let (dp1, dp2) = (b.position - a.position, c.position - a.position);
        let (duv1, duv2) = (b.uv - a.uv, c.uv - a.uv);
        let det = duv1.x * duv2.y - duv2.x * duv1.y;
        if det.abs() < 1e-20 || !det.is_finite() {
            continue; // degenerate UV mapping: contributes no direction
        }
        let r = 1.0 / det;
        let sdir = (dp1 * duv2.y - dp2 * duv1.y) * r;
        let tdir = (dp2 * duv1.x - dp1 * duv2.x) * r;
        for &i in t {
            tan[i as usize] += sdir;
            bitan[i as usize] += tdir;
        }
    }
    for (i, v) in vertices.iter_mut().enumerate() {
        let n = v.normal;
        let t = (tan[i] - n * n.dot(tan[i])).normalize_or_zero();
        let t = if t == Vec3::ZERO {
            any_perpendicular(n)
        } else {
            t
        };
        let w = if n.cross(t).dot(bitan[i]) < 0.0 {
            -1.0
        } else {
            1.0
        };
        v.tangent = t.extend(w);
    }
}

/// A unit vector perpendicular to unit `n` (Duff et al. 2017, branchless ONB).
pub(crate) fn any_perpendicular(n: Vec3) -> Vec3 {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x)
}

/// Positions by the matrix, normals by its inverse transpose, tangents by its 3×3 part.
/// A mirroring transform (negative determinant) flips the winding, so two indices are swapped to
/// keep counter-clockwise = front, and the bitangent sign is flipped to keep the normal-map frame.
fn to_world(vertices: &mut [Vertex], triangles: &mut [[u32; 3]], world: Mat4) {
    let linear = Mat3::from_mat4(world);
    let det = linear.determinant();
    let normal_matrix = if det.abs() > 1e-30 {
        linear.inverse().transpose()
    } else {
        linear
    };
    let flip = if det < 0.0 { -1.0 } else { 1.0 };
    for v in vertices.iter_mut() {
        v.position = world.transform_point3(v.position);
        v.normal = (normal_matrix * v.normal).normalize_or(Vec3::Z);
        let t = (linear * v.tangent.truncate()).normalize_or_zero();
        let t = if t == Vec3::ZERO {
            any_perpendicular(v.normal)
        } else {
            t
        };
        v.tangent = t.extend(v.tangent.w.signum() * flip);
    }
    if det < 0.0 {
        triangles.iter_mut().for_each(|t| t.swap(1, 2));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_and_fans_keep_counter_clockwise_winding() {
        assert_eq!(
            strip_to_triangles(&[0, 1, 2, 3]),
            vec![[0, 1, 2], [1, 3, 2]]
        );
        assert_eq!(fan_to_triangles(&[0, 1, 2, 3]), vec![[1, 2, 0], [2, 3, 0]]);
        assert!(strip_to_triangles(&[0, 1]).is_empty());
    }

    #[test]
    fn generated_tangents_follow_u_and_handedness_follows_v() {
        let quad = PrimitiveData {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            normals: Some(vec![Vec3::Z; 4]),
            uvs: Some(vec![
                Vec2::new(0.0, 0.0),
                Vec2::new(1.0, 0.0),
                Vec2::new(1.0, 1.0),
                Vec2::new(0.0, 1.0),
            ]),
            tangents: None,
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        };
        let (v, _) = build_world_vertices(quad, true, Mat4::IDENTITY);
        for vert in &v {
            assert!((vert.tangent.truncate() - Vec3::X).length() < 1e-6);
            assert_eq!(vert.tangent.w, 1.0); // +v runs along +Y = cross(Z, X)
        }
    }

    #[test]
    fn mirroring_transform_swaps_winding_and_flat_normals_are_generated() {
        let tri = PrimitiveData {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            normals: None,
            uvs: None,
            tangents: None,
            triangles: vec![[0, 1, 2]],
        };
        let (v, t) = build_world_vertices(tri, false, Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)));
        assert_eq!(t, vec![[0, 2, 1]]);
        let p = t[0].map(|i| v[i as usize].position);
        let geometric = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
        assert!(
            (geometric - v[0].normal).length() < 1e-6,
            "normal {:?} vs {geometric:?}",
            v[0].normal
        );
        assert!((v[0].normal - Vec3::Z).length() < 1e-6);
    }
}
