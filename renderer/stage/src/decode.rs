//! Bounded reading and decoding of the image files users hand fovea (references and frames for
//! `fovea eval`, `quality`, `method-table` and `replay` baselines; environment maps): the file is
//! opened non-blocking and read only if it is a regular file of at most a stated size, and the
//! image's declared size is checked against a pixel budget from its header, before the decoder
//! allocates anything. Limits are listed in docs/guide/safety.md.

use anyhow::{bail, Context, Result};
use std::io::{Cursor, Read};
use std::path::Path;

/// Most pixels of one image that `fovea eval`, `quality`, `method-table` and `replay` read: 16 Mi
/// (4096 × 4096). The per-ring figures keep about 120 bytes per pixel (values, the displayed
/// image, FLIP, SSIM, ring masks), so this bounds a run near 2 GiB.
pub const MAX_IMAGE_PIXELS: u64 = 1 << 24;
/// Largest image file read (1 GiB): an uncompressed 32-bit RGBA EXR of `MAX_IMAGE_PIXELS` is
/// 256 MiB; an environment map of 8192 × 4096 is 512 MiB.
pub const MAX_IMAGE_FILE_BYTES: u64 = 1 << 30;

/// The bytes of `path`, refused unless it is a regular file of at most `limit` bytes (opened
/// non-blocking: a FIFO or device is refused without blocking; the read stops one byte past
/// the limit if the file grows meanwhile). `what` names the file in errors.
pub fn read_bounded(path: &Path, limit: u64, what: &str) -> Result<Vec<u8>> {
    let name = path.display();
    let file = open_nonblocking(path).with_context(|| format!("reading {what} {name}"))?;
    let meta = file
        .metadata()
        .with_context(|| format!("reading {what} {name}"))?;
    if !meta.is_file() {
        bail!(
            "reading {what} {name}: it is {}, not a regular file",
            fovea_hal::file::file_kind(&meta.file_type())
        );
    }
    if meta.len() > limit {
        bail!(
            "{what} {name}: {} bytes, more than the {limit}-byte limit",
            meta.len()
        );
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .with_context(|| format!("reading {what} {name}"))?;
    if bytes.len() as u64 > limit {
        bail!("{what} {name}: it grew past the {limit}-byte limit while being read");
    }
    Ok(bytes)
}

#[cfg(unix)]
fn open_nonblocking(path: &Path) -> std::io::Result<std::fs::File> {
    use std::os::unix::fs::OpenOptionsExt;
    std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK | libc::O_CLOEXEC)
        .open(path)
}

#[cfg(not(unix))]
fn open_nonblocking(path: &Path) -> std::io::Result<std::fs::File> {
    std::fs::File::open(path)
}

/// A declared size within `max_pixels` (and non-empty); `expect`, when given, must match.
pub fn check_declared_size(
    name: &str,
    width: u64,
    height: u64,
    max_pixels: u64,
    expect: Option<(u32, u32)>,
) -> Result<(u32, u32)> {
    if width == 0 || height == 0 {
        bail!("{name}: the image is {width}×{height}; it must be at least 1×1");
    }
    if width.saturating_mul(height) > max_pixels {
        bail!(
            "{name}: the image declares {width}×{height} pixels, more than the {max_pixels}-pixel limit"
        );
    }
    if let Some((w, h)) = expect {
        if (width, height) != (w as u64, h as u64) {
            bail!("{name}: the image is {width}×{height}, expected {w}×{h}");
        }
    }
    Ok((width as u32, height as u32))
}

/// A PNG or JPEG (told apart by content) as RGBA8, its size checked from the header first.
pub fn decode_rgba8(
    bytes: &[u8],
    name: &str,
    max_pixels: u64,
    expect: Option<(u32, u32)>,
) -> Result<(u32, u32, Vec<u8>)> {
    use image::ImageDecoder;
    let mut reader = image::ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .with_context(|| format!("reading {name}"))?;
    if !matches!(
        reader.format(),
        Some(image::ImageFormat::Png | image::ImageFormat::Jpeg)
    ) {
        bail!("{name}: not a PNG or JPEG image");
    }
    let mut limits = image::Limits::default();
    // Enough for the decoded image at 16 bits per channel plus the decoder's own buffers.
    limits.max_alloc = Some(max_pixels * 16 + (16 << 20));
    reader.limits(limits);
    let decoder = reader
        .into_decoder()
        .with_context(|| format!("reading {name}"))?;
    let (w, h) = decoder.dimensions();
    let (w, h) = check_declared_size(name, w as u64, h as u64, max_pixels, expect)?;
    let image = image::DynamicImage::from_decoder(decoder)
        .with_context(|| format!("decoding {name}"))?
        .to_rgba8();
    Ok((w, h, image.into_raw()))
}

