//! glTF 2.0 → [`Scene`]: walks the node hierarchy and flattens every camera, punctual light and
//! mesh placed by one node into world space; a mesh placed by several nodes is read once in object
//! space and placed by instances ([`crate::instancing`]). Order matters for safety: the document is validated
//! (`validate`) and the geometry budget checked from accessor counts before any buffer is read;
//! buffers and images are read through `source` (inside the scene's folder, regular files,
//! bounded), images decoded in `images` (only those rendered materials sample), materials
//! converted in `load_material`, per-primitive vertex work (missing normals/tangents,
//! transforms) done in `geometry`.

use crate::geometry::{self, PrimitiveData};
use crate::images::{decode_images, ImageInputs};
use crate::instancing::{Instance, InstancedMesh};
use crate::limits::{over_budget, ByteBudget, LoadLimits, INSTANCES, TRIANGLES};
use crate::load_material::{convert_material, images_used};
use crate::source::{self, ReadError, Uri};
use crate::validate;
use crate::{Camera, Material, PunctualLight, Scene, SceneError, Triangle, Vertex};
use glam::{Mat4, Vec2, Vec3, Vec4};
use gltf::khr_lights_punctual::Kind as LightKindGltf;
use gltf::mesh::Mode;
use std::path::{Path, PathBuf};

/// Extensions we honour; a file that *requires* anything else is refused with its name, since
/// rendering it without the extension would be silently wrong (e.g. compressed geometry).
/// Extensions that are only *used* are optional by definition and are ignored when unknown.
pub(crate) const SUPPORTED_REQUIRED_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_materials_specular",
    "KHR_materials_ior",
    "KHR_texture_transform",
];

/// Extensions the loader reads when present (beyond the required-capable ones above). Others in
/// `extensionsUsed` are listed once in [`Scene::warnings`].
const UNDERSTOOD_EXTENSIONS: &[&str] = SUPPORTED_REQUIRED_EXTENSIONS;

struct Loader<'a> {
    file: PathBuf,
    buffers: &'a [Vec<u8>],
    scene: Scene,
    /// Index of the appended default material, created the first time a primitive needs it.
    default_material: Option<u32>,
    /// Per glTF mesh: how many nodes place it (≥ 2: instanced).
    placements: Vec<u32>,
    /// Per glTF mesh: its [`InstancedMesh`], once read.
    instanced: Vec<Option<u32>>,
}

/// A node placed in the world: every mesh, camera and light the scene renders hangs off one.
struct Placed<'a> {
    node: gltf::Node<'a>,
    world: Mat4,
}

pub(crate) fn load(path: &Path, limits: &LoadLimits) -> Result<Scene, SceneError> {
    // The checks in `validate` cover every panicking path of the gltf crate we know of; this is
    // the backstop for ones we don't, so malformed input can never take the renderer down.
    std::panic::catch_unwind(|| load_unguarded(path, limits)).unwrap_or_else(|panic| {
        let what = panic
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned());
        Err(SceneError::Invalid {
            file: path.to_path_buf(),
            detail: format!("the glTF parser failed: {}", what.unwrap_or_default()),
        })
    })
}

/// The JSON text just before a parse error (where a value is refused, its key): the parser's
/// message names only a line and column. `bytes` is a .gltf file or a GLB (its JSON chunk).
fn json_context(bytes: &[u8], error: &serde_json::Error) -> Option<String> {
    const BEFORE: usize = 48;
    let json = match bytes.get(..4) {
        Some(b"glTF") => {
            let length = u32::from_le_bytes(bytes.get(12..16)?.try_into().ok()?) as usize;
            bytes.get(20..20usize.checked_add(length)?)?
        }
        _ => bytes,
    };
    let line = json
        .split(|&b| b == b'\n')
        .nth(error.line().checked_sub(1)?)?;
    let end = error.column().min(line.len());
    let start = end.saturating_sub(BEFORE);
    let near = String::from_utf8_lossy(&line[start..end]);
    let near: String = near.split_whitespace().collect::<Vec<_>>().join(" ");
    (!near.is_empty()).then(|| format!("{}{near}", if start > 0 { "…" } else { "" }))
}

