//! The whole scene's acceleration structure as the GPU traverses it: the 4-wide world tree over
//! the flattened triangles, then — when the scene has instances — a 4-wide top-level tree over
//! the instances' world boxes whose leaves lead to each instanced mesh's object-space tree (its
//! BLAS, built once however often it is placed).
//!
//! A ray enters an instance's BLAS transformed by the instance's inverse, direction unnormalised,
//! so the hit distance t is the same parameter in both spaces: the closest hit so far keeps
//! culling boxes across the levels, and `(t, placed id)` ties resolve as in the flat scene.
//! [`SceneBvh::intersect`] is the CPU reference of `bvh_trace` in shaders/common/bvh.glsl.

use super::compressed::Bvh8;
use super::traverse::{safe_inverse_dir, slab_test};
use super::wide::{Bvh4, WIDTH};
use super::{Bvh, BvhBuilder, TraceState};
use crate::intersect::{Hit, Ray};
use crate::{Aabb, Scene};
use glam::{Vec3, Vec4};

/// One instance as the traversal needs it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InstanceRay {
    /// Rows of the 3×4 object-from-world matrix.
    pub object_from_world: [Vec4; 3],
    pub mesh: u32,
    pub first_id: u32,
}

impl InstanceRay {
    /// The ray in object space, with the arithmetic (and its order) the GLSL uses.
    pub fn to_object(&self, ray: &Ray) -> Ray {
        let [r0, r1, r2] = self.object_from_world;
        let (o, d) = (ray.origin, ray.dir);
        let point = |r: Vec4| r.x * o.x + r.y * o.y + r.z * o.z + r.w;
        let vector = |r: Vec4| r.x * d.x + r.y * d.y + r.z * d.z;
        Ray {
            origin: Vec3::new(point(r0), point(r1), point(r2)),
            dir: Vec3::new(vector(r0), vector(r1), vector(r2)),
        }
    }
}

/// The binary trees of the instance levels, before they are collapsed for a traversal: one per
/// instanced mesh (object space) and the top level over the instances' world boxes.
pub struct InstanceLevels {
    pub meshes: Vec<Bvh>,
    pub mesh_tris: Vec<Vec<[Vec3; 3]>>,
    pub top: Bvh,
    /// The instances' world boxes as the degenerate "triangles" the top level was built over
    /// (min, max, max).
    pub top_boxes: Vec<[Vec3; 3]>,
    pub instances: Vec<InstanceRay>,
}

impl InstanceLevels {
    /// Each BLAS with `builder`, the top level binned (spatial splits would cut instance boxes,
    /// which are not triangles).
    pub fn build(scene: &Scene, builder: BvhBuilder) -> InstanceLevels {
        let inst = &scene.instancing;
        let mesh_tris: Vec<Vec<[Vec3; 3]>> = (0..inst.meshes.len())
            .map(|m| inst.mesh_positions(m))
            .collect();
        let meshes = mesh_tris
            .iter()
            .map(|t| Bvh::build_with(t, builder))
            .collect();
        let mesh_bounds: Vec<Aabb> = mesh_tris
            .iter()
            .map(|t| Aabb::of_points(&t.concat()))
            .collect();
        // Each instance's world box (its mesh box's corners transformed) as a degenerate
        // "triangle" spanning it: the binned builder only looks at the corners' bounds.
        let top_boxes: Vec<[Vec3; 3]> = inst
            .instances
            .iter()
            .map(|i| {
                let b = mesh_bounds[i.mesh as usize];
                let corners: Vec<Vec3> = (0..8)
                    .map(|k| {
                        i.world_from_object.transform_point3(Vec3::select(
                            glam::BVec3::new(k & 1 != 0, k & 2 != 0, k & 4 != 0),
                            b.max,
                            b.min,
                        ))
                    })
                    .collect();
                let w = Aabb::of_points(&corners);
                [w.min, w.max, w.max]
            })
            .collect();
        let top = Bvh::build_with(&top_boxes, BvhBuilder::BINNED);
        let instances = inst
            .instances
            .iter()
            .map(|i| {
                let m = i.object_from_world();
                InstanceRay {
                    object_from_world: [m.row(0), m.row(1), m.row(2)],
                    mesh: i.mesh,
                    first_id: i.first_id,
                }
            })
            .collect();
        InstanceLevels {
            meshes,
            mesh_tris,
            top,
            top_boxes,
            instances,
        }
    }
}

