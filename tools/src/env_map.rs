//! Reads `--env FILE` (an equirectangular HDR environment map: OpenEXR through the `exr` crate,
//! Radiance `.hdr` through `image`) into a checked [`EnvironmentMap`]. Every error names the file
//! and the reason: missing or not a regular file, an extension other than .exr/.hdr, a file that
//! does not decode, a size of zero or above `MAX_ENVIRONMENT_SIZE` (checked from the header,
//! before the texels are decoded), a non-finite or negative texel.

use anyhow::{bail, Context, Result};
use fovea_renderer::scene::environment::{check_size, EnvironmentMap};
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

fn read_exr(path: &Path) -> Result<(u32, u32, Vec<Vec3>)> {
    use exr::prelude::*;
    let meta = MetaData::read_from_file(path, false).context("not a readable OpenEXR file")?;
    let size = meta
        .headers
        .first()
        .context("the OpenEXR file has no layer")?
        .layer_size;
    check_size(size.width() as u32, size.height() as u32).map_err(anyhow::Error::msg)?;
    let image = read_first_rgba_layer_from_file(
        path,
        |resolution, _| {
            (
                resolution.width(),
                vec![Vec3::ZERO; resolution.width() * resolution.height()],
            )
        },
        |(w, texels), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            texels[pos.y() * *w + pos.x()] = Vec3::new(r, g, b)
        },
    )
    .context("cannot read its RGB channels")?;
    let size = image.layer_data.size;
    Ok((
        size.width() as u32,
        size.height() as u32,
        image.layer_data.channel_data.pixels.1,
    ))
}

fn read_hdr(path: &Path) -> Result<(u32, u32, Vec<Vec3>)> {
    use image::ImageDecoder;
    let file = std::io::BufReader::new(std::fs::File::open(path)?);
    let decoder =
        image::codecs::hdr::HdrDecoder::new(file).context("not a readable Radiance HDR file")?;
    let (width, height) = decoder.dimensions();
    check_size(width, height).map_err(anyhow::Error::msg)?;
    let pixels = image::DynamicImage::from_decoder(decoder)
        .context("cannot decode its pixels")?
        .into_rgb32f();
    Ok((
        width,
        height,
        pixels.pixels().map(|p| Vec3::from_array(p.0)).collect(),
    ))
}
