//! Resolves `--scene <name|path>`: an existing path is loaded as given; a name is looked up in
//! `./scenes/`, then in the repository's `scenes/`, and the project's own scenes are generated
//! on the fly (into a cache folder) when no copy is found, so `fovea` works from any directory.

use crate::scenegen::{write_scene, SceneKind, DEFAULT_LARGE_TRIANGLES};
use anyhow::{bail, Context, Result};
use fovea_renderer::scene::Scene;
use std::path::{Path, PathBuf};

pub const DEFAULT_SCENE: &str = "cornell-box";

fn generator_for(name: &str) -> Option<SceneKind> {
    match name {
        "cornell-box" => Some(SceneKind::CornellBox),
        "stress" => Some(SceneKind::Stress),
        "large" => Some(SceneKind::Large { min_triangles: DEFAULT_LARGE_TRIANGLES }),
        _ => None,
    }
}

/// Where a scene name or path is found (generating the project's scenes when needed).
pub fn resolve(name_or_path: &str) -> Result<PathBuf> {
    let as_path = Path::new(name_or_path);
    if as_path.exists() {
        return Ok(as_path.to_path_buf());
    }
    let looks_like_path = name_or_path.contains('/') || name_or_path.ends_with(".gltf") || name_or_path.ends_with(".glb");
    if looks_like_path {
        bail!("scene file {name_or_path} does not exist");
    }
    let repo_scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    for dir in [PathBuf::from("scenes"), repo_scenes] {
        let candidate = dir.join(format!("{name_or_path}.gltf"));
        if candidate.exists() {
            return Ok(candidate);
        }
    }
    let Some(kind) = generator_for(name_or_path) else {
        bail!("unknown scene '{name_or_path}': give a .gltf/.glb path or one of cornell-box, stress, large");
    };
    let cache = std::env::temp_dir().join("fovea-scenes");
    std::fs::create_dir_all(&cache).with_context(|| format!("creating {}", cache.display()))?;
    let file = cache.join(kind.file_name());
    if !file.exists() {
        // Write under a temporary name and rename, so a concurrent or interrupted run never
        // leaves a half-written scene behind.
        let tmp = cache.join(format!(".{}.{}", kind.file_name(), std::process::id()));
        write_scene(&kind, &tmp, true)?;
        std::fs::rename(&tmp, &file).with_context(|| format!("moving the generated scene to {}", file.display()))?;
    }
    Ok(file)
}

/// Loads a scene within the budgets of `FOVEA_MAX_TRIANGLES`, `FOVEA_MAX_TEXELS` and
/// `FOVEA_MAX_SCENE_BYTES` (see `fovea_scene::limits`); what the loader ignored is printed once.
pub fn load(name_or_path: &str) -> Result<Scene> {
    let path = resolve(name_or_path)?;
    let scene = Scene::load(&path)?;
    for warning in &scene.warnings {
        eprintln!("warning: {}: {warning}", path.display());
    }
    Ok(scene)
}