/// A binary glTF's header length must cover the 12-byte header itself: the gltf crate subtracts
/// the header's size from it unchecked (an overflow panic where overflow checks are on).
fn check_glb_header(bytes: &[u8], file: &Path) -> Result<(), SceneError> {
    const HEADER: usize = 12;
    if bytes.len() < HEADER || &bytes[..4] != b"glTF" {
        return Ok(());
    }
    let length = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]);
    if (length as usize) < HEADER {
        return Err(SceneError::Malformed {
            file: file.to_path_buf(),
            detail: format!(
                "GLB header: length {length} is shorter than the {HEADER}-byte header itself"
            ),
        });
    }
    Ok(())
}

/// The whole load without the panic backstop (the fuzz test calls this, so a panic fails it).
pub(crate) fn load_unguarded(path: &Path, limits: &LoadLimits) -> Result<Scene, SceneError> {
    let file = path.to_path_buf();
    let mut budget = ByteBudget::new(limits.max_bytes);
    let bytes = read_scene_file(path, &mut budget)?;
    check_glb_header(&bytes, &file)?;
    let gltf::Gltf { document, blob } =
        gltf::Gltf::from_slice_without_validation(&bytes).map_err(|e| SceneError::Malformed {
            file: file.clone(),
            detail: match &e {
                gltf::Error::Deserialize(json) => match json_context(&bytes, json) {
                    Some(near) => format!("{e}, at `{near}`"),
                    None => e.to_string(),
                },
                _ => e.to_string(),
            },
        })?;
    drop(bytes);

    let mut warnings = Vec::new();
    let document = vetted_document(document, &file, &mut warnings)?;
    let placed = place_nodes(&document, &file)?;
    check_geometry_budget(&document, &placed, limits, &file)?;

    let folder = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let buffers = load_buffers(document.as_json(), folder, blob, &mut budget, &file)?;
    let used_materials = materials_used(&placed);
    let used_images = images_of(&document, &used_materials);
    let inputs = ImageInputs {
        file: &file,
        folder,
        buffers: &buffers,
        budget: &mut budget,
        max_texels: limits.max_texels,
    };
    let textures = decode_images(document.as_json(), &used_images, inputs)?;

    let placements = placements_per_mesh(&document, &placed, limits);
    let instanced = vec![None; placements.len()];
    let mut loader = Loader {
        file: file.clone(),
        buffers: &buffers,
        scene: Scene::default(),
        default_material: None,
        placements,
        instanced,
    };
    loader.scene.source = file.clone();
    loader.scene.warnings = warnings;
    loader.scene.textures = textures;
    let map = |image: usize| used_images.binary_search(&image).ok().map(|i| i as u32);
    let no_images = |_: usize| None;
    loader.scene.materials = document
        .materials()
        .map(|m| {
            convert_material(
                &m,
                if m.index().is_some_and(|i| used_materials.contains(&i)) {
                    &map
                } else {
                    &no_images
                },
            )
        })
        .collect();
    loader.scene.mesh_names = document
        .meshes()
        .map(|m| {
            m.name()
                .map(str::to_owned)
                .unwrap_or_else(|| format!("mesh{}", m.index()))
        })
        .collect();
    for p in &placed {
        loader.append_node(&p.node, p.world)?;
    }
    let flat = loader.scene.triangles.len();
    // check_geometry_budget bounds placed triangles far below 2³², so this cannot fail.
    loader
        .scene
        .instancing
        .assign_ids(flat)
        .ok_or_else(|| SceneError::Budget {
            file,
            detail: "placed triangles do not fit 32-bit ids".into(),
        })?;
    Ok(loader.scene)
}

