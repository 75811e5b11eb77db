//! glTF 2.0 → [`Scene`]: walks the node hierarchy and flattens every mesh primitive, camera and
//! punctual light into world space. Materials and images are converted in `load_material`,
//! per-primitive vertex work (missing normals/tangents, transforms) in `geometry`.

use crate::geometry::{self, PrimitiveData};
use crate::load_material::{convert_images, convert_material};
use crate::{Camera, Material, PunctualLight, Scene, SceneError, Triangle};
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
];

struct Loader<'a> {
    file: PathBuf,
    buffers: &'a [gltf::buffer::Data],
    scene: Scene,
    /// Index of the appended default material, created the first time a primitive needs it.
    default_material: Option<u32>,
}

pub(crate) fn load(path: &Path) -> Result<Scene, SceneError> {
    // The checks below cover every panicking path of the gltf crate we know of; this is the
    // backstop for ones we don't, so malformed input can never take the renderer down.
    std::panic::catch_unwind(|| load_unguarded(path)).unwrap_or_else(|panic| {
        let what = panic.downcast_ref::<&str>().map(|s| s.to_string()).or_else(|| panic.downcast_ref::<String>().cloned());
        Err(SceneError::Invalid { file: path.to_path_buf(), detail: format!("the glTF parser failed: {}", what.unwrap_or_default()) })
    })
}

fn load_unguarded(path: &Path) -> Result<Scene, SceneError> {
    let file = path.to_path_buf();
    let bytes = std::fs::read(path).map_err(|source| SceneError::Io { file: file.clone(), source })?;
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice_without_validation(&bytes)
        .map_err(|e| SceneError::Malformed { file: file.clone(), detail: e.to_string() })?;

    // Check required extensions before the crate's validator: it knows only the extensions compiled
    // into it (not KHR_materials_specular) and reports others as a bare "Unsupported" path.
    for ext in document.extensions_required() {
        if !SUPPORTED_REQUIRED_EXTENSIONS.contains(&ext) {
            return Err(SceneError::Unsupported {
                file,
                feature: format!("required extension {ext} (supported: {})", SUPPORTED_REQUIRED_EXTENSIONS.join(", ")),
            });
        }
    }
    let mut json = document.into_json();
    json.extensions_required.clear(); // vetted above
    check_images_have_sources(&json, &file)?;
    check_position_accessors_exist(&json, &file)?;
    let document = gltf::Document::from_json(json).map_err(|e| SceneError::Invalid { file: file.clone(), detail: describe(e) })?;

    let base = path.parent().map(|p| if p.as_os_str().is_empty() { Path::new(".") } else { p });
    let data_err = |e: gltf::Error| SceneError::Data { file: file.clone(), detail: e.to_string() };
    let buffers = gltf::import_buffers(&document, base, blob).map_err(data_err)?;
    let images = gltf::import_images(&document, base, &buffers).map_err(data_err)?;

    let mut loader = Loader { file: file.clone(), buffers: &buffers, scene: Scene::default(), default_material: None };
    loader.scene.source = file.clone();
    loader.scene.textures = convert_images(images, &file)?;
    loader.scene.materials = document.materials().map(|m| convert_material(&m)).collect();
    loader.scene.mesh_names =
        document.meshes().map(|m| m.name().map(str::to_owned).unwrap_or_else(|| format!("mesh{}", m.index()))).collect();
    loader.walk_nodes(&document)?;
    Ok(loader.scene)
}

/// `gltf::image::Image::source` unwraps a missing uri / mimeType; refuse such files first.
fn check_images_have_sources(json: &gltf::json::Root, file: &Path) -> Result<(), SceneError> {
    for (i, image) in json.images.iter().enumerate() {
        let ok = image.uri.is_some() || (image.buffer_view.is_some() && image.mime_type.is_some());
        if !ok {
            return Err(SceneError::Invalid {
                file: file.to_path_buf(),
                detail: format!("images[{i}] needs a uri, or a bufferView with a mimeType"),
            });
        }
    }
    Ok(())
}

