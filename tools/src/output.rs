//! Writes what a run produces: PNG and linear EXR images, and the JSON report. Output folders
//! are checked first so files the user wrote are never overwritten.

use anyhow::{bail, Context, Result};
use std::path::Path;

/// Creates `dir` or accepts an existing one holding only files fovea writes (frames, reports,
/// debug views); anything else in it means the user chose the wrong folder.
pub fn prepare_output_dir(dir: &Path) -> Result<()> {
    if dir.exists() {
        if !dir.is_dir() {
            bail!("output {} exists and is not a folder", dir.display());
        }
        for entry in std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))? {
            let entry = entry?;
            let name = entry.file_name().to_string_lossy().into_owned();
            // `fovea quality` keeps one `fovea render` folder per run (checked when reused).
            let run_folder = name.starts_with("run_") && entry.path().is_dir();
            let ours = matches!(name.as_str(), "report.json" | "eval.json" | "eval.png" | "quality.json" | "quality.md")
                || run_folder
                || (name.starts_with("reference_") && name.ends_with(".exr"))
                || (name.starts_with("frame_") && (name.ends_with(".png") || name.ends_with(".exr")))
                || (name.starts_with("debug_") && [".png", ".exr", ".json"].iter().any(|e| name.ends_with(e)));
            if !ours {
                bail!(
                    "output folder {} holds '{name}', which fovea did not write; choose an empty or new folder",
                    dir.display()
                );
            }
        }
    }
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))
}

/// Refuses to replace an existing file unless `force` is set.
pub fn check_new_file(path: &Path, force: bool) -> Result<()> {
    if path.exists() && !force {
        bail!("{} already exists; pass --force to replace it", path.display());
    }
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).with_context(|| format!("creating {}", parent.display()))?;
    }
    Ok(())
}

pub fn write_png(path: &Path, width: u32, height: u32, rgba8: &[u8]) -> Result<()> {
    image::save_buffer(path, rgba8, width, height, image::ExtendedColorType::Rgba8)
        .with_context(|| format!("writing {}", path.display()))
}

/// Linear float RGB(A) EXR.
pub fn write_exr(path: &Path, width: u32, height: u32, texels: &[[f32; 4]]) -> Result<()> {
    let w = width as usize;
    exr::prelude::write_rgba_file(path, w, height as usize, |x, y| {
        let t = texels[y * w + x];
        (t[0], t[1], t[2], 1.0f32)
    })
    .with_context(|| format!("writing {}", path.display()))
}

/// Reads a linear EXR's RGB channels (references for `fovea eval` and tests).
pub fn read_exr(path: &Path) -> Result<(u32, u32, Vec<[f32; 4]>)> {
    use exr::prelude::*;
    let image = read_first_rgba_layer_from_file(
        path,
        |resolution, _| {
            let w = resolution.width();
            (w, vec![[0f32; 4]; w * resolution.height()])
        },
        |(w, pixels), pos, (r, g, b, a): (f32, f32, f32, f32)| pixels[pos.y() * *w + pos.x()] = [r, g, b, a],
    )
    .with_context(|| format!("reading {}", path.display()))?;
    let size = image.layer_data.size;
    Ok((size.width() as u32, size.height() as u32, image.layer_data.channel_data.pixels.1))
}

/// Linear radiance → sRGB RGBA8 with the same fitted ACES curve as the tonemap pass (previews).
pub fn tonemap_preview(texels: &[[f32; 4]], exposure: f32) -> Vec<u8> {
    let curve = |x: f32| ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0);
    let srgb = |c: f32| if c <= 0.0031308 { c * 12.92 } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    texels
        .iter()
        .flat_map(|t| {
            let px = |c: f32| (srgb(curve((c * exposure).max(0.0))) * 255.0 + 0.5) as u8;
            [px(t[0]), px(t[1]), px(t[2]), 255]
        })
        .collect()
}