/// The scene file itself: a regular file, read whole within the byte budget.
fn read_scene_file(path: &Path, budget: &mut ByteBudget) -> Result<Vec<u8>, SceneError> {
    let file = path.to_path_buf();
    source::read_bounded(path, None, budget, "the scene file").map_err(|e| match e {
        ReadError::Budget(detail) => SceneError::Budget { file, detail },
        ReadError::Open(source) | ReadError::Read(source) => SceneError::Io { file, source },
        other => SceneError::Io {
            file,
            source: std::io::Error::other(other.to_string()),
        },
    })
}

/// Extension policy and every check that must run before the gltf crate's accessors; returns
/// the validated document.
fn vetted_document(
    document: gltf::Document,
    file: &Path,
    warnings: &mut Vec<String>,
) -> Result<gltf::Document, SceneError> {
    // Check required extensions before the crate's validator: it knows only the extensions compiled
    // into it (not KHR_materials_specular) and reports others as a bare "Unsupported" path.
    for ext in document.extensions_required() {
        if !SUPPORTED_REQUIRED_EXTENSIONS.contains(&ext) {
            return Err(SceneError::Unsupported {
                file: file.to_path_buf(),
                feature: format!(
                    "required extension {ext} (supported: {})",
                    SUPPORTED_REQUIRED_EXTENSIONS.join(", ")
                ),
            });
        }
    }
    let ignored: Vec<&str> = document
        .extensions_used()
        .filter(|e| !UNDERSTOOD_EXTENSIONS.contains(e))
        .collect();
    if !ignored.is_empty() {
        warnings.push(format!(
            "ignoring extensions the renderer does not understand: {} (optional: the scene renders without them)",
            ignored.join(", ")
        ));
    }
    let mut json = document.into_json();
    json.extensions_required.clear(); // vetted above
    validate::check_json(&json, file)?;
    let document = gltf::Document::from_json(json).map_err(|e| SceneError::Invalid {
        file: file.to_path_buf(),
        detail: describe(e),
    })?;
    validate::check_document(&document, file)?;
    Ok(document)
}

/// Every node reachable from the scene's roots with its world transform, depth first in document
/// order. Refuses a hierarchy that is not a tree and transforms that are not finite.
fn place_nodes<'a>(
    document: &'a gltf::Document,
    file: &Path,
) -> Result<Vec<Placed<'a>>, SceneError> {
    let invalid = |detail: String| SceneError::Invalid {
        file: file.to_path_buf(),
        detail,
    };
    let roots: Vec<gltf::Node> = match document
        .default_scene()
        .or_else(|| document.scenes().next())
    {
        Some(scene) => scene.nodes().collect(),
        None => {
            // No scene: every node that is nobody's child is a root.
            let mut is_child = vec![false; document.nodes().len()];
            document
                .nodes()
                .flat_map(|n| n.children())
                .for_each(|c| is_child[c.index()] = true);
            document.nodes().filter(|n| !is_child[n.index()]).collect()
        }
    };
    // Depth-first with an explicit stack; `visited` turns a cyclic or shared hierarchy (invalid
    // glTF that the crate does not detect) into an error instead of an endless loop.
    let mut visited = vec![false; document.nodes().len()];
    let mut stack: Vec<(gltf::Node, Mat4)> = roots
        .into_iter()
        .rev()
        .map(|n| (n, Mat4::IDENTITY))
        .collect();
    let mut placed = Vec::new();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut visited[node.index()], true) {
            return Err(invalid(format!(
                "node {} is reached twice: the node hierarchy is not a tree",
                node.index()
            )));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if !world.is_finite() {
            return Err(invalid(format!(
                "nodes[{}]: its transform (or a parent's) is not finite",
                node.index()
            )));
        }
        let children: Vec<_> = node.children().collect();
        stack.extend(children.into_iter().rev().map(|c| (c, world)));
        placed.push(Placed { node, world });
    }
    Ok(placed)
}

