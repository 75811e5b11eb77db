//! Reading and decoding the images that rendered materials use (and no others: a DDS or KTX2
//! alternative that only an extension refers to is never opened). Every image is bounded twice:
//! its encoded bytes by the byte budget, its texels by the texel budget, checked from the header
//! before the pixels are decoded.

use crate::limits::{over_budget, ByteBudget, TEXELS};
use crate::source::{
    decode_data_uri, display_uri, parse_uri, read_bounded, resolve_inside, ReadError, Uri,
};
use crate::{SceneError, Texture};
use image::ImageFormat;
use std::io::Cursor;
use std::path::Path;

/// What decoding needs from the loader.
pub(crate) struct ImageInputs<'a> {
    pub file: &'a Path,
    /// The scene file's folder; relative URIs resolve inside it.
    pub folder: &'a Path,
    pub buffers: &'a [Vec<u8>],
    pub budget: &'a mut ByteBudget,
    pub max_texels: u64,
}

/// Decodes `images` (glTF image indices) in order, to RGBA8.
pub(crate) fn decode_images(
    json: &gltf::json::Root,
    images: &[usize],
    mut inputs: ImageInputs,
) -> Result<Vec<Texture>, SceneError> {
    let mut texels_used = 0u64;
    let mut out = Vec::with_capacity(images.len());
    for &index in images {
        let image = &json.images[index];
        let named = Named::new(inputs.file, index, image);
        let encoded = encoded_bytes(json, image, &named, &mut inputs)?;
        let texture = decode(&encoded, &named, inputs.max_texels, &mut texels_used)?;
        out.push(texture);
    }
    Ok(out)
}

/// An image as error messages name it: index, where its bytes come from, its mime type.
struct Named<'a> {
    file: &'a Path,
    index: usize,
    location: String,
    mime: Option<String>,
}

impl<'a> Named<'a> {
    fn new(file: &'a Path, index: usize, image: &gltf::json::Image) -> Self {
        let location = match (&image.uri, image.buffer_view) {
            (Some(uri), _) => format!("uri \"{}\"", display_uri(uri)),
            (None, Some(view)) => format!("bufferViews[{}]", view.value()),
            (None, None) => "no source".into(),
        };
        let mime = image
            .mime_type
            .as_ref()
            .map(|m| m.0.clone())
            .or_else(|| image.uri.as_deref().and_then(mime_from_uri));
        Named {
            file,
            index,
            location,
            mime,
        }
    }

    fn error(&self, reason: String) -> SceneError {
        SceneError::Image {
            file: self.file.to_path_buf(),
            index: self.index,
            location: self.location.clone(),
            mime: self.mime.clone().unwrap_or_else(|| "not given".into()),
            reason,
        }
    }

    fn read_error(&self, e: ReadError) -> SceneError {
        match e {
            ReadError::Budget(detail) => SceneError::Budget {
                file: self.file.to_path_buf(),
                detail,
            },
            other => self.error(other.to_string()),
        }
    }
}

/// The media type a data URI states, or the one a file name's extension implies.
fn mime_from_uri(uri: &str) -> Option<String> {
    if let Ok(Uri::Data { media_type, .. }) = parse_uri(uri) {
        return (!media_type.is_empty()).then(|| media_type.to_string());
    }
    let path = uri.split(['?', '#']).next()?;
    let ext = path.rsplit_once('.')?.1.to_ascii_lowercase();
    Some(
        match ext.as_str() {
            "png" => "image/png",
            "jpg" | "jpeg" => "image/jpeg",
            "dds" => "image/vnd-ms.dds",
            "ktx2" => "image/ktx2",
            "webp" => "image/webp",
            _ => return None,
        }
        .to_string(),
    )
}

fn format_of(mime: &str) -> Option<ImageFormat> {
    match mime.to_ascii_lowercase().as_str() {
        "image/png" => Some(ImageFormat::Png),
        "image/jpeg" | "image/jpg" => Some(ImageFormat::Jpeg),
        _ => None,
    }
}

fn unsupported(mime: &str) -> String {
    format!("{mime} is not decoded (only image/png and image/jpeg); for DDS/KTX2/WebP give the texture a PNG or JPEG `source`")
}

fn encoded_bytes(
    json: &gltf::json::Root,
    image: &gltf::json::Image,
    named: &Named,
    inputs: &mut ImageInputs,
) -> Result<Vec<u8>, SceneError> {
    // Refuse a known-undecodable type before reading a byte of it.
    if let Some(mime) = named.mime.as_deref().filter(|m| format_of(m).is_none()) {
        return Err(named.error(unsupported(mime)));
    }
    let what = format!("images[{}]", named.index);
    if let Some(uri) = &image.uri {
        return match parse_uri(uri).map_err(|reason| named.error(reason))? {
            Uri::Data { payload, .. } => {
                decode_data_uri(payload, inputs.budget, &what).map_err(|reason| named.error(reason))
            }
            Uri::Relative(relative) => {
                let path = resolve_inside(inputs.folder, &relative)
                    .map_err(|reason| named.error(reason))?;
                read_bounded(&path, None, inputs.budget, &what).map_err(|e| named.read_error(e))
            }
        };
    }
    let view_index = image
        .buffer_view
        .map(|v| v.value())
        .ok_or_else(|| named.error("it has neither a uri nor a bufferView".into()))?;
    let view = json
        .buffer_views
        .get(view_index)
        .ok_or_else(|| named.error("its bufferView does not exist".into()))?;
    let start = view.byte_offset.map_or(0, |o| o.0);
    let range = start
        .checked_add(view.byte_length.0)
        .map(|end| start as usize..end as usize);
    let bytes = range.and_then(|r| inputs.buffers.get(view.buffer.value())?.get(r));
    bytes.map(<[u8]>::to_vec).ok_or_else(|| {
        named.error(format!(
            "bufferViews[{view_index}] reaches past the end of its buffer"
        ))
    })
}

