//! Uploads a CPU scene (`fovea_scene::Scene`) into the GPU buffers the tracing passes bind: the
//! BVH in the layout of one traversal ([`Traversal`]: the 4-wide tree's nodes and leaf triangles
//! as texel buffers, or the compressed 8-wide tree's as storage buffers), shading data as std430
//! storage buffers.
//! Instanced meshes (`fovea_scene::instancing`) are uploaded once: their vertices, triangles and
//! object-space trees follow the flattened ones in the same buffers, with one `InstanceGpu` per
//! placement and a top-level tree over the instances (`fovea_scene::bvh::instanced`).

use crate::environment::GpuEnvironment;
use crate::error::{Error, Result};
use crate::graph::{read_buffer, read_texels, Bind};
use crate::layouts::{
    InstanceGpu, LightGpu, MaterialGpu, TriangleGpu, VertexGpu, LIGHT_KIND_DIRECTIONAL,
    LIGHT_KIND_ENVIRONMENT, LIGHT_KIND_POINT, LIGHT_KIND_SPOT, LIGHT_KIND_TRIANGLE,
    MATERIAL_ALPHA_BLEND, MATERIAL_ALPHA_MASK, MATERIAL_DOUBLE_SIDED, NO_TEXTURE,
};
use crate::scene::bvh::compressed::{self, Bvh8};
use crate::scene::bvh::instanced::{InstanceRay, InstancingStats, SceneBvh, SceneBvh8};
use crate::scene::bvh::wide::{Bvh4, Bvh4Node};
use crate::scene::bvh::{Bvh, BvhBuilder};
use crate::scene::lights::{build_light_table_scaled, LightKind};
use crate::scene::{Aabb, PunctualLight, Scene, TextureSlot};
use crate::texture_pack;
use crate::traversal::Traversal;
use crate::vk::{Buffer, Context};
use ash::vk;
use glam::{UVec4, Vec4};
use std::sync::Arc;

/// Must match BVH_STACK_SIZE in shaders/common/bvh.glsl: trees whose traversal could push more
/// entries (`Bvh4::max_stack`) could lose hits.
pub const MAX_BVH_STACK: u32 = 64;
/// Must match TOP_STACK_SIZE in shaders/common/bvh.glsl (the instance level's stack).
pub const MAX_TOP_STACK: u32 = 16;
/// Must match BVH8_STACK_SIZE in shaders/common/bvh.glsl (the GPU traversal's stack,
/// `Bvh8::max_stack`).
pub const MAX_BVH8_STACK: u32 = compressed::STACK_SIZE as u32;
/// Must match BVH8_TOP_STACK_SIZE in shaders/common/bvh.glsl (its instance level's stack).
pub const MAX_TOP_STACK_GPU: u32 = 32;

/// The scene's bindings by their GLSL names (`GpuScene::binds`); a kernel binds those it reads.
#[derive(Clone, Copy)]
pub struct SceneBinds<'a> {
    pub bvh_nodes: Bind<'a>,
    pub bvh_triangles: Bind<'a>,
    pub vertices: Bind<'a>,
    pub triangles: Bind<'a>,
    pub materials: Bind<'a>,
    pub textures: Bind<'a>,
    pub texels: Bind<'a>,
    pub lights: Bind<'a>,
    pub environment: Bind<'a>,
    pub instances: Bind<'a>,
}

/// The bindings of a kernel that reads the whole scene: the scene's ten ([`SceneBinds`], in the
/// order of the GLSL bindings 0–9 of `common/scene.glsl`) then `rest`, as one fixed array (no host
/// allocation per dispatch): `scene_then!(scene.binds(); read_buffer("frame", …), …)`.
macro_rules! scene_then {
    ($scene:expr; $($rest:expr),* $(,)?) => {{
        let s: $crate::gpu_scene::SceneBinds = $scene;
        [
            s.bvh_nodes,
            s.bvh_triangles,
            s.vertices,
            s.triangles,
            s.materials,
            s.textures,
            s.texels,
            s.lights,
            s.environment,
            s.instances,
            $($rest),*
        ]
    }};
}
pub(crate) use scene_then;