/// Triangles and vertices one primitive will produce, from its accessor counts alone (no data
/// read), mirroring what `append_primitive` and `geometry` build.
fn primitive_size(json: &gltf::json::Root, prim: &gltf::json::mesh::Primitive) -> (u64, u64) {
    use gltf::json::validation::Checked;
    let count = |index: usize| json.accessors.get(index).map_or(0, |a| a.count.0);
    let positions = prim
        .attributes
        .get(&Checked::Valid(gltf::Semantic::Positions))
        .map_or(0, |i| count(i.value()));
    let corners = prim.indices.map_or(positions, |i| count(i.value()));
    let triangles = match prim.mode {
        Checked::Valid(Mode::Triangles) => corners / 3,
        Checked::Valid(Mode::TriangleStrip | Mode::TriangleFan) => corners.saturating_sub(2),
        _ => 0,
    };
    // Without normals every corner becomes its own vertex (flat shading).
    let has_normals = prim
        .attributes
        .contains_key(&Checked::Valid(gltf::Semantic::Normals));
    (
        triangles,
        if has_normals {
            positions
        } else {
            triangles.saturating_mul(3)
        },
    )
}

/// How many nodes place each glTF mesh, as instancing sees it: all 1 (everything flattened)
/// when the scene places no more than `limits.instance_above` triangles.
fn placements_per_mesh(
    document: &gltf::Document,
    placed: &[Placed],
    limits: &LoadLimits,
) -> Vec<u32> {
    let mut n = vec![0u32; document.meshes().len()];
    placed
        .iter()
        .filter_map(|p| p.node.mesh())
        .for_each(|m| n[m.index()] += 1);
    let json = document.as_json();
    let placed_triangles = json.meshes.iter().zip(&n).fold(0u64, |sum, (m, &k)| {
        let tris = m
            .primitives
            .iter()
            .fold(0u64, |t, p| t.saturating_add(primitive_size(json, p).0));
        sum.saturating_add(tris.saturating_mul(u64::from(k)))
    });
    if placed_triangles <= limits.instance_above {
        n.iter_mut().for_each(|k| *k = (*k).min(1));
    }
    n
}

/// Refuses, before any geometry is read, a scene whose uploaded triangles (or vertices), instances
/// or placed triangles exceed what the renderer takes: a mesh placed once is uploaded once (its
/// world-space copy), a mesh placed by several nodes once plus one instance per node (an extra
/// flattened copy per node with a singular transform), and every placed triangle needs a 32-bit id.
fn check_geometry_budget(
    document: &gltf::Document,
    placed: &[Placed],
    limits: &LoadLimits,
    file: &Path,
) -> Result<(), SceneError> {
    let json = document.as_json();
    let sizes: Vec<(u64, u64)> = json
        .meshes
        .iter()
        .map(|m| {
            m.primitives
                .iter()
                .map(|p| primitive_size(json, p))
                .fold((0u64, 0u64), |a, b| {
                    (a.0.saturating_add(b.0), a.1.saturating_add(b.1))
                })
        })
        .collect();
    let placements = placements_per_mesh(document, placed, limits);
    // Per mesh: copies uploaded, and instances.
    let mut copies = vec![0u64; sizes.len()];
    let mut instances = vec![0u64; sizes.len()];
    for m in placed
        .iter()
        .filter_map(|p| p.node.mesh().map(|m| (m.index(), p.world)))
    {
        match (placements[m.0] >= 2, invertible(m.1)) {
            (true, true) => instances[m.0] += 1,
            _ => copies[m.0] += 1,
        }
    }
    let uploaded = |m: usize| copies[m] + u64::from(instances[m] > 0);
    let total = |pick: fn(&(u64, u64)) -> u64, count: &dyn Fn(usize) -> u64| {
        (0..sizes.len()).fold(0u64, |sum, m| {
            sum.saturating_add(pick(&sizes[m]).saturating_mul(count(m)))
        })
    };
    let name = |m: usize| {
        document
            .meshes()
            .nth(m)
            .and_then(|m| m.name().map(str::to_owned))
            .unwrap_or_else(|| format!("mesh{m}"))
    };
    let fail = |budget, limit, what: String| SceneError::Budget {
        file: file.to_path_buf(),
        detail: over_budget(budget, limit, what),
    };
    let (triangles, vertices) = (total(|s| s.0, &uploaded), total(|s| s.1, &uploaded));
    if triangles > limits.max_triangles {
        let largest = (0..sizes.len())
            .max_by_key(|&m| sizes[m].0.saturating_mul(uploaded(m)))
            .unwrap_or(0);
        return Err(fail(&TRIANGLES, limits.max_triangles, format!(
            "meshes: {triangles} triangles to upload (the largest share: mesh '{}', {} triangles × {} copies; a mesh placed by several nodes is uploaded once and instanced)",
            name(largest), sizes[largest].0, uploaded(largest)
        )));
    }
    if vertices > limits.max_triangles.saturating_mul(3) {
        return Err(fail(
            &TRIANGLES,
            limits.max_triangles,
            format!("meshes: {vertices} vertices to upload (3 per budgeted triangle at most)"),
        ));
    }
    let instance_count: u64 = instances.iter().sum();
    if instance_count > limits.max_instances {
        let most = (0..sizes.len()).max_by_key(|&m| instances[m]).unwrap_or(0);
        return Err(fail(
            &INSTANCES,
            limits.max_instances,
            format!(
                "nodes: {instance_count} mesh instances (the most: mesh '{}', placed by {} nodes)",
                name(most),
                instances[most]
            ),
        ));
    }
    let placed_triangles = total(|s| s.0, &|m| copies[m] + instances[m]);
    if placed_triangles >= u64::from(u32::MAX) {
        return Err(SceneError::Budget { file: file.to_path_buf(), detail: format!(
            "nodes: {placed_triangles} placed triangles (each node's copy or instance of its mesh counts): every placed triangle needs a 32-bit id, at most {}", u32::MAX - 1
        )});
    }
    Ok(())
}

