//! glTF materials → [`Material`]; which images they sample (decoded in `images`).
//!
//! Texture references point at glTF *images* (the texture's `source`), so two glTF textures
//! sharing an image share one [`crate::Texture`]. Samplers and `texCoord` sets other than 0 are not
//! modelled: the tracer samples UV0 with repeat wrapping.

use crate::Material;
use glam::{Vec3, Vec4};

/// Maps a glTF image index to its [`crate::Scene::textures`] index (None: not decoded).
pub(crate) type ImageMap<'a> = &'a dyn Fn(usize) -> Option<u32>;

/// The images a material samples (the slots [`Material`] has; occlusion is not used), by glTF
/// image index. A texture's `source` is its PNG/JPEG image; an alternative in an extension
/// (MSFT_texture_dds, EXT_texture_webp) is never looked at.
pub(crate) fn images_used(m: &gltf::Material) -> Vec<usize> {
    let pbr = m.pbr_metallic_roughness();
    let specular = m.specular();
    let textures = [
        pbr.base_color_texture().map(|i| i.texture()),
        pbr.metallic_roughness_texture().map(|i| i.texture()),
        m.normal_texture().map(|t| t.texture()),
        m.emissive_texture().map(|i| i.texture()),
        specular.as_ref().and_then(|s| s.specular_texture()).map(|i| i.texture()),
        specular.as_ref().and_then(|s| s.specular_color_texture()).map(|i| i.texture()),
    ];
    textures.into_iter().flatten().map(|t| t.source().index()).collect()
}

pub(crate) fn convert_material(m: &gltf::Material, map: ImageMap) -> Material {
    let image_of = |info: Option<gltf::texture::Info>| info.and_then(|i| map(i.texture().source().index()));
    let pbr = m.pbr_metallic_roughness();
    let specular = m.specular();
    Material {
        base_color: Vec4::from(pbr.base_color_factor()),
        base_color_texture: image_of(pbr.base_color_texture()),
        metallic: pbr.metallic_factor(),
        roughness: pbr.roughness_factor(),
        metallic_roughness_texture: image_of(pbr.metallic_roughness_texture()),
        normal_texture: m.normal_texture().and_then(|t| map(t.texture().source().index())),
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
        alpha_cutoff: match m.alpha_mode() {
            gltf::material::AlphaMode::Mask => Some(m.alpha_cutoff().unwrap_or(0.5)),
            _ => None,
        },
        alpha_blend: m.alpha_mode() == gltf::material::AlphaMode::Blend,
    }
}