pub struct GpuScene {
    /// The traversal whose tree layout the BVH buffers hold (kernels of the other cannot bind it).
    pub traversal: Traversal,
    /// The nodes and leaf triangles of every tree (texel buffers for [`Traversal::CpuDriver`],
    /// storage buffers for [`Traversal::Gpu`]).
    pub bvh_nodes: Buffer,
    pub bvh_triangles: Buffer,
    pub vertices: Buffer,
    pub triangles: Buffer,
    pub materials: Buffer,
    pub textures: Buffer,
    pub texels: Buffer,
    pub lights: Buffer,
    pub instances: Buffer,
    /// `FrameData.instancing` for this upload.
    pub instancing_slots: UVec4,
    /// Instance count and the bytes instancing keeps off the GPU (`fovea bench`).
    pub instancing_stats: InstancingStats,
    pub light_count: u32,
    /// Counts the light-table rebuilds (`set_emission_scale`): history that stores light-table
    /// entries or light gathered at surfaces (ReSTIR DI's and GI's reservoirs) is dropped when it
    /// changes.
    pub lights_version: u64,
    /// Light entries that are emissive triangles (the table's first): without any, ReSTIR DI's
    /// BRDF candidates could find nothing and are not drawn.
    pub triangle_light_count: u32,
    pub triangle_count: u32,
    pub material_count: u32,
    pub texture_count: u32,
    /// How many times a texture was halved so that all texels fit one storage buffer
    /// (`maxStorageBufferRange`: 128 MiB on lavapipe, less than Sponza's 250 MB of RGBA8).
    pub textures_halved: u32,
    pub bounds: Aabb,
    /// What escaping rays see (`Scene::environment_map`: a loaded map or the baked sky).
    pub environment: GpuEnvironment,
    /// `FrameData.environment` and `.environment_map` for this upload and light table.
    pub environment_slots: (Vec4, UVec4),
    /// Depth and GPU bytes of the trees the shaders traverse (nodes + leaf triangles; with
    /// instances also every BLAS, the top level and the instance data). Depth is the world tree's.
    pub bvh_depth: u32,
    pub bvh_bytes: usize,
    /// Some material is alpha-masked or blended: traversal tests alpha (`FRAME_FLAG_ALPHA_MASK`).
    pub alpha_masked: bool,
    /// Per-material emission factor set at run time (`set_emission_scale`; 1 = as loaded).
    emission_scale: Vec<f32>,
    /// Per material and texture slot, the `textures` entry it reads (`texture_pack`).
    material_textures: Vec<[Option<u32>; TextureSlot::COUNT]>,
}

impl GpuScene {
    /// Uploads `scene` for the context's traversal.
    pub fn upload(ctx: &Arc<Context>, scene: &Scene) -> Result<GpuScene> {
        let positions = scene.flat_positions();
        let bvh = Bvh::build(&positions);
        GpuScene::upload_with_bvh(ctx, scene, &positions, &bvh)
    }

    /// `positions` and `bvh`: the flattened triangles ([`Scene::flat_positions`]) and the world
    /// tree over them; instanced meshes get [`BvhBuilder::DEFAULT`] trees. For the context's
    /// traversal.
    pub fn upload_with_bvh(
        ctx: &Arc<Context>,
        scene: &Scene,
        positions: &[[glam::Vec3; 3]],
        bvh: &Bvh,
    ) -> Result<GpuScene> {
        GpuScene::upload_for(ctx, scene, positions, bvh, ctx.traversal)
    }