/// Buffer data, each exactly its declared `byteLength` (a shorter source is an error; a longer one
/// is read only that far).
fn load_buffers(
    json: &gltf::json::Root,
    folder: &Path,
    mut blob: Option<Vec<u8>>,
    budget: &mut ByteBudget,
    file: &Path,
) -> Result<Vec<Vec<u8>>, SceneError> {
    let mut out = Vec::with_capacity(json.buffers.len());
    for (i, buffer) in json.buffers.iter().enumerate() {
        let item = format!("buffers[{i}]");
        let declared = buffer.byte_length.0;
        let fail = |uri: &str, reason: String| SceneError::Reference {
            file: file.to_path_buf(),
            item: item.clone(),
            uri: source::display_uri(uri),
            reason,
        };
        let data = match &buffer.uri {
            // GLB: the first buffer without a uri is the binary chunk (already read with the file).
            None => {
                let mut bin = blob.take().ok_or_else(|| {
                    fail(
                        "",
                        "no uri, and there is no (further) GLB binary chunk".into(),
                    )
                })?;
                if (bin.len() as u64) < declared {
                    return Err(fail(
                        "",
                        format!(
                            "the GLB binary chunk has {} bytes but byteLength declares {declared}",
                            bin.len()
                        ),
                    ));
                }
                bin.truncate(declared as usize);
                bin
            }
            Some(uri) => {
                match source::parse_uri(uri).map_err(|reason| fail(uri, reason))? {
                    Uri::Data { payload, .. } => {
                        let mut data = source::decode_data_uri(payload, budget, &item)
                            .map_err(|reason| fail(uri, reason))?;
                        if (data.len() as u64) < declared {
                            return Err(fail(uri, format!("the data URI holds {} bytes but byteLength declares {declared}", data.len())));
                        }
                        data.truncate(declared as usize);
                        data
                    }
                    Uri::Relative(relative) => {
                        let path = source::resolve_inside(folder, &relative)
                            .map_err(|reason| fail(uri, reason))?;
                        source::read_bounded(&path, Some(declared), budget, &item).map_err(|e| {
                            match e {
                                ReadError::Budget(detail) => SceneError::Budget {
                                    file: file.to_path_buf(),
                                    detail,
                                },
                                other => fail(uri, other.to_string()),
                            }
                        })?
                    }
                }
            }
        };
        out.push(data);
    }
    Ok(out)
}