/// gltf-json 1.4.1's validator indexes `accessors[POSITION]` unchecked (mesh.rs:151).
fn check_position_accessors_exist(json: &gltf::json::Root, file: &Path) -> Result<(), SceneError> {
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let position = prim.attributes.get(&gltf::json::validation::Checked::Valid(gltf::Semantic::Positions));
            if let Some(index) = position.filter(|i| i.value() >= json.accessors.len()) {
                return Err(SceneError::Invalid {
                    file: file.to_path_buf(),
                    detail: format!(
                        "meshes[{m}].primitives[{p}].attributes.POSITION = {}: index out of range (there are {} accessors)",
                        index.value(),
                        json.accessors.len()
                    ),
                });
            }
        }
    }
    Ok(())
}

fn describe(e: gltf::Error) -> String {
    match e {
        gltf::Error::Validation(list) => {
            list.iter().map(|(path, err)| format!("{path}: {err}")).collect::<Vec<_>>().join("; ")
        }
        other => other.to_string(),
    }
}

impl Loader<'_> {
    fn walk_nodes(&mut self, document: &gltf::Document) -> Result<(), SceneError> {
        let roots: Vec<gltf::Node> = match document.default_scene().or_else(|| document.scenes().next()) {
            Some(scene) => scene.nodes().collect(),
            None => {
                // No scene: every node that is nobody's child is a root.
                let mut is_child = vec![false; document.nodes().len()];
                document.nodes().flat_map(|n| n.children()).for_each(|c| is_child[c.index()] = true);
                document.nodes().filter(|n| !is_child[n.index()]).collect()
            }
        };
        // Depth-first with an explicit stack; `visited` turns a cyclic or shared hierarchy (invalid
        // glTF that the crate does not detect) into an error instead of an endless loop.
        let mut visited = vec![false; document.nodes().len()];
        let mut stack: Vec<(gltf::Node, Mat4)> = roots.into_iter().rev().map(|n| (n, Mat4::IDENTITY)).collect();
        while let Some((node, parent)) = stack.pop() {
            if std::mem::replace(&mut visited[node.index()], true) {
                return Err(SceneError::Invalid {
                    file: self.file.clone(),
                    detail: format!("node {} is reached twice: the node hierarchy is not a tree", node.index()),
                });
            }
            let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
            if let Some(mesh) = node.mesh() {
                for primitive in mesh.primitives() {
                    self.append_primitive(&mesh, &primitive, world)?;
                }
            }
            if let Some(camera) = node.camera() {
                self.append_camera(&camera, world);
            }
            if let Some(light) = node.light() {
                self.append_light(&light, world);
            }
            let children: Vec<_> = node.children().collect();
            stack.extend(children.into_iter().rev().map(|c| (c, world)));
        }
        Ok(())
    }

    fn bad(&self, mesh: &gltf::Mesh, primitive: usize, problem: String) -> SceneError {
        let mesh = mesh.name().map(str::to_owned).unwrap_or_else(|| format!("mesh{}", mesh.index()));
        SceneError::BadPrimitive { file: self.file.clone(), mesh, primitive, problem }
    }

    fn append_primitive(&mut self, mesh: &gltf::Mesh, prim: &gltf::Primitive, world: Mat4) -> Result<(), SceneError> {
        let pi = prim.index();
        let mode = prim.mode();
        if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
            return Err(SceneError::Unsupported {
                file: self.file.clone(),
                feature: format!(
                    "primitive mode {mode:?} in mesh '{}' primitive {pi} (only triangles, triangle strips and fans)",
                    mesh.name().unwrap_or("")
                ),
            });
        }
        let buffers = self.buffers;
        let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
        let positions: Vec<Vec3> = match reader.read_positions() {
            Some(it) => it.map(Vec3::from).collect(),
            None => return Err(self.bad(mesh, pi, "POSITION is missing or its data is out of the buffer's range".into())),
        };
        let n = positions.len();
        let expect_len = |what: &str, len: usize| -> Result<(), SceneError> {
            if len == n { Ok(()) } else { Err(self.bad(mesh, pi, format!("{what} has {len} elements but POSITION has {n}"))) }
        };
        let normals: Option<Vec<Vec3>> = reader.read_normals().map(|it| it.map(Vec3::from).collect());
        let uvs: Option<Vec<Vec2>> = reader.read_tex_coords(0).map(|it| it.into_f32().map(Vec2::from).collect());
        let tangents: Option<Vec<Vec4>> = reader.read_tangents().map(|it| it.map(Vec4::from).collect());
        for (what, len) in [("NORMAL", normals.as_ref().map(Vec::len)), ("TEXCOORD_0", uvs.as_ref().map(Vec::len)), ("TANGENT", tangents.as_ref().map(Vec::len))] {
            if let Some(len) = len {
                expect_len(what, len)?;
            }
        }
        // Attributes that are declared but unreadable would otherwise be silently regenerated.
        for (semantic, read) in [(gltf::Semantic::Normals, normals.is_some()), (gltf::Semantic::TexCoords(0), uvs.is_some()), (gltf::Semantic::Tangents, tangents.is_some())] {
            if prim.get(&semantic).is_some() && !read {
                return Err(self.bad(mesh, pi, format!("{semantic:?} data is out of the buffer's range")));
            }
        }
        let indices: Vec<u32> = match (prim.indices(), reader.read_indices()) {
            (None, _) => (0..n as u32).collect(),
            (Some(_), Some(it)) => it.into_u32().collect(),
            (Some(_), None) => return Err(self.bad(mesh, pi, "indices data is out of the buffer's range".into())),
        };
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= n) {
            return Err(self.bad(mesh, pi, format!("index {bad} is out of range (the primitive has {n} vertices)")));
        }
        let triangles = match mode {
            Mode::Triangles => {
                let leftover = indices.len() % 3;
                if leftover > 0 {
                    return Err(self.bad(mesh, pi, format!("{} indices is not a multiple of 3", indices.len())));
                }
                indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
            }
            Mode::TriangleStrip => geometry::strip_to_triangles(&indices),
            _ => geometry::fan_to_triangles(&indices),
        };

        let material = match prim.material().index() {
            Some(i) => i as u32,
            None => self.default_material_index(),
        };
        let needs_tangents = self.scene.materials[material as usize].normal_texture.is_some();
        let data = PrimitiveData { positions, normals, uvs, tangents, triangles };
        let (vertices, tris) = geometry::build_world_vertices(data, needs_tangents, world);
        let base = self.scene.vertices.len() as u32;
        self.scene.vertices.extend(vertices);
        let mesh_id = mesh.index() as u32;
        self.scene.triangles.extend(tris.into_iter().map(|t| Triangle { indices: t.map(|i| i + base), material, mesh: mesh_id }));
        Ok(())
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
            let name = camera.name().map(str::to_owned).unwrap_or_else(|| format!("camera{}", camera.index()));
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
        let direction = world.transform_vector3(Vec3::NEG_Z).normalize_or(Vec3::NEG_Z);
        let range = light.range();
        self.scene.punctual_lights.push(match light.kind() {
            LightKindGltf::Point => PunctualLight::Point { position, intensity: power, range },
            LightKindGltf::Spot { inner_cone_angle, outer_cone_angle } => PunctualLight::Spot {
                position,
                direction,
                intensity: power,
                range,
                inner_cone: inner_cone_angle,
                outer_cone: outer_cone_angle,
            },
            LightKindGltf::Directional => PunctualLight::Directional { direction, illuminance: power },
        });
    }
}