    /// [`GpuScene::upload_with_bvh`] in the layout of `traversal`.
    pub fn upload_for(
        ctx: &Arc<Context>,
        scene: &Scene,
        positions: &[[glam::Vec3; 3]],
        bvh: &Bvh,
        traversal: Traversal,
    ) -> Result<GpuScene> {
        // The trees collapsed from the binary ones (same leaves): 4-wide or compressed 8-wide.
        let (trees, depth, stats) = match traversal {
            Traversal::CpuDriver => {
                let levels = SceneBvh::with_world(
                    scene,
                    positions.to_vec(),
                    Bvh4::from_binary(bvh),
                    BvhBuilder::DEFAULT,
                );
                check_stacks(scene, &levels)?;
                (
                    pack_trees(&levels, scene),
                    levels.world.depth(),
                    InstancingStats::of(scene, &levels),
                )
            }
            Traversal::Gpu => {
                let levels =
                    SceneBvh8::with_world(scene, positions.to_vec(), bvh, BvhBuilder::DEFAULT);
                check_stacks_gpu(scene, &levels)?;
                let stats = InstancingStats::of_compressed(scene, &levels);
                (pack_trees8(&levels, scene)?, levels.world.depth(), stats)
            }
        };
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let (vertices, triangles) = geometry(scene)?;
        let emission_scale = vec![1.0; scene.materials.len()];
        let packed = texture_pack::pack(scene, ctx.info.max_storage_buffer_range as usize / 4);
        let materials: Vec<MaterialGpu> = scene
            .materials
            .iter()
            .zip(&packed.material_slots)
            .map(|(m, t)| material_gpu(m, t, 1.0))
            .collect();
        let (textures, texels) = (packed.infos, packed.texels);
        let lights = light_entries(scene, &emission_scale);
        let environment = GpuEnvironment::upload(ctx, scene)?;

        let tree_bytes = (trees.nodes.len() + trees.triangles.len()) * 16
            + std::mem::size_of_val(trees.instances.as_slice());
        let (bvh_nodes, bvh_triangles) = match traversal {
            Traversal::CpuDriver => (
                Buffer::device_texels(ctx, "bvh_nodes", &trees.nodes)?,
                Buffer::device_texels(ctx, "bvh_triangles", &trees.triangles)?,
            ),
            Traversal::Gpu => (
                Buffer::device_local(ctx, "bvh8_nodes", &trees.nodes, storage)?,
                Buffer::device_local(ctx, "bvh8_triangles", &trees.triangles, storage)?,
            ),
        };
        Ok(GpuScene {
            traversal,
            bvh_nodes,
            bvh_triangles,
            instances: Buffer::device_local(ctx, "instances", &trees.instances, storage)?,
            instancing_slots: trees.slots,
            instancing_stats: stats,
            vertices: Buffer::device_local(ctx, "vertices", &vertices, storage)?,
            triangles: Buffer::device_local(ctx, "triangles", &triangles, storage)?,
            materials: Buffer::with_data(ctx, "materials", &materials, storage)?,
            textures: Buffer::device_local(ctx, "textures", &textures, storage)?,
            texels: Buffer::device_local(ctx, "texels", &texels, storage)?,
            lights: Buffer::with_data(ctx, "lights", &lights, storage)?,
            light_count: lights.len() as u32,
            lights_version: 0,
            triangle_light_count: triangle_lights(&lights),
            triangle_count: triangles.len() as u32,
            material_count: materials.len() as u32,
            texture_count: textures.len() as u32,
            textures_halved: packed.halvings,
            material_textures: packed.material_slots,
            bounds: scene.bounds(),
            environment_slots: environment.frame_slots(&lights),
            environment,
            alpha_masked: scene
                .materials
                .iter()
                .any(|m| m.alpha_cutoff.is_some() || m.alpha_blend),
            bvh_depth: depth,
            bvh_bytes: tree_bytes,
            emission_scale,
        })
    }

    /// Scales material `material`'s emission by `scale` (relative to `scene`, the scene this was
    /// uploaded from; 0 switches its lights off) and rebuilds the light-sampling table so that
    /// next-event estimation picks lights by their new power. For lights switched during a
    /// sequence (tests, scripted sequences); takes effect from the next frame recorded.
    pub fn set_emission_scale(
        &mut self,
        ctx: &Arc<Context>,
        scene: &Scene,
        material: usize,
        scale: f32,
    ) -> Result<()> {
        if material >= self.emission_scale.len()
            || scene.materials.len() != self.emission_scale.len()
        {
            return Err(Error::Invalid(format!(
                "emission scale: material {material} does not exist ({} materials uploaded, {} in the scene given)",
                self.emission_scale.len(),
                scene.materials.len()
            )));
        }
        if !scale.is_finite() || scale < 0.0 {
            return Err(Error::Invalid(format!(
                "emission scale of material {material} must be finite and ≥ 0, got {scale}"
            )));
        }
        self.emission_scale[material] = scale;
        let materials: Vec<MaterialGpu> = scene
            .materials
            .iter()
            .zip(&self.material_textures)
            .zip(&self.emission_scale)
            .map(|((m, t), s)| material_gpu(m, t, *s))
            .collect();
        self.materials.write(&materials)?;
        let lights = light_entries(scene, &self.emission_scale);
        if std::mem::size_of_val(lights.as_slice()) as u64 > self.lights.size {
            self.lights =
                Buffer::with_data(ctx, "lights", &lights, vk::BufferUsageFlags::STORAGE_BUFFER)?;
        } else {
            self.lights.write(&lights)?;
        }
        self.light_count = lights.len() as u32;
        self.lights_version += 1;
        self.triangle_light_count = triangle_lights(&lights);
        self.environment_slots = self.environment.frame_slots(&lights);
        Ok(())
    }

