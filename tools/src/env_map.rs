//! Reads `--env FILE` (an equirectangular HDR environment map: OpenEXR through the `exr` crate,
//! Radiance `.hdr` through `image`) into a checked [`EnvironmentMap`]. Every error names the file
//! and the reason: missing or not a regular file, an extension other than .exr/.hdr, a file that
//! does not decode, a size of zero or above `MAX_ENVIRONMENT_SIZE` (checked from the header,
//! before the texels are decoded), a non-finite or negative texel.

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
    crate::output::check_regular_input(path).with_context(|| format!("environment map {name}"))?;
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("exr") => Ok(Format::Exr),
        Some("hdr") => Ok(Format::Hdr),
        _ => bail!("environment map {name}: unsupported format (expected an equirectangular OpenEXR .exr or Radiance .hdr file)"),
    }
}

/// The map in `path`, turned `rotation_deg` about +Y and scaled by `intensity`.
pub fn load(path: &Path, rotation_deg: f32, intensity: f32) -> Result<EnvironmentMap> {
    let name = path.display();
    let (width, height, texels) = match format_of(path)? {
        Format::Exr => read_exr(path),
        Format::Hdr => read_hdr(path),
    }
    .with_context(|| format!("environment map {name}"))?;
    let mut map = EnvironmentMap::new(width, height, texels)
        .map_err(|e| anyhow::anyhow!("environment map {name}: {e}"))?;
    map.rotation = rotation_deg.to_radians();
    map.intensity = intensity;
    Ok(map)
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
