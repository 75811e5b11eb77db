//! `fovea gen-scene`: writes one of the project's procedural scenes as glTF.

use anyhow::{bail, Result};
use fovea_stage::scenegen::{write_scene, SceneKind, DEFAULT_LARGE_TRIANGLES};
use std::path::{Path, PathBuf};

/// `--min-triangles`: at most the scene loader's triangle budget (`FOVEA_MAX_TRIANGLES`, default
/// 4,000,000), so every scene written loads (1e11 took 18.8 GB and wrote a file fovea refused).
pub fn check_triangles(n: usize) -> Result<usize> {
    let budget = fovea_scene::LoadLimits::from_env()
        .map_err(anyhow::Error::msg)?
        .max_triangles;
    if n == 0 || n as u64 > budget {
        bail!("--min-triangles {n} must be in 1..={budget} (the scene loader's triangle budget; set FOVEA_MAX_TRIANGLES to raise it)");
    }
    Ok(n)
}

pub fn run(kind: &str, out: &Path, min_triangles: Option<usize>, force: bool) -> Result<()> {
    let kind = match kind {
        "cornell-box" => SceneKind::CornellBox,
        "stress" => SceneKind::Stress,
        "large" => SceneKind::Large {
            min_triangles: check_triangles(min_triangles.unwrap_or(DEFAULT_LARGE_TRIANGLES))?,
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

// `fovea gen-scene` (its help is the variant's in `crate::cli::Command`).
#[derive(clap::Args)]
pub struct GenSceneCommand {
    /// cornell-box, stress or large.
    pub kind: String,
    #[arg(long)]
    pub out: PathBuf,
    /// Minimum triangle count of the large scene.
    #[arg(long)]
    pub min_triangles: Option<usize>,
    #[arg(long)]
    pub force: bool,
}

impl GenSceneCommand {
    pub fn run(self) -> Result<()> {
        run(&self.kind, &self.out, self.min_triangles, self.force)
    }
}