    /// The scene bindings of `shaders/common/scene.glsl` and `environment.glsl` (all read-only);
    /// the BVH's by the names of this upload's traversal, so a kernel of the other one refuses it.
    pub fn binds(&self) -> SceneBinds<'_> {
        let (bvh_nodes, bvh_triangles) = match self.traversal {
            Traversal::CpuDriver => (
                read_texels("bvh_nodes", &self.bvh_nodes),
                read_texels("bvh_triangles", &self.bvh_triangles),
            ),
            Traversal::Gpu => (
                read_buffer("bvh8_nodes", &self.bvh_nodes),
                read_buffer("bvh8_triangles", &self.bvh_triangles),
            ),
        };
        SceneBinds {
            bvh_nodes,
            bvh_triangles,
            vertices: read_buffer("vertices", &self.vertices),
            triangles: read_buffer("triangles", &self.triangles),
            materials: read_buffer("materials", &self.materials),
            textures: read_buffer("textures", &self.textures),
            texels: read_buffer("texels", &self.texels),
            lights: read_buffer("lights", &self.lights),
            environment: read_buffer("environment", &self.environment.buffer),
            instances: read_buffer("instances", &self.instances),
        }
    }

    /// Centre and radius of the scene's bounding sphere.
    pub fn bounding_sphere(&self) -> Vec4 {
        let centre = (self.bounds.min + self.bounds.max) * 0.5;
        centre.extend((self.bounds.max - self.bounds.min).length() * 0.5)
    }
}

/// Vertices and triangles: the flattened ones, then each instanced mesh's (object space).
fn geometry(scene: &Scene) -> Result<(Vec<VertexGpu>, Vec<TriangleGpu>)> {
    let vertex = |v: &crate::scene::Vertex| VertexGpu {
        position_u: v.position.extend(v.uv.x),
        normal_v: v.normal.extend(v.uv.y),
        tangent: v.tangent,
    };
    let mut vertices: Vec<VertexGpu> = scene.vertices.iter().map(vertex).collect();
    let mut triangles = Vec::with_capacity(scene.unique_triangle_count());
    let meshes = scene
        .instancing
        .meshes
        .iter()
        .map(|m| (&m.vertices, &m.triangles));
    for (k, (verts, tris)) in std::iter::once((&scene.vertices, &scene.triangles))
        .chain(meshes)
        .enumerate()
    {
        let base = if k == 0 { 0 } else { vertices.len() as u32 };
        if k > 0 {
            vertices.extend(verts.iter().map(vertex));
        }
        for t in tris {
            if t.material > 0xffff || t.mesh > 0xffff {
                return Err(Error::Invalid(format!(
                    "{}: more than 65536 materials or meshes",
                    scene.source.display()
                )));
            }
            let [a, b, c] = t.indices.map(|i| i + base);
            triangles.push(TriangleGpu {
                vertices: UVec4::new(a, b, c, t.material | (t.mesh << 16)),
            });
        }
    }
    Ok((vertices, triangles))
}

/// Whether placed triangle `id` of the flattened triangles, or triangle `id` of instanced mesh
/// `mesh`, has an alpha-masked or blended material (the leaf data's TRIANGLE_ALPHA_TESTED flag).
fn alpha_tested(scene: &Scene, mesh: Option<usize>, id: u32) -> bool {
    let tri = match mesh {
        None => &scene.triangles[id as usize],
        Some(m) => &scene.instancing.meshes[m].triangles[id as usize],
    };
    let m = &scene.materials[tri.material as usize];
    m.alpha_cutoff.is_some() || m.alpha_blend
}

