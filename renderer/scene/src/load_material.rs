//! glTF materials and images → [`Material`] and RGBA8 [`Texture`].
//!
//! Texture references point at glTF *images* (the texture's `source`), so two glTF textures
//! sharing an image share one [`Texture`]. Samplers and `texCoord` sets other than 0 are not
//! modelled: the tracer samples UV0 with repeat wrapping.

use crate::{Material, SceneError, Texture};
use glam::{Vec3, Vec4};
use gltf::image::Format;
use std::path::Path;

fn image_of(info: Option<gltf::texture::Info>) -> Option<u32> {
    info.map(|i| i.texture().source().index() as u32)
}

pub(crate) fn convert_material(m: &gltf::Material) -> Material {
    let pbr = m.pbr_metallic_roughness();
    let specular = m.specular();
    Material {
        base_color: Vec4::from(pbr.base_color_factor()),
        base_color_texture: image_of(pbr.base_color_texture()),
        metallic: pbr.metallic_factor(),
        roughness: pbr.roughness_factor(),
        metallic_roughness_texture: image_of(pbr.metallic_roughness_texture()),
        normal_texture: m.normal_texture().map(|t| t.texture().source().index() as u32),
        normal_scale: m.normal_texture().map_or(1.0, |t| t.scale()),
        emissive: Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0),
        emissive_texture: image_of(m.emissive_texture()),
        // KHR_materials_specular defaults (factor 1, colour 1) when the extension is absent.
        specular_factor: specular.as_ref().map_or(1.0, |s| s.specular_factor()),
        specular_texture: specular.as_ref().and_then(|s| image_of(s.specular_texture())),
        specular_color: specular.as_ref().map_or(Vec3::ONE, |s| Vec3::from(s.specular_color_factor())),
        specular_color_texture: specular.as_ref().and_then(|s| image_of(s.specular_color_texture())),
        ior: m.ior().unwrap_or(1.5),
        double_sided: m.double_sided(),
    }
}

/// Converts every decoded image to RGBA8. Grey images replicate into RGB (PNG semantics);
/// 16-bit channels are rounded to 8 bits; float images are clamped to [0, 1].
pub(crate) fn convert_images(images: Vec<gltf::image::Data>, file: &Path) -> Result<Vec<Texture>, SceneError> {
    images
        .into_iter()
        .enumerate()
        .map(|(i, img)| {
            let rgba8 = to_rgba8(&img).ok_or_else(|| SceneError::Data {
                file: file.to_path_buf(),
                detail: format!("images[{i}]: {} bytes do not match {}×{} {:?}", img.pixels.len(), img.width, img.height, img.format),
            })?;
            Ok(Texture { width: img.width, height: img.height, rgba8 })
        })
        .collect()
}

fn to_rgba8(img: &gltf::image::Data) -> Option<Vec<u8>> {
    let texels = img.width as usize * img.height as usize;
    let (channels, bytes_per_channel) = match img.format {
        Format::R8 => (1, 1),
        Format::R8G8 => (2, 1),
        Format::R8G8B8 => (3, 1),
        Format::R8G8B8A8 => (4, 1),
        Format::R16 => (1, 2),
        Format::R16G16 => (2, 2),
        Format::R16G16B16 => (3, 2),
        Format::R16G16B16A16 => (4, 2),
        Format::R32G32B32FLOAT => (3, 4),
        Format::R32G32B32A32FLOAT => (4, 4),
    };
    if img.pixels.len() != texels * channels * bytes_per_channel {
        return None;
    }
    // Channel values normalised to 8 bits, then expanded to RGBA.
    let channel = |k: usize| -> u8 {
        let at = k * bytes_per_channel;
        match bytes_per_channel {
            1 => img.pixels[at],
            2 => {
                let v = u16::from_ne_bytes([img.pixels[at], img.pixels[at + 1]]) as u32;
                ((v * 255 + 32767) / 65535) as u8
            }
            _ => {
                let v = f32::from_ne_bytes(img.pixels[at..at + 4].try_into().unwrap_or([0; 4]));
                (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
            }
        }
    };
    let mut out = Vec::with_capacity(texels * 4);
    for t in 0..texels {
        let c = |k: usize| channel(t * channels + k);
        let rgba = match channels {
            1 => [c(0), c(0), c(0), 255],
            2 => [c(0), c(0), c(0), c(1)],
            3 => [c(0), c(1), c(2), 255],
            _ => [c(0), c(1), c(2), c(3)],
        };
        out.extend_from_slice(&rgba);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grey_and_sixteen_bit_images_expand_to_rgba8() {
        let grey = gltf::image::Data { pixels: vec![10, 20], format: Format::R8, width: 2, height: 1 };
        assert_eq!(to_rgba8(&grey).unwrap(), vec![10, 10, 10, 255, 20, 20, 20, 255]);
        let px: Vec<u8> = [65535u16, 0, 32896].iter().flat_map(|v| v.to_ne_bytes()).collect();
        let rgb16 = gltf::image::Data { pixels: px, format: Format::R16G16B16, width: 1, height: 1 };
        assert_eq!(to_rgba8(&rgb16).unwrap(), vec![255, 0, 128, 255]);
        let short = gltf::image::Data { pixels: vec![1, 2, 3], format: Format::R8G8B8A8, width: 1, height: 1 };
        assert!(to_rgba8(&short).is_none());
    }
}