/// Materials some placed mesh primitive uses, sorted.
fn materials_used(placed: &[Placed]) -> Vec<usize> {
    let mut used: Vec<usize> = placed
        .iter()
        .filter_map(|p| p.node.mesh())
        .flat_map(|m| {
            m.primitives()
                .filter_map(|p| p.material().index())
                .collect::<Vec<_>>()
        })
        .collect();
    used.sort_unstable();
    used.dedup();
    used
}

/// Images the used materials sample, sorted and unique (their order in [`Scene::textures`]).
fn images_of(document: &gltf::Document, materials: &[usize]) -> Vec<usize> {
    let mut images: Vec<usize> = document
        .materials()
        .filter(|m| m.index().is_some_and(|i| materials.contains(&i)))
        .flat_map(|m| images_used(&m))
        .collect();
    images.sort_unstable();
    images.dedup();
    images
}

/// Whether rays can be taken into the node's object space (a finite inverse).
fn invertible(world: Mat4) -> bool {
    let det = glam::Mat3::from_mat4(world).determinant();
    det != 0.0 && det.is_finite() && world.inverse().is_finite()
}

fn describe(e: gltf::Error) -> String {
    match e {
        gltf::Error::Validation(list) => list
            .iter()
            .map(|(path, err)| format!("{path}: {err}"))
            .collect::<Vec<_>>()
            .join("; "),
        other => other.to_string(),
    }
}