#[derive(Clone, Debug, Default)]
pub struct SceneBvh {
    pub world: Bvh4,
    /// The flattened triangles' world-space corners (by placed id).
    pub world_tris: Vec<[Vec3; 3]>,
    /// Per instanced mesh: its object-space tree and corners (by local index).
    pub meshes: Vec<Bvh4>,
    pub mesh_tris: Vec<Vec<[Vec3; 3]>>,
    /// Over the instances' world boxes; its `tri_order` holds instance indices.
    pub top: Bvh4,
    pub instances: Vec<InstanceRay>,
}

impl SceneBvh {
    /// Builds every level: the world tree and each BLAS with `builder`, the top level binned
    /// (spatial splits would cut instance boxes, which are not triangles).
    pub fn build(scene: &Scene, builder: BvhBuilder) -> SceneBvh {
        let world_tris = scene.flat_positions();
        let world = Bvh4::from_binary(&Bvh::build_with(&world_tris, builder));
        SceneBvh::with_world(scene, world_tris, world, builder)
    }

    /// The instance levels around a world tree built by the caller (`fovea bench` compares
    /// builders on it).
    pub fn with_world(
        scene: &Scene,
        world_tris: Vec<[Vec3; 3]>,
        world: Bvh4,
        builder: BvhBuilder,
    ) -> SceneBvh {
        let levels = InstanceLevels::build(scene, builder);
        SceneBvh {
            world,
            world_tris,
            meshes: levels.meshes.iter().map(Bvh4::from_binary).collect(),
            mesh_tris: levels.mesh_tris,
            top: Bvh4::from_binary(&levels.top),
            instances: levels.instances,
        }
    }

    /// Closest hit over the whole scene (smallest `(t, placed id)`) or, with `any_hit`, the first
    /// hit found, for `0 < t < t_max`: the world tree, then the instances.
    pub fn intersect(&self, ray: &Ray, t_max: f32, any_hit: bool) -> Option<Hit> {
        let mut state = TraceState::default();
        if let Some(hit) =
            self.world
                .intersect_into(&self.world_tris, ray, t_max, any_hit, 0, &mut state)
        {
            return Some(hit);
        }
        if self.instances.is_empty() {
            return state.best;
        }
        let inv_dir = safe_inverse_dir(ray.dir);
        let mut stack = vec![0u32];
        while let Some(node) = stack.pop() {
            let n = &self.top.nodes[node as usize];
            for c in (0..WIDTH).filter(|&c| !n.is_empty_child(c)) {
                let limit = state.best.map_or(t_max, |h: Hit| h.t);
                if slab_test(n.child_min[c], n.child_max[c], ray.origin, inv_dir, limit).is_none() {
                    continue;
                }
                if n.child_count[c] == 0 {
                    stack.push(n.child_ref[c]);
                    continue;
                }
                let start = n.child_ref[c] as usize;
                for &k in &self.top.tri_order[start..start + n.child_count[c] as usize] {
                    let inst = &self.instances[k as usize];
                    let m = inst.mesh as usize;
                    let local = inst.to_object(ray);
                    if let Some(hit) = self.meshes[m].intersect_into(
                        &self.mesh_tris[m],
                        &local,
                        t_max,
                        any_hit,
                        inst.first_id,
                        &mut state,
                    ) {
                        return Some(hit);
                    }
                }
            }
        }
        state.best
    }

    /// The most entries the top level's traversal stack can hold (see [`Bvh4::max_stack`]).
    pub fn top_max_stack(&self) -> u32 {
        if self.instances.is_empty() {
            0
        } else {
            self.top.max_stack()
        }
    }
}

/// Bytes the traversals read per instance entered: its leaf entry (16) and its `InstanceGpu` (112).
pub const INSTANCE_BYTES: u64 = 128;

/// The scene's levels as compressed 8-wide trees ([`Bvh8`]), what the GPU-shaped traversal reads;
/// [`SceneBvh8::intersect`] is the CPU reference of its `bvh_trace`.
#[derive(Clone, Debug, Default)]
pub struct SceneBvh8 {
    pub world: Bvh8,
    pub world_tris: Vec<[Vec3; 3]>,
    pub meshes: Vec<Bvh8>,
    pub mesh_tris: Vec<Vec<[Vec3; 3]>>,
    /// Over the instances' world boxes; its `tri_order` holds instance indices.
    pub top: Bvh8,
    pub instances: Vec<InstanceRay>,
}

