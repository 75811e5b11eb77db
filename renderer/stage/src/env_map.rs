//! Reads `--env FILE` (an equirectangular HDR environment map: OpenEXR through the `exr` crate,
//! Radiance `.hdr` through `image`) into a checked [`EnvironmentMap`]. Every error names the file
//! and the reason: missing or not a regular file, an extension other than .exr/.hdr, a file that
//! does not decode, a size of zero or above `MAX_ENVIRONMENT_SIZE` (checked from the header,
//! before the texels are decoded), a non-finite texel, a texel whose radiance × the intensity
//! exceeds `MAX_ENVIRONMENT_RADIANCE` (the frame would be black). Negative channels, which lossy
//! OpenEXR compression (DWAA/DWAB, B44) leaves around dark texels, are read as 0 with a warning.

use anyhow::{bail, Context, Result};
use fovea_renderer::scene::environment::{check_size, EnvironmentMap, MAX_ENVIRONMENT_SIZE};
use glam::Vec3;
use std::path::Path;

#[derive(Clone, Copy)]
enum Format {
    Exr,
    Hdr,
}

/// What can be said of `path` without decoding it: a regular file with a supported extension.
/// Profiles check their `env` this way when they are read, so the error names the key.
pub fn check_path(path: &Path) -> Result<()> {
    format_of(path).map(|_| ())
}

fn format_of(path: &Path) -> Result<Format> {
    let name = path.display();
    crate::files::check_regular_input(path).with_context(|| format!("environment map {name}"))?;
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("exr") => Ok(Format::Exr),
        Some("hdr") => Ok(Format::Hdr),
        _ => bail!("environment map {name}: unsupported format (expected an equirectangular OpenEXR .exr or Radiance .hdr file)"),
    }
}

/// The map in `path`, turned `rotation_deg` about +Y and scaled by `intensity`.
pub fn load(path: &Path, rotation_deg: f32, intensity: f32) -> Result<EnvironmentMap> {
    let name = path.display();
    let (width, height, mut texels) = match format_of(path)? {
        Format::Exr => read_exr(path),
        Format::Hdr => read_hdr(path),
    }
    .with_context(|| format!("environment map {name}"))?;
    if let Some((count, lowest)) = clamp_negative(&mut texels) {
        eprintln!(
            "warning: environment map {name}: {count} texels with negative channels (lowest {lowest}) read as 0 (radiance cannot be negative; lossy OpenEXR compression leaves such values)"
        );
    }
    let mut map = EnvironmentMap::new(width, height, texels)
        .map_err(|e| anyhow::anyhow!("environment map {name}: {e}"))?;
    map.rotation = rotation_deg.to_radians();
    map.intensity = intensity;
    map.check_radiance().map_err(|e| {
        anyhow::anyhow!("environment map {name}: {e}; lower --env-intensity (or the profile's env_intensity) or scale the map")
    })?;
    Ok(map)
}

/// Sets finite negative channels to 0; how many texels had one and the lowest value, if any.
/// Non-finite channels stay for `EnvironmentMap::new` to refuse.
fn clamp_negative(texels: &mut [Vec3]) -> Option<(usize, f32)> {
    let mut count = 0;
    let mut lowest = 0.0f32;
    for t in texels.iter_mut() {
        if t.is_finite() && t.min_element() < 0.0 {
            count += 1;
            lowest = lowest.min(t.min_element());
            *t = t.max(Vec3::ZERO);
        }
    }
    (count > 0).then_some((count, lowest))
}

/// Most texels a map file may declare (the supported 8192 × 4096), checked from its header.
const MAX_TEXELS: u64 = MAX_ENVIRONMENT_SIZE.0 as u64 * MAX_ENVIRONMENT_SIZE.1 as u64;

fn read_exr(path: &Path) -> Result<(u32, u32, Vec<Vec3>)> {
    let bytes =
        crate::decode::read_bounded(path, crate::decode::MAX_IMAGE_FILE_BYTES, "environment map")?;
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(&bytes), false)
        .context("not a readable OpenEXR file")?;
    let size = meta
        .headers
        .first()
        .context("the OpenEXR file has no layer")?
        .layer_size;
    check_size(size.width() as u32, size.height() as u32).map_err(anyhow::Error::msg)?;
    let (w, h, texels) = crate::decode::decode_exr(&bytes, "the file", MAX_TEXELS, None)
        .context("cannot read its RGB channels")?;
    Ok((
        w,
        h,
        texels.iter().map(|t| Vec3::new(t[0], t[1], t[2])).collect(),
    ))
}

fn read_hdr(path: &Path) -> Result<(u32, u32, Vec<Vec3>)> {
    let bytes =
        crate::decode::read_bounded(path, crate::decode::MAX_IMAGE_FILE_BYTES, "environment map")?;
    let mut header = std::io::Cursor::new(&bytes);
    let decoder = image::codecs::hdr::HdrDecoder::new(&mut header)
        .context("not a readable Radiance HDR file")?;
    let (width, height) = image::ImageDecoder::dimensions(&decoder);
    check_size(width, height).map_err(anyhow::Error::msg)?;
    let (w, h, texels) = crate::decode::decode_hdr(&bytes, "the file", MAX_TEXELS)?;
    Ok((w, h, texels.into_iter().map(Vec3::from_array).collect()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A Radiance HDR file of `w` × `h` texels, each the RGBE bytes `rgbe`.
    fn hdr(name: &str, rgbe: [u8; 4]) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("fovea-env-map-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        let mut bytes = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 4\n".to_vec();
        for i in 0..8 {
            bytes.extend(if i == 5 { rgbe } else { [128, 128, 128, 129] });
        }
        std::fs::write(&path, bytes).unwrap();
        path
    }

    /// Finite texels of 1e20 and above, an RGBE exponent of 255, or 1e15 × the allowed
    /// --env-intensity 1e6 passed every check and rendered a black frame (exit 0).
    #[test]
    fn radiance_a_frame_cannot_show_is_refused() {
        // RGBE (m, e) is m / 256 × 2^(e − 128): 0.5 × 2^68 ≈ 1.5e20; exponent 255 ≈ 1.3e38;
        // 0.5 × 2^51 ≈ 1.1e15.
        for (name, rgbe, intensity) in [
            ("1e20.hdr", [128, 128, 128, 196], 1.0),
            ("e255.hdr", [200, 200, 200, 255], 1.0),
            ("1e15.hdr", [128, 128, 128, 179], 1e6),
        ] {
            let err = format!("{:#}", load(&hdr(name, rgbe), 0.0, intensity).unwrap_err());
            assert!(
                err.contains(name)
                    && err.contains("texel (1, 1)")
                    && err.contains("--env-intensity"),
                "{name}: {err}"
            );
        }
        // A sun-bright 5.4e8 at intensity 1000 (5.4e11) loads.
        load(&hdr("5e8.hdr", [128, 128, 128, 158]), 0.0, 1e3).unwrap();
    }
}