fn check_stacks_gpu(scene: &Scene, levels: &SceneBvh8) -> Result<()> {
    let (deepest, top) = levels.max_stack();
    if deepest > MAX_BVH8_STACK || top > MAX_TOP_STACK_GPU {
        return Err(Error::Invalid(format!(
            "{}: the GPU traversal's BVH could need {deepest} stack entries (the shaders have {MAX_BVH8_STACK}) and {top} at the instance level (the shaders have {MAX_TOP_STACK_GPU}); --traversal cpu-driver traverses it",
            scene.source.display()
        )));
    }
    Ok(())
}

/// Moves a compressed tree's children to `node_base` and its leaf entries to `entry_base`.
fn rebased8(tree: &Bvh8, node_base: u32, entry_base: u32) -> Bvh8 {
    let mut tree = tree.clone();
    for n in &mut tree.nodes {
        n.child_base += node_base;
        n.triangle_base += entry_base;
    }
    tree
}

/// Every compressed tree in one node and one leaf buffer: the world tree (root 0), each instanced
/// mesh's, then the top level (`FrameData.instancing.z` its root), whose leaf entries hold
/// instance indices in their first word.
fn pack_trees8(levels: &SceneBvh8, scene: &Scene) -> Result<PackedTrees> {
    let words = |tree: &Bvh8| -> Vec<[f32; 4]> {
        tree.node_words()
            .into_iter()
            .map(|w| w.map(f32::from_bits))
            .collect()
    };
    let mut nodes = words(&levels.world);
    let mut triangles = levels
        .world
        .triangle_words(&levels.world_tris, &|i| alpha_tested(scene, None, i));
    let (mut roots, mut first_triangle) = (Vec::new(), scene.triangles.len() as u32);
    let mut mesh_first = Vec::new();
    for (m, (tree, tris)) in levels.meshes.iter().zip(&levels.mesh_tris).enumerate() {
        let node_base = (nodes.len() / 5) as u32;
        roots.push(node_base);
        nodes.extend(words(&rebased8(
            tree,
            node_base,
            (triangles.len() / 3) as u32,
        )));
        triangles.extend(tree.triangle_words(tris, &|i| alpha_tested(scene, Some(m), i)));
        mesh_first.push(first_triangle);
        first_triangle += tris.len() as u32;
    }
    let top_root = (nodes.len() / 5) as u32;
    if !levels.instances.is_empty() {
        nodes.extend(words(&rebased8(
            &levels.top,
            top_root,
            (triangles.len() / 3) as u32,
        )));
        triangles.extend(
            levels
                .top
                .tri_order
                .iter()
                .flat_map(|&k| [[f32::from_bits(k), 0.0, 0.0, 0.0]; 3]),
        );
    }
    // A leaf entry addresses its first triangle in 29 bits (bvh.glsl's BVH8_LEAF encoding).
    if triangles.len() / 3 >= 1 << 29 {
        return Err(Error::Invalid(format!(
            "{}: {} leaf entries, more than the GPU traversal addresses (2^29)",
            scene.source.display(),
            triangles.len() / 3
        )));
    }
    let instances = instance_data(&levels.instances, scene, &roots, &mesh_first);
    let slots = UVec4::new(
        levels.instances.len() as u32,
        scene.triangles.len() as u32,
        top_root,
        0,
    );
    Ok(PackedTrees {
        nodes,
        triangles,
        instances,
        slots,
    })
}

fn check_stacks(scene: &Scene, levels: &SceneBvh) -> Result<()> {
    let deepest = levels
        .meshes
        .iter()
        .map(Bvh4::max_stack)
        .chain([levels.world.max_stack()])
        .max()
        .unwrap_or(0);
    let top = levels.top_max_stack();
    if deepest > MAX_BVH_STACK || top > MAX_TOP_STACK {
        return Err(Error::Invalid(format!(
            "{}: BVH traversal could need {deepest} stack entries (the shaders have {MAX_BVH_STACK}) and {top} at the instance level (the shaders have {MAX_TOP_STACK})",
            scene.source.display()
        )));
    }
    Ok(())
}

