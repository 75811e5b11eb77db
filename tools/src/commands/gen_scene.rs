//! `fovea gen-scene`: writes one of the project's procedural scenes as glTF.

use crate::scenegen::{write_scene, SceneKind, DEFAULT_LARGE_TRIANGLES};
use anyhow::{bail, Result};
use std::path::Path;

pub fn run(kind: &str, out: &Path, min_triangles: Option<usize>, force: bool) -> Result<()> {
    let kind = match kind {
        "cornell-box" => SceneKind::CornellBox,
        "stress" => SceneKind::Stress,
        "large" => SceneKind::Large {
            min_triangles: min_triangles.unwrap_or(DEFAULT_LARGE_TRIANGLES),
        },
        other => bail!("unknown scene kind '{other}' (cornell-box, stress, large)"),
    };
    crate::output::check_new_file(out, force)?;
    let stats = write_scene(&kind, out, force)?;
    println!(
        "wrote {}: {} triangles, {} meshes, {} materials, {} textures, {} bytes",
        out.display(),
        stats.triangles,
        stats.meshes,
        stats.materials,
        stats.textures,
        stats.bytes
    );
    Ok(())
}