impl SceneBvh8 {
    /// The world tree collapsed from `world` (built over `world_tris`), the instance levels
    /// built with `builder`.
    pub fn with_world(
        scene: &Scene,
        world_tris: Vec<[Vec3; 3]>,
        world: &Bvh,
        builder: BvhBuilder,
    ) -> SceneBvh8 {
        let levels = InstanceLevels::build(scene, builder);
        SceneBvh8 {
            world: Bvh8::from_binary(world, &world_tris),
            world_tris,
            meshes: levels
                .meshes
                .iter()
                .zip(&levels.mesh_tris)
                .map(|(bvh, tris)| Bvh8::from_binary(bvh, tris))
                .collect(),
            mesh_tris: levels.mesh_tris,
            top: Bvh8::from_binary(&levels.top, &levels.top_boxes),
            instances: levels.instances,
        }
    }

    /// Closest hit (smallest `(t, placed id)`) or, with `any_hit`, the first hit found, for
    /// `0 < t < t_max`, with the GPU's counts in `state`.
    pub fn intersect(
        &self,
        ray: &Ray,
        t_max: f32,
        any_hit: bool,
        state: &mut TraceState,
    ) -> Option<Hit> {
        if let Some(hit) =
            self.world
                .intersect_into(&self.world_tris, ray, t_max, any_hit, 0, state)
        {
            return Some(hit);
        }
        if self.instances.is_empty() {
            return state.best;
        }
        let found = self.top.walk(ray, t_max, state, |k, state| {
            state.counts.bytes += INSTANCE_BYTES;
            let inst = &self.instances[k as usize];
            let m = inst.mesh as usize;
            let local = inst.to_object(ray);
            self.meshes[m].intersect_into(
                &self.mesh_tris[m],
                &local,
                t_max,
                any_hit,
                inst.first_id,
                state,
            )
        });
        found.or(state.best)
    }

    /// The most entries either level's traversal stack can hold.
    pub fn max_stack(&self) -> (u32, u32) {
        let deepest = self
            .meshes
            .iter()
            .map(Bvh8::max_stack)
            .chain([self.world.max_stack()])
            .max()
            .unwrap_or(0);
        let top = if self.instances.is_empty() {
            0
        } else {
            self.top.max_stack()
        };
        (deepest, top)
    }
}

/// What instancing keeps off the GPU, for `fovea bench`.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct InstancingStats {
    pub instances: usize,
    pub instanced_meshes: usize,
    /// Triangles that can be hit (instances expanded) and triangles uploaded.
    pub placed_triangles: usize,
    pub uploaded_triangles: usize,
    /// GPU bytes a flattened upload would add (vertices 48 B, triangles 16 B and one 48 B leaf
    /// reference each, for every copy beyond the first of each instanced mesh; its extra BVH
    /// nodes not counted) less what instancing costs (per instance 112 B of data and a 16 B leaf
    /// entry, the top level's nodes: 128 B each in the 4-wide layout, 80 B in the compressed one).
    pub bytes_saved: i64,
}

impl InstancingStats {
    /// For the 4-wide levels (top-level nodes at 128 B).
    pub fn of(scene: &Scene, bvh: &SceneBvh) -> InstancingStats {
        let top = if scene.instancing.instances.is_empty() {
            0
        } else {
            bvh.top.nodes.len() * 128
        };
        InstancingStats::with_top_bytes(scene, top)
    }

    /// For the compressed levels (top-level nodes at 80 B).
    pub fn of_compressed(scene: &Scene, bvh: &SceneBvh8) -> InstancingStats {
        let top = if scene.instancing.instances.is_empty() {
            0
        } else {
            bvh.top.nodes.len() * super::compressed::NODE_BYTES as usize
        };
        InstancingStats::with_top_bytes(scene, top)
    }

    fn with_top_bytes(scene: &Scene, top_bytes: usize) -> InstancingStats {
        let inst = &scene.instancing;
        let mut copies_bytes = 0i64;
        for i in &inst.instances {
            let mesh = &inst.meshes[i.mesh as usize];
            copies_bytes += (mesh.vertices.len() * 48 + mesh.triangles.len() * (16 + 48)) as i64;
        }
        for mesh in &inst.meshes {
            copies_bytes -= (mesh.vertices.len() * 48 + mesh.triangles.len() * (16 + 48)) as i64;
        }
        let overhead = (inst.instances.len() * (112 + 16) + top_bytes) as i64;
        InstancingStats {
            instances: inst.instances.len(),
            instanced_meshes: inst.meshes.len(),
            placed_triangles: scene.placed_triangle_count(),
            uploaded_triangles: scene.unique_triangle_count(),
            bytes_saved: copies_bytes - overhead,
        }
    }
}
