//! A small glTF 2.0 writer: meshes, materials, PNG textures, nodes, cameras and lights into one
//! JSON document whose single binary buffer is embedded as a base64 data URI.

use super::shapes::MeshData;
use base64::Engine;
use serde_json::{json, Value};
use std::collections::BTreeSet;

#[derive(Default)]
pub struct GltfWriter {
    buffer: Vec<u8>,
    buffer_views: Vec<Value>,
    accessors: Vec<Value>,
    meshes: Vec<Value>,
    /// Triangles per mesh, to count the flattened scene's triangles.
    mesh_triangles: Vec<usize>,
    materials: Vec<Value>,
    images: Vec<Value>,
    textures: Vec<Value>,
    nodes: Vec<Value>,
    root_nodes: Vec<usize>,
    cameras: Vec<Value>,
    lights: Vec<Value>,
    extensions_used: BTreeSet<&'static str>,
    /// Triangles after instancing (what the loader will produce).
    pub scene_triangles: usize,
}

impl GltfWriter {
    /// Appends bytes as a new buffer view (4-byte aligned, as accessors require).
    fn push_view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        let padding = (4 - self.buffer.len() % 4) % 4;
        self.buffer.resize(self.buffer.len() + padding, 0);
        let mut view =
            json!({"buffer": 0, "byteOffset": self.buffer.len(), "byteLength": bytes.len()});
        if let Some(target) = target {
            view["target"] = json!(target);
        }
        self.buffer.extend_from_slice(bytes);
        self.buffer_views.push(view);
        self.buffer_views.len() - 1
    }

    fn push_accessor(&mut self, accessor: Value) -> usize {
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    fn float_accessor(
        &mut self,
        data: &[f32],
        components: usize,
        kind: &str,
        with_bounds: bool,
    ) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.push_view(&bytes, Some(34962));
        let mut accessor = json!({"bufferView": view, "componentType": 5126, "count": data.len() / components, "type": kind});
        if with_bounds {
            // POSITION accessors must carry min/max (glTF §5.1.1).
            let mut min = vec![f32::INFINITY; components];
            let mut max = vec![f32::NEG_INFINITY; components];
            for chunk in data.chunks_exact(components) {
                for c in 0..components {
                    min[c] = min[c].min(chunk[c]);
                    max[c] = max[c].max(chunk[c]);
                }
            }
            accessor["min"] = json!(min);
            accessor["max"] = json!(max);
        }
        self.push_accessor(accessor)
    }

    /// One mesh with one indexed triangle primitive; returns the mesh index.
    pub fn add_mesh(&mut self, name: &str, mesh: &MeshData, material: usize) -> usize {
        let positions: Vec<f32> = mesh.positions.iter().flat_map(|p| p.to_array()).collect();
        let normals: Vec<f32> = mesh.normals.iter().flat_map(|n| n.to_array()).collect();
        let uvs: Vec<f32> = mesh.uvs.iter().flat_map(|t| t.to_array()).collect();
        let position = self.float_accessor(&positions, 3, "VEC3", true);
        let normal = self.float_accessor(&normals, 3, "VEC3", false);
        let uv = self.float_accessor(&uvs, 2, "VEC2", false);
        // 16-bit indices when they fit: half the bytes for every small mesh.
        let (bytes, component): (Vec<u8>, u32) = if mesh.positions.len() <= u16::MAX as usize {
            (
                mesh.indices
                    .iter()
                    .flat_map(|&i| (i as u16).to_le_bytes())
                    .collect(),
                5123,
            )
        } else {
            (
                mesh.indices.iter().flat_map(|i| i.to_le_bytes()).collect(),
                5125,
            )
        };
        let view = self.push_view(&bytes, Some(34963));
        let indices = self.push_accessor(json!({"bufferView": view, "componentType": component, "count": mesh.indices.len(), "type": "SCALAR"}));
        self.meshes.push(json!({
            "name": name,
            "primitives": [{"attributes": {"POSITION": position, "NORMAL": normal, "TEXCOORD_0": uv}, "indices": indices, "material": material}]
        }));
        self.mesh_triangles.push(mesh.indices.len() / 3);
        self.meshes.len() - 1
    }

    /// `material` is a glTF material object; extensions it names are recorded as used.
    pub fn add_material(&mut self, material: Value) -> usize {
        if let Some(ext) = material.get("extensions").and_then(Value::as_object) {
            for (name, known) in [
                ("KHR_materials_specular", "KHR_materials_specular"),
                (
                    "KHR_materials_emissive_strength",
                    "KHR_materials_emissive_strength",
                ),
                ("KHR_materials_ior", "KHR_materials_ior"),
            ] {
                if ext.contains_key(name) {
                    self.extensions_used.insert(known);
                }
            }
        }
        self.materials.push(material);
        self.materials.len() - 1
    }

    /// Embeds PNG bytes as an image + texture (repeat wrapping, trilinear); returns the texture index.
    pub fn add_png_texture(&mut self, name: &str, png: &[u8]) -> usize {
        let view = self.push_view(png, None);
        self.images
            .push(json!({"name": name, "bufferView": view, "mimeType": "image/png"}));
        self.textures
            .push(json!({"source": self.images.len() - 1, "sampler": 0}));
        self.textures.len() - 1
    }

    /// Adds a root node; returns its index.
    pub fn add_root_node(&mut self, node: Value) -> usize {
        if let Some(mesh) = node.get("mesh").and_then(Value::as_u64) {
            self.scene_triangles += self.mesh_triangles[mesh as usize];
        }
        self.nodes.push(node);
        self.root_nodes.push(self.nodes.len() - 1);
        self.nodes.len() - 1
    }

    /// A perspective camera at `translation` with rotation quaternion `rotation` (xyzw).
    pub fn add_camera(
        &mut self,
        name: &str,
        yfov: f32,
        aspect: f32,
        translation: [f32; 3],
        rotation: [f32; 4],
    ) {
        self.cameras.push(json!({"name": name, "type": "perspective", "perspective": {"yfov": yfov, "aspectRatio": aspect, "znear": 0.01}}));
        self.add_root_node(json!({"name": name, "camera": self.cameras.len() - 1, "translation": translation, "rotation": rotation}));
    }

    /// A KHR_lights_punctual light (`light` is its JSON object) on a node with `transform` fields.
    pub fn add_light(&mut self, light: Value, mut node: Value) {
        self.extensions_used.insert("KHR_lights_punctual");
        self.lights.push(light);
        node["extensions"] = json!({"KHR_lights_punctual": {"light": self.lights.len() - 1}});
        self.add_root_node(node);
    }

    pub fn finish(self) -> Value {
        let uri = format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&self.buffer)
        );
        let mut doc = json!({
            "asset": {"version": "2.0", "generator": "fovea scenegen"},
            "scene": 0,
            "scenes": [{"nodes": self.root_nodes}],
            "nodes": self.nodes,
            "meshes": self.meshes,
            "materials": self.materials,
            "accessors": self.accessors,
            "bufferViews": self.buffer_views,
            "buffers": [{"byteLength": self.buffer.len(), "uri": uri}],
        });
        if !self.cameras.is_empty() {
            doc["cameras"] = json!(self.cameras);
        }
        if !self.textures.is_empty() {
            doc["images"] = json!(self.images);
            doc["textures"] = json!(self.textures);
            // 10497 = REPEAT, 9729 = LINEAR, 9987 = LINEAR_MIPMAP_LINEAR.
            doc["samplers"] =
                json!([{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}]);
        }
        if !self.lights.is_empty() {
            doc["extensions"] = json!({"KHR_lights_punctual": {"lights": self.lights}});
        }
        if !self.extensions_used.is_empty() {
            doc["extensionsUsed"] = json!(self.extensions_used);
        }
        doc
    }
}