/// Every tree in one node and one leaf texel buffer (module doc of `fovea_scene::bvh::instanced`).
struct PackedTrees {
    nodes: Vec<[f32; 4]>,
    triangles: Vec<[f32; 4]>,
    instances: Vec<InstanceGpu>,
    slots: UVec4,
}

/// Moves a tree's nodes to `node_base` and its leaves to leaf entry `leaf_base` (empty children
/// stay count 0, ref 0).
fn rebased(tree: &Bvh4, node_base: u32, leaf_base: u32) -> Bvh4 {
    let nodes = tree
        .nodes
        .iter()
        .map(|n| {
            let mut n: Bvh4Node = *n;
            for c in 0..n.child_ref.len() {
                if n.child_count[c] > 0 {
                    n.child_ref[c] += leaf_base;
                } else if !n.is_empty_child(c) {
                    n.child_ref[c] += node_base;
                }
            }
            n
        })
        .collect();
    Bvh4 {
        nodes,
        tri_order: tree.tri_order.clone(),
    }
}

fn pack_trees(levels: &SceneBvh, scene: &Scene) -> PackedTrees {
    let mut nodes = levels.world.node_texels();
    let mut triangles = levels
        .world
        .triangle_texels(&levels.world_tris, &|i| alpha_tested(scene, None, i));
    let (mut roots, mut first_triangle) = (Vec::new(), scene.triangles.len() as u32);
    let mut mesh_first = Vec::new();
    for (m, (tree, tris)) in levels.meshes.iter().zip(&levels.mesh_tris).enumerate() {
        let node_base = (nodes.len() / 8) as u32;
        roots.push(node_base);
        nodes.extend(rebased(tree, node_base, (triangles.len() / 3) as u32).node_texels());
        triangles.extend(tree.triangle_texels(tris, &|i| alpha_tested(scene, Some(m), i)));
        mesh_first.push(first_triangle);
        first_triangle += tris.len() as u32;
    }
    let top_root = (nodes.len() / 8) as u32;
    let top_leaves = triangles.len() as u32;
    if !levels.instances.is_empty() {
        nodes.extend(rebased(&levels.top, top_root, 0).node_texels());
        triangles.extend(
            levels
                .top
                .tri_order
                .iter()
                .map(|&k| [f32::from_bits(k), 0.0, 0.0, 0.0]),
        );
    }
    let instances = instance_data(&levels.instances, scene, &roots, &mesh_first);
    let slots = UVec4::new(
        levels.instances.len() as u32,
        scene.triangles.len() as u32,
        top_root,
        top_leaves,
    );
    PackedTrees {
        nodes,
        triangles,
        instances,
        slots,
    }
}

/// One `InstanceGpu` per instance (a dummy when there are none: a buffer cannot be empty, and
/// `FrameData.instancing.x` = 0 skips it), with its mesh's root node and first TriangleGpu.
fn instance_data(
    rays: &[InstanceRay],
    scene: &Scene,
    roots: &[u32],
    mesh_first: &[u32],
) -> Vec<InstanceGpu> {
    let mut instances: Vec<InstanceGpu> = rays
        .iter()
        .zip(&scene.instancing.instances)
        .map(|(ray, inst)| {
            let w = inst.world_from_object;
            let [o0, o1, o2] = ray.object_from_world;
            InstanceGpu {
                object_from_world0: o0,
                object_from_world1: o1,
                object_from_world2: o2,
                world_from_object0: w.row(0),
                world_from_object1: w.row(1),
                world_from_object2: w.row(2),
                mesh: UVec4::new(
                    inst.first_id,
                    roots[inst.mesh as usize],
                    mesh_first[inst.mesh as usize],
                    inst.mirrors() as u32,
                ),
            }
        })
        .collect();
    if instances.is_empty() {
        instances.push(InstanceGpu::default());
    }
    instances
}