impl Loader<'_> {
    fn append_node(&mut self, node: &gltf::Node, world: Mat4) -> Result<(), SceneError> {
        if let Some(mesh) = node.mesh() {
            if self.placements[mesh.index()] >= 2 && invertible(world) {
                self.append_instance(&mesh, world)?;
            } else {
                // Placed once (or by a singular transform, which has no object-space ray).
                for primitive in mesh.primitives() {
                    self.append_primitive(&mesh, &primitive, world)?;
                }
            }
        }
        if let Some(camera) = node.camera() {
            self.append_camera(&camera, world);
        }
        if let Some(light) = node.light() {
            self.append_light(&light, world);
        }
        Ok(())
    }

    fn bad(&self, mesh: &gltf::Mesh, primitive: usize, problem: String) -> SceneError {
        let mesh = mesh
            .name()
            .map(str::to_owned)
            .unwrap_or_else(|| format!("mesh{}", mesh.index()));
        SceneError::BadPrimitive {
            file: self.file.clone(),
            mesh,
            primitive,
            problem,
        }
    }

    /// One placement of a mesh several nodes place: the mesh is read in object space the first
    /// time, and every placement adds an instance.
    fn append_instance(&mut self, mesh: &gltf::Mesh, world: Mat4) -> Result<(), SceneError> {
        let index = match self.instanced[mesh.index()] {
            Some(i) => i,
            None => {
                let mut object = InstancedMesh::default();
                for primitive in mesh.primitives() {
                    let (vertices, triangles) =
                        self.read_primitive(mesh, &primitive, Mat4::IDENTITY)?;
                    let base = object.vertices.len() as u32;
                    object.vertices.extend(vertices);
                    object
                        .triangles
                        .extend(triangles.into_iter().map(|t| Triangle {
                            indices: t.indices.map(|i| i + base),
                            ..t
                        }));
                }
                self.scene.instancing.meshes.push(object);
                let i = (self.scene.instancing.meshes.len() - 1) as u32;
                self.instanced[mesh.index()] = Some(i);
                i
            }
        };
        let object = &self.scene.instancing.meshes[index as usize];
        // Affine, so the corners of the object-space box bound every transformed position.
        let bounds = crate::Aabb::of_points(
            &object
                .vertices
                .iter()
                .map(|v| v.position)
                .collect::<Vec<_>>(),
        );
        let corners = (0..8).map(|k| {
            Vec3::select(
                glam::BVec3::new(k & 1 != 0, k & 2 != 0, k & 4 != 0),
                bounds.max,
                bounds.min,
            )
        });
        if !bounds.is_empty()
            && corners
                .map(|c| world.transform_point3(c))
                .any(|p| !p.is_finite())
        {
            return Err(self.bad(
                mesh,
                0,
                "world-space positions overflow f32 (the node transforms scale them too far)"
                    .into(),
            ));
        }
        self.scene.instancing.instances.push(Instance {
            mesh: index,
            world_from_object: world,
            first_id: 0,
        });
        Ok(())
    }

    fn append_primitive(
        &mut self,
        mesh: &gltf::Mesh,
        prim: &gltf::Primitive,
        world: Mat4,
    ) -> Result<(), SceneError> {
        let (vertices, tris) = self.read_primitive(mesh, prim, world)?;
        let base = self.scene.vertices.len() as u32;
        self.scene.vertices.extend(vertices);
        self.scene
            .triangles
            .extend(tris.into_iter().map(|t| Triangle {
                indices: t.indices.map(|i| i + base),
                ..t
            }));
        Ok(())
    }

    /// One primitive's vertices (transformed by `world`) and triangles (indices local to them).
    fn read_primitive(
        &mut self,
        mesh: &gltf::Mesh,
        prim: &gltf::Primitive,
        world: Mat4,
    ) -> Result<(Vec<Vertex>, Vec<Triangle>), SceneError> {
        let pi = prim.index();
        let mode = prim.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            return Err(SceneError::Unsupported {
                file: self.file.clone(),
                feature: format!(
                    "primitive mode {mode:?} in mesh '{}' primitive {pi} (only triangles, triangle strips and fans)",
                    mesh.name().unwrap_or("")
                ),
            });
        }
        let buffers = self.buffers;
        let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d[..]));
        let positions: Vec<Vec3> = match reader.read_positions() {
            Some(it) => it.map(Vec3::from).collect(),
            None => {
                return Err(self.bad(
                    mesh,
                    pi,
                    "POSITION is missing or its data is out of the buffer's range".into(),
                ))
            }
        };
        if let Some(k) = positions.iter().position(|p| !p.is_finite()) {
            return Err(self.bad(
                mesh,
                pi,
                format!(
                    "POSITION element {k} is {}: positions must be finite",
                    positions[k]
                ),
            ));
        }
        let n = positions.len();
        let expect_len = |what: &str, len: usize| -> Result<(), SceneError> {
            if len == n {
                Ok(())
            } else {
                Err(self.bad(
                    mesh,
                    pi,
                    format!("{what} has {len} elements but POSITION has {n}"),
                ))
            }
        };
        let normals: Option<Vec<Vec3>> =
            reader.read_normals().map(|it| it.map(Vec3::from).collect());
        let uvs: Option<Vec<Vec2>> = reader
            .read_tex_coords(0)
            .map(|it| it.into_f32().map(Vec2::from).collect());
        let tangents: Option<Vec<Vec4>> = reader
            .read_tangents()
            .map(|it| it.map(Vec4::from).collect());
        for (what, len) in [
            ("NORMAL", normals.as_ref().map(Vec::len)),
            ("TEXCOORD_0", uvs.as_ref().map(Vec::len)),
            ("TANGENT", tangents.as_ref().map(Vec::len)),
        ] {
            if let Some(len) = len {
                expect_len(what, len)?;
            }
        }
        let bad_uv = uvs
            .as_ref()
            .and_then(|v| v.iter().position(|u| !u.is_finite()));
        let bad_tangent = tangents
            .as_ref()
            .and_then(|v| v.iter().position(|t| !t.is_finite()));
        for (what, k) in [("TEXCOORD_0", bad_uv), ("TANGENT", bad_tangent)] {
            if let Some(k) = k {
                return Err(self.bad(mesh, pi, format!("{what} element {k} is not finite")));
            }
        }
        // Attributes that are declared but unreadable would otherwise be silently regenerated.
        for (semantic, read) in [
            (gltf::Semantic::Normals, normals.is_some()),
            (gltf::Semantic::TexCoords(0), uvs.is_some()),
            (gltf::Semantic::Tangents, tangents.is_some()),
        ] {
            if prim.get(&semantic).is_some() && !read {
                return Err(self.bad(
                    mesh,
                    pi,
                    format!("{semantic:?} data is out of the buffer's range"),
                ));
            }
        }
        let indices: Vec<u32> = match (prim.indices(), reader.read_indices()) {
            (None, _) => (0..n as u32).collect(),
            (Some(_), Some(it)) => it.into_u32().collect(),
            (Some(_), None) => {
                return Err(self.bad(mesh, pi, "indices data is out of the buffer's range".into()))
            }
        };
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= n) {
            return Err(self.bad(
                mesh,
                pi,
                format!("index {bad} is out of range (the primitive has {n} vertices)"),
            ));
        }
        let triangles = match mode {
            Mode::Triangles => {
                let leftover = indices.len() % 3;
                if leftover > 0 {
                    return Err(self.bad(
                        mesh,
                        pi,
                        format!("{} indices is not a multiple of 3", indices.len()),
                    ));
                }
                indices
                    .chunks_exact(3)
                    .map(|c| [c[0], c[1], c[2]])
                    .collect()
            }
            Mode::TriangleStrip => geometry::strip_to_triangles(&indices),
            _ => geometry::fan_to_triangles(&indices),
        };

        let material = match prim.material().index() {
            Some(i) => i as u32,
            None => self.default_material_index(),
        };
        let needs_tangents = self.scene.materials[material as usize]
            .normal_texture
            .is_some();
        let data = PrimitiveData {
            positions,
            normals,
            uvs,
            tangents,
            triangles,
        };
        let (vertices, tris) = geometry::build_world_vertices(data, needs_tangents, world);
        if vertices.iter().any(|v| !v.position.is_finite()) {
            return Err(self.bad(
                mesh,
                pi,
                "world-space positions overflow f32 (the node transforms scale them too far)"
                    .into(),
            ));
        }
        let mesh_id = mesh.index() as u32;
        Ok((
            vertices,
            tris.into_iter()
                .map(|t| Triangle {
                    indices: t,
                    material,
                    mesh: mesh_id,
                })
                .collect(),
        ))
    }

    fn default_material_index(&mut self) -> u32 {
        *self.default_material.get_or_insert_with(|| {
            self.scene.materials.push(Material::default());
            (self.scene.materials.len() - 1) as u32
        })
    }

    /// Orthographic cameras are skipped: the tracer has only a perspective model.
    fn append_camera(&mut self, camera: &gltf::Camera, world: Mat4) {
        if let gltf::camera::Projection::Perspective(p) = camera.projection() {
            let (_scale, rotation, translation) = world.to_scale_rotation_translation();
            let name = camera
                .name()
                .map(str::to_owned)
                .unwrap_or_else(|| format!("camera{}", camera.index()));
            self.scene.cameras.push(Camera {
                world_from_view: Mat4::from_rotation_translation(rotation.normalize(), translation),
                yfov: p.yfov(),
                aspect: p.aspect_ratio(),
                znear: p.znear(),
                name,
            });
        }
    }

    /// glTF lights shine along the node's −Z; intensities are colour × intensity.
    fn append_light(&mut self, light: &gltf::khr_lights_punctual::Light, world: Mat4) {
        let power = Vec3::from(light.color()) * light.intensity();
        let position = world.transform_point3(Vec3::ZERO);
        let direction = world
            .transform_vector3(Vec3::NEG_Z)
            .normalize_or(Vec3::NEG_Z);
        let range = light.range();
        self.scene.punctual_lights.push(match light.kind() {
            LightKindGltf::Point => PunctualLight::Point {
                position,
                intensity: power,
                range,
            },
            LightKindGltf::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => PunctualLight::Spot {
                position,
                direction,
                intensity: power,
                range,
                inner_cone: inner_cone_angle,
                outer_cone: outer_cone_angle,
            },
            LightKindGltf::Directional => PunctualLight::Directional {
                direction,
                illuminance: power,
            },
        });
    }
}
