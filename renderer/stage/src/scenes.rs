//! Resolves `--scene <name|path>`: an existing path is loaded as given; a name is looked up in
//! `./scenes/`, then in the repository's `scenes/`; the shared real scenes (sponza,
//! breakfast-room, flight-helmet) in `$FOVEA_SCENES` or `../shared/data/scenes` beside the
//! repository, an error naming the path when they are missing; the project's own scenes are generated
//! on the fly (into the per-user cache, checked by SHA-256) when no copy is found, so `fovea`
//! works from any directory.

use crate::scenegen::{write_scene, SceneKind, DEFAULT_LARGE_TRIANGLES};
use anyhow::{bail, Context, Result};
use fovea_renderer::scene::Scene;
use std::path::{Path, PathBuf};

pub const DEFAULT_SCENE: &str = "cornell-box";

fn generator_for(name: &str) -> Option<SceneKind> {
    match name {
        "cornell-box" => Some(SceneKind::CornellBox),
        "stress" => Some(SceneKind::Stress),
        "large" => Some(SceneKind::Large {
            min_triangles: DEFAULT_LARGE_TRIANGLES,
        }),
        _ => None,
    }
}

/// The real scenes of the shared data folder, by name: (name, file under the folder).
pub const SHARED_SCENES: [(&str, &str); 3] = [
    ("sponza", "sponza/Sponza.gltf"),
    ("breakfast-room", "breakfast-room/BreakfastRoom.gltf"),
    ("flight-helmet", "flight-helmet/FlightHelmet.gltf"),
];

/// Overrides where the shared real scenes are looked for.
pub const SHARED_SCENES_VAR: &str = "FOVEA_SCENES";

fn shared_file(name: &str) -> Option<&'static str> {
    SHARED_SCENES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, file)| *file)
}

/// `$FOVEA_SCENES`, else the repository's `../shared/data/scenes`.
fn shared_dir() -> PathBuf {
    std::env::var_os(SHARED_SCENES_VAR)
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/scenes")
        })
}

/// Where a scene name or path is found (generating the project's scenes when needed).
pub fn resolve(name_or_path: &str) -> Result<PathBuf> {
    let as_path = Path::new(name_or_path);
    if as_path.exists() {
        return Ok(as_path.to_path_buf());
    }
    let looks_like_path = name_or_path.contains('/')
        || name_or_path.ends_with(".gltf")
        || name_or_path.ends_with(".glb");
    if looks_like_path {
        bail!("scene file {name_or_path} does not exist");
    }
    let repo_scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    for dir in [PathBuf::from("scenes"), repo_scenes] {
        let candidate = dir.join(format!("{name_or_path}.gltf"));
        if candidate.exists() {
            return Ok(candidate);
        }
    }
    if let Some(file) = shared_file(name_or_path) {
        let dir = shared_dir();
        let path = dir.join(file);
        if !path.is_file() {
            bail!(
                "scene '{name_or_path}' is one of the shared real scenes: {} does not exist (set {SHARED_SCENES_VAR} to the folder holding {})",
                path.display(),
                Path::new(file).parent().map_or("".into(), |p| p.display().to_string())
            );
        }
        return Ok(path);
    }
    let Some(kind) = generator_for(name_or_path) else {
        bail!("unknown scene '{name_or_path}': give a .gltf/.glb path or one of cornell-box, stress, large, {}", SHARED_SCENES.map(|(n, _)| n).join(", "));
    };
    generated_in(&cache_dir()?, &kind)
}

/// The per-user scene cache: `$XDG_CACHE_HOME/fovea/scenes`, else `~/.cache/fovea/scenes`.
/// Never a shared temporary folder: another local user could plant a scene there.
fn cache_dir() -> Result<PathBuf> {
    let base = std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .filter(|p| p.is_absolute())
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .context("no per-user cache folder for generated scenes (set XDG_CACHE_HOME or HOME)")?;
    Ok(base.join("fovea").join("scenes"))
}