fn material_gpu(
    m: &crate::scene::Material,
    textures: &[Option<u32>; TextureSlot::COUNT],
    emission_scale: f32,
) -> MaterialGpu {
    let texture_index = |slot: TextureSlot| textures[slot as usize].unwrap_or(NO_TEXTURE);
    MaterialGpu {
        base_color: m.base_color,
        emissive: (m.emissive * emission_scale).extend(0.0),
        specular: m.specular_color.extend(m.specular_factor),
        surface: Vec4::new(m.metallic, m.roughness, m.ior, m.normal_scale),
        textures: UVec4::new(
            texture_index(TextureSlot::BaseColor),
            texture_index(TextureSlot::MetallicRoughness),
            texture_index(TextureSlot::Normal),
            texture_index(TextureSlot::Emissive),
        ),
        textures2: UVec4::new(
            texture_index(TextureSlot::Specular),
            texture_index(TextureSlot::SpecularColor),
            if m.double_sided {
                MATERIAL_DOUBLE_SIDED
            } else {
                0
            } | if m.alpha_cutoff.is_some() {
                MATERIAL_ALPHA_MASK
            } else {
                0
            } | if m.alpha_blend {
                MATERIAL_ALPHA_BLEND
            } else {
                0
            },
            m.alpha_cutoff.unwrap_or(0.0).to_bits(),
        ),
    }
}

fn triangle_lights(lights: &[LightGpu]) -> u32 {
    lights
        .iter()
        .filter(|l| l.kind_index.x == LIGHT_KIND_TRIANGLE)
        .count() as u32
}

fn light_entries(scene: &Scene, emission_scale: &[f32]) -> Vec<LightGpu> {
    let table = build_light_table_scaled(scene, emission_scale);
    table
        .entries
        .iter()
        .zip(&table.alias)
        .map(|(entry, slot)| {
            let mut gpu = LightGpu {
                kind_index: UVec4::new(LIGHT_KIND_TRIANGLE, entry.index, slot.alias, 0),
                sampling: Vec4::new(slot.threshold, slot.pdf, 0.0, 0.0),
                ..Default::default()
            };
            if entry.kind == LightKind::Environment {
                gpu.kind_index.x = LIGHT_KIND_ENVIRONMENT;
            } else if entry.kind != LightKind::EmissiveTriangle {
                match &scene.punctual_lights[entry.index as usize] {
                    PunctualLight::Point {
                        position,
                        intensity,
                        range,
                    } => {
                        gpu.kind_index.x = LIGHT_KIND_POINT;
                        gpu.position = position.extend(range.unwrap_or(0.0));
                        gpu.intensity = intensity.extend(1.0);
                    }
                    PunctualLight::Spot {
                        position,
                        direction,
                        intensity,
                        range,
                        inner_cone,
                        outer_cone,
                    } => {
                        gpu.kind_index.x = LIGHT_KIND_SPOT;
                        gpu.position = position.extend(range.unwrap_or(0.0));
                        gpu.direction = direction.extend(outer_cone.cos());
                        gpu.intensity = intensity.extend(inner_cone.cos());
                    }
                    PunctualLight::Directional {
                        direction,
                        illuminance,
                    } => {
                        gpu.kind_index.x = LIGHT_KIND_DIRECTIONAL;
                        gpu.direction = direction.extend(0.0);
                        gpu.intensity = illuminance.extend(0.0);
                    }
                }
            }
            gpu
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The stack sizes the uploads check are the ones the shaders declare.
    #[test]
    fn stack_limits_match_the_shaders() {
        let glsl = include_str!("../../shaders/common/bvh.glsl");
        let declared = |name: &str| -> u32 {
            let line = glsl
                .lines()
                .find(|l| l.trim_start().starts_with(&format!("const int {name} = ")))
                .unwrap_or_else(|| panic!("bvh.glsl declares no {name}"));
            let value = line.split('=').nth(1).unwrap().split(';').next().unwrap();
            value.trim().parse().unwrap()
        };
        assert_eq!(declared("BVH_STACK_SIZE"), MAX_BVH_STACK);
        assert_eq!(declared("TOP_STACK_SIZE"), MAX_TOP_STACK);
        assert_eq!(declared("BVH8_STACK_SIZE"), MAX_BVH8_STACK);
        assert_eq!(declared("BVH8_TOP_STACK_SIZE"), MAX_TOP_STACK_GPU);
    }
}