fn decode(
    encoded: &[u8],
    named: &Named,
    max_texels: u64,
    texels_used: &mut u64,
) -> Result<Texture, SceneError> {
    let format = match named.mime.as_deref() {
        Some(mime) => format_of(mime).ok_or_else(|| named.error(unsupported(mime)))?,
        None => match image::guess_format(encoded) {
            Ok(f @ (ImageFormat::Png | ImageFormat::Jpeg)) => f,
            Ok(other) => {
                return Err(named.error(format!(
                    "its bytes look like {other:?}, which is not decoded (only PNG and JPEG)"
                )))
            }
            Err(_) => {
                return Err(
                    named.error("no mime type, and its bytes are neither PNG nor JPEG".into())
                )
            }
        },
    };
    let reason = |e: image::ImageError| named.error(e.to_string());
    let (width, height) = image::ImageReader::with_format(Cursor::new(encoded), format)
        .into_dimensions()
        .map_err(reason)?;
    let texels = width as u64 * height as u64;
    if texels_used.saturating_add(texels) > max_texels {
        let what = format!(
            "images[{}] ({width}×{height}, {}) with the {texels_used} texels decoded before it",
            named.index, named.location
        );
        return Err(SceneError::Budget {
            file: named.file.to_path_buf(),
            detail: over_budget(&TEXELS, max_texels, what),
        });
    }
    let mut reader = image::ImageReader::with_format(Cursor::new(encoded), format);
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(width);
    limits.max_image_height = Some(height);
    // 16-bit RGBA is the widest PNG/JPEG decode; the margin covers the decoder's own state.
    limits.max_alloc = Some(texels * 8 + (1 << 20));
    reader.limits(limits);
    let rgba8 = reader.decode().map_err(reason)?.into_rgba8().into_raw();
    *texels_used += texels;
    Ok(Texture {
        width,
        height,
        rgba8,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn png(img: image::DynamicImage) -> Vec<u8> {
        let mut out = Vec::new();
        img.write_to(&mut Cursor::new(&mut out), ImageFormat::Png)
            .unwrap();
        out
    }

    fn named(mime: Option<&str>) -> Named<'static> {
        Named {
            file: Path::new("s.gltf"),
            index: 3,
            location: "uri \"t.png\"".into(),
            mime: mime.map(str::to_string),
        }
    }

    #[test]
    fn grey_and_sixteen_bit_images_expand_to_rgba8() {
        let grey = image::GrayImage::from_raw(2, 1, vec![10, 20]).unwrap();
        let t = decode(&png(grey.into()), &named(Some("image/png")), 100, &mut 0).unwrap();
        assert_eq!(t.rgba8, vec![10, 10, 10, 255, 20, 20, 20, 255]);
        let rgb16 =
            image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(1, 1, vec![65535u16, 0, 32896])
                .unwrap();
        let t = decode(
            &png(image::DynamicImage::ImageRgb16(rgb16)),
            &named(None),
            100,
            &mut 0,
        )
        .unwrap();
        assert_eq!(t.rgba8, vec![255, 0, 128, 255]);
    }

    #[test]
    fn texel_budget_is_checked_from_the_header_and_undecodable_bytes_are_named() {
        let img = png(image::RgbaImage::new(8, 8).into());
        let mut used = 40;
        let err = decode(&img, &named(Some("image/png")), 100, &mut used)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("images[3] (8×8")
                && err.contains("FOVEA_MAX_TEXELS")
                && err.contains("budget of 100"),
            "{err}"
        );
        assert_eq!(used, 40);
        let err = decode(b"not a png at all", &named(Some("image/png")), 100, &mut 0)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("images[3]") && err.contains("t.png") && err.contains("image/png"),
            "{err}"
        );
        let err = decode(b"DDS |....", &named(Some("image/vnd-ms.dds")), 100, &mut 0)
            .unwrap_err()
            .to_string();
        assert!(err.contains("image/vnd-ms.dds is not decoded"), "{err}");
    }

    #[test]
    fn mime_types_come_from_data_uris_and_extensions() {
        assert_eq!(
            mime_from_uri("data:image/jpeg;base64,AAAA").as_deref(),
            Some("image/jpeg")
        );
        assert_eq!(
            mime_from_uri("tex/Floor.DDS").as_deref(),
            Some("image/vnd-ms.dds")
        );
        assert_eq!(mime_from_uri("a.png?x=1").as_deref(), Some("image/png"));
        assert_eq!(mime_from_uri("noext"), None);
    }
}
