//! Generators for the scenes the project owns. They WRITE glTF 2.0 (JSON `.gltf` with the binary
//! buffer and PNG images embedded as base64), reproducibly: same code, same bytes.
//!
//! Regenerate the stored scenes (`scenes/cornell-box.gltf`, `scenes/stress.gltf`) with
//! `cargo test -p fovea-tools --lib scenegen::tests::regenerate_owned_scenes -- --ignored`;
//! a normal test run fails if the stored files differ from what the generators write.
//! The large scene is generated on demand (`fovea gen-scene`, benchmarks), never stored.

mod cornell;
pub mod gltf_writer;
mod large;
pub mod shapes;
mod stress;
mod textures;

use anyhow::{bail, Context};
use std::path::Path;

/// Triangle count of the default large scene: Sponza-class (Crytek Sponza has ~262k).
pub const DEFAULT_LARGE_TRIANGLES: usize = 250_000;

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SceneKind {
    CornellBox,
    Stress,
    Large { min_triangles: usize },
}

impl SceneKind {
    /// File name the project uses for the scene (`scenes/<name>`).
    pub fn file_name(&self) -> &'static str {
        match self {
            SceneKind::CornellBox => "cornell-box.gltf",
            SceneKind::Stress => "stress.gltf",
            SceneKind::Large { .. } => "large.gltf",
        }
    }
}

/// What was written.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SceneStats {
    /// Triangles after instancing, i.e. what `fovea_scene::Scene::load` will produce.
    pub triangles: usize,
    pub meshes: usize,
    pub nodes: usize,
    pub materials: usize,
    pub textures: usize,
    pub bytes: usize,
}

/// Builds the scene's glTF JSON in memory.
pub fn scene_json(kind: &SceneKind) -> (serde_json::Value, usize) {
    let writer = match kind {
        SceneKind::CornellBox => cornell::build(),
        SceneKind::Stress => stress::build(),
        SceneKind::Large { min_triangles } => large::build(*min_triangles),
    };
    let triangles = writer.scene_triangles;
    (writer.finish(), triangles)
}

/// Writes `kind` to `out`. An existing file is only replaced when `overwrite` is true, so a
/// mistyped path cannot silently destroy a scene.
pub fn write_scene(kind: &SceneKind, out: &Path, overwrite: bool) -> anyhow::Result<SceneStats> {
    if out.exists() && !overwrite {
        bail!(
            "{} already exists (pass overwrite to replace it)",
            out.display()
        );
    }
    let (doc, triangles) = scene_json(kind);
    let text = serde_json::to_string(&doc).context("serialising the glTF JSON")?;
    crate::files::write_text(out, &text)?;
    let count = |key: &str| doc.get(key).and_then(|v| v.as_array()).map_or(0, Vec::len);
    Ok(SceneStats {
        triangles,
        meshes: count("meshes"),
        nodes: count("nodes"),
        materials: count("materials"),
        textures: count("textures"),
        bytes: text.len(),
    })
}

#[cfg(test)]
mod tests;