/// The generated scene `kind` in `cache`, made (or remade) when missing or when its bytes do not
/// match the SHA-256 recorded when it was written (a truncated or altered copy is never used).
pub fn generated_in(cache: &Path, kind: &SceneKind) -> Result<PathBuf> {
    std::fs::create_dir_all(cache).with_context(|| format!("creating {}", cache.display()))?;
    check_private(cache)?;
    let file = cache.join(kind.file_name());
    let sum_file = cache.join(format!("{}.sha256", kind.file_name()));
    let recorded = std::fs::read_to_string(&sum_file).ok();
    if file.is_file() && recorded.as_deref().map(str::trim) == Some(sha256_hex(&file)?.as_str()) {
        return Ok(file);
    }
    // Write under temporary names and rename, so a concurrent or interrupted run never leaves a
    // half-written scene (or a checksum of one) behind.
    let tmp = cache.join(format!(".{}.{}", kind.file_name(), std::process::id()));
    write_scene(kind, &tmp, true)?;
    let sum = sha256_hex(&tmp)?;
    crate::files::write_text(&sum_file, &format!("{sum}\n"))?;
    std::fs::rename(&tmp, &file)
        .with_context(|| format!("moving the generated scene to {}", file.display()))?;
    Ok(file)
}

/// The cache folder must belong to this user; write access for others is taken away (a umask
/// of 002 makes group-writable folders).
#[cfg(unix)]
fn check_private(dir: &Path) -> Result<()> {
    use std::os::unix::fs::{MetadataExt, PermissionsExt};
    let meta = std::fs::metadata(dir).with_context(|| format!("inspecting {}", dir.display()))?;
    // SAFETY: geteuid has no preconditions.
    let me = unsafe { libc::geteuid() };
    if meta.uid() != me {
        bail!("scene cache {} belongs to uid {}, not to you (uid {me}); fovea does not use scenes others can plant", dir.display(), meta.uid());
    }
    if meta.permissions().mode() & 0o022 != 0 {
        std::fs::set_permissions(dir, std::fs::Permissions::from_mode(0o700))
            .with_context(|| format!("making {} private", dir.display()))?;
    }
    Ok(())
}

#[cfg(not(unix))]
fn check_private(_dir: &Path) -> Result<()> {
    Ok(())
}

fn sha256_hex(path: &Path) -> Result<String> {
    use sha2::Digest;
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    Ok(sha2::Sha256::digest(&bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect())
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

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("fovea-scene-cache-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    /// A shared scene's name resolves into the shared folder, and its absence is an error naming
    /// the path looked at.
    #[test]
    fn shared_scene_names_resolve_or_name_the_missing_path() {
        let path = resolve("breakfast-room");
        match path {
            Ok(p) => assert!(p.ends_with("breakfast-room/BreakfastRoom.gltf"), "{p:?}"),
            Err(e) => {
                let e = e.to_string();
                assert!(
                    e.contains("BreakfastRoom.gltf does not exist")
                        && e.contains(SHARED_SCENES_VAR),
                    "{e}"
                );
            }
        }
        let err = resolve("no-such-scene").unwrap_err().to_string();
        assert!(
            err.contains("sponza, breakfast-room, flight-helmet"),
            "{err}"
        );
    }

    #[test]
    fn an_altered_cached_scene_is_remade_and_a_shared_cache_refused() {
        let cache = temp("altered");
        let kind = SceneKind::CornellBox;
        let file = generated_in(&cache, &kind).unwrap();
        let original = std::fs::read(&file).unwrap();
        std::fs::write(&file, b"{\"asset\":{\"version\":\"2.0\"}}").unwrap(); // planted or truncated
        assert_eq!(generated_in(&cache, &kind).unwrap(), file);
        assert_eq!(
            std::fs::read(&file).unwrap(),
            original,
            "the altered copy was replaced"
        );
        #[cfg(unix)]
        {
            use std::os::unix::fs::{MetadataExt, PermissionsExt};
            // Writable by others: made private.
            std::fs::set_permissions(&cache, std::fs::Permissions::from_mode(0o777)).unwrap();
            generated_in(&cache, &kind).unwrap();
            assert_eq!(
                std::fs::metadata(&cache).unwrap().permissions().mode() & 0o777,
                0o700
            );
            // Someone else's folder (only root can make one here): refused.
            if std::os::unix::fs::chown(&cache, Some(65534), None).is_ok() {
                assert_eq!(std::fs::metadata(&cache).unwrap().uid(), 65534);
                let err = generated_in(&cache, &kind).unwrap_err().to_string();
                assert!(err.contains("not to you"), "{err}");
            }
        }
    }
}