/// A PNG or JPEG file as RGBA8 (bounded read, size checked from the header).
pub fn read_rgba8(
    path: &Path,
    max_pixels: u64,
    expect: Option<(u32, u32)>,
) -> Result<(u32, u32, Vec<u8>)> {
    let bytes = read_bounded(path, MAX_IMAGE_FILE_BYTES, "image")?;
    decode_rgba8(&bytes, &path.display().to_string(), max_pixels, expect)
}

/// The first RGBA layer of an OpenEXR image (alpha 1 where absent). Every part's declared size
/// and chunk count are checked from the headers before pixels are allocated: the chunk offsets
/// alone must fit in the file.
pub fn decode_exr(
    bytes: &[u8],
    name: &str,
    max_pixels: u64,
    expect: Option<(u32, u32)>,
) -> Result<(u32, u32, Vec<[f32; 4]>)> {
    use exr::prelude::*;
    let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false)
        .with_context(|| format!("{name}: not a readable OpenEXR file"))?;
    let Some(first) = meta.headers.first() else {
        bail!("{name}: the OpenEXR file has no layer");
    };
    let mut chunks = 0u64;
    for (i, header) in meta.headers.iter().enumerate() {
        let part = if meta.headers.len() > 1 {
            format!("{name} (part {i})")
        } else {
            name.to_string()
        };
        let size = header.layer_size;
        check_declared_size(
            &part,
            size.width() as u64,
            size.height() as u64,
            max_pixels,
            None,
        )?;
        chunks = chunks.saturating_add(header.chunk_count as u64);
    }
    if chunks.saturating_mul(8) > bytes.len() as u64 {
        bail!(
            "{name}: the headers declare {chunks} chunks, more than the {}-byte file can hold",
            bytes.len()
        );
    }
    let size = first.layer_size;
    check_declared_size(
        name,
        size.width() as u64,
        size.height() as u64,
        max_pixels,
        expect,
    )?;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |resolution, _| {
                let w = resolution.width();
                (w, vec![[0f32; 4]; w * resolution.height()])
            },
            |(w, pixels): &mut (usize, Vec<[f32; 4]>), pos, (r, g, b, a): (f32, f32, f32, f32)| {
                pixels[pos.y() * *w + pos.x()] = [r, g, b, a]
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(Cursor::new(bytes))
        .with_context(|| format!("reading {name}"))?;
    let size = image.layer_data.size;
    let (w, h) = check_declared_size(
        name,
        size.width() as u64,
        size.height() as u64,
        max_pixels,
        expect,
    )?;
    Ok((w, h, image.layer_data.channel_data.pixels.1))
}

/// An OpenEXR file (bounded read, sizes checked from the headers).
pub fn read_exr(
    path: &Path,
    max_pixels: u64,
    expect: Option<(u32, u32)>,
) -> Result<(u32, u32, Vec<[f32; 4]>)> {
    let bytes = read_bounded(path, MAX_IMAGE_FILE_BYTES, "OpenEXR image")?;
    decode_exr(&bytes, &path.display().to_string(), max_pixels, expect)
}

/// A Radiance HDR (RGBE) image, its size checked from the header.
pub fn decode_hdr(bytes: &[u8], name: &str, max_pixels: u64) -> Result<(u32, u32, Vec<[f32; 3]>)> {
    use image::ImageDecoder;
    let decoder = image::codecs::hdr::HdrDecoder::new(Cursor::new(bytes))
        .with_context(|| format!("{name}: not a readable Radiance HDR file"))?;
    let (w, h) = decoder.dimensions();
    let (w, h) = check_declared_size(name, w as u64, h as u64, max_pixels, None)?;
    let pixels = image::DynamicImage::from_decoder(decoder)
        .with_context(|| format!("{name}: cannot decode its pixels"))?
        .into_rgb32f();
    Ok((w, h, pixels.pixels().map(|p| p.0).collect()))
}

#[cfg(test)]
#[path = "decode_tests.rs"]
mod tests;
