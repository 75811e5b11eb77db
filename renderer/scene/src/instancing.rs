//! Meshes placed by two or more nodes, kept once in object space and placed by affine transforms
//! (true instancing). Meshes placed once stay flattened in [`Scene::vertices`]/[`Scene::triangles`]
//! so scenes without repeats keep the single world-space BVH; scenes that place no more than
//! [`crate::LoadLimits::instance_above`] triangles are flattened whole (faster on lavapipe).
//!
//! **Placed triangle ids.** Every triangle the renderer can hit has one id: the flattened
//! triangles are `0 .. triangles.len()`, then instance k's are `first_id + local index`, instances
//! in order. Hits, the G-buffer, A-SVGF's re-shading and the light table all speak these ids, and
//! the ties of the closest-hit rule (smallest `(t, id)`) use them, so [`Scene::flattened`] — the
//! same scene expanded into world space in id order — is a reference with the same ids.

use crate::{Scene, Triangle, Vertex};
use glam::{Mat3, Mat4, Vec3};

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Instancing {
    pub meshes: Vec<InstancedMesh>,
    pub instances: Vec<Instance>,
}

/// One glTF mesh (all its primitives) in object space; triangle indices are local to `vertices`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InstancedMesh {
    pub vertices: Vec<Vertex>,
    pub triangles: Vec<Triangle>,
}

/// One placement of an [`InstancedMesh`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    /// Index into [`Instancing::meshes`].
    pub mesh: u32,
    /// The node's world matrix (affine).
    pub world_from_object: Mat4,
    /// Placed id of the mesh's triangle 0 (see the module doc).
    pub first_id: u32,
}

impl Instance {
    /// A mirroring transform flips the winding; shading flips the geometric normal back (the
    /// flattened copy swaps two indices instead, see `geometry::to_world`).
    pub fn mirrors(&self) -> bool {
        Mat3::from_mat4(self.world_from_object).determinant() < 0.0
    }

    /// The inverse, for rays into object space (the loader refuses singular transforms).
    pub fn object_from_world(&self) -> Mat4 {
        self.world_from_object.inverse()
    }

    /// A vertex in world space: positions by the matrix, normals by its inverse transpose,
    /// tangents by its 3×3 part with the handedness flipped by a mirror (as the flattened copy).
    pub fn vertex_to_world(&self, v: &Vertex) -> Vertex {
        let linear = Mat3::from_mat4(self.world_from_object);
        let normal_matrix = linear.inverse().transpose();
        let flip = if self.mirrors() { -1.0 } else { 1.0 };
        Vertex {
            position: self.world_from_object.transform_point3(v.position),
            normal: (normal_matrix * v.normal).normalize_or(Vec3::Z),
            uv: v.uv,
            tangent: (linear * v.tangent.truncate())
                .normalize_or(Vec3::X)
                .extend(v.tangent.w * flip),
        }
    }
}

impl Instancing {
    pub fn placed_triangles(&self) -> usize {
        self.instances
            .iter()
            .map(|i| self.meshes[i.mesh as usize].triangles.len())
            .sum()
    }

    /// Object-space triangle corners of mesh `m`, by local index (its BLAS's input).
    pub fn mesh_positions(&self, m: usize) -> Vec<[Vec3; 3]> {
        let mesh = &self.meshes[m];
        mesh.triangles
            .iter()
            .map(|t| t.indices.map(|i| mesh.vertices[i as usize].position))
            .collect()
    }

    /// Gives the instances consecutive placed ids after the `flat` flattened triangles; `None`
    /// when they would not fit 32 bits (the loader refuses such scenes first).
    pub(crate) fn assign_ids(&mut self, flat: usize) -> Option<()> {
        let mut next = u32::try_from(flat).ok()?;
        for inst in &mut self.instances {
            inst.first_id = next;
            let n = u32::try_from(self.meshes[inst.mesh as usize].triangles.len()).ok()?;
            next = next.checked_add(n).filter(|&n| n < u32::MAX)?;
        }
        Some(())
    }
}

impl Scene {
    /// Triangles that can be hit: the flattened ones plus every instance's.
    pub fn placed_triangle_count(&self) -> usize {
        self.triangles.len() + self.instancing.placed_triangles()
    }

    /// Triangles uploaded once: the flattened ones plus each instanced mesh's.
    pub fn unique_triangle_count(&self) -> usize {
        self.triangles.len()
            + self
                .instancing
                .meshes
                .iter()
                .map(|m| m.triangles.len())
                .sum::<usize>()
    }

    /// The same scene with every instance copied into world space, triangles in placed-id order
    /// (mirrored copies with two indices swapped, as the loader flattens): the reference the
    /// instanced traversal and shading are tested against.
    pub fn flattened(&self) -> Scene {
        let mut out = Scene {
            instancing: Instancing::default(),
            ..self.clone()
        };
        for inst in &self.instancing.instances {
            let mesh = &self.instancing.meshes[inst.mesh as usize];
            let base = out.vertices.len() as u32;
            out.vertices
                .extend(mesh.vertices.iter().map(|v| inst.vertex_to_world(v)));
            let mirror = inst.mirrors();
            out.triangles.extend(mesh.triangles.iter().map(|t| {
                let [a, b, c] = t.indices.map(|i| i + base);
                Triangle {
                    indices: if mirror { [a, c, b] } else { [a, b, c] },
                    ..*t
                }
            }));
        }
        out
    }

    /// Every placed triangle in id order: its world-space corners (counter-clockwise from the
    /// front, as [`Scene::flattened`]) and its flattened or mesh triangle.
    pub fn placed_triangles(&self) -> impl Iterator<Item = ([Vec3; 3], &Triangle)> + '_ {
        let flat = self
            .triangles
            .iter()
            .map(|t| (t.indices.map(|i| self.vertices[i as usize].position), t));
        let instanced = self.instancing.instances.iter().flat_map(move |inst| {
            let mesh = &self.instancing.meshes[inst.mesh as usize];
            let mirror = inst.mirrors();
            mesh.triangles.iter().map(move |t| {
                let [a, b, c] = t.indices.map(|i| {
                    inst.world_from_object
                        .transform_point3(mesh.vertices[i as usize].position)
                });
                (if mirror { [a, c, b] } else { [a, b, c] }, t)
            })
        });
        flat.chain(instanced)
    }
}

#[cfg(test)]
#[path = "instancing_tests.rs"]
mod tests;
