//! glTF materials → [`Material`]; which images they sample (decoded in `images`).
//!
//! Texture references point at glTF *images* (the texture's `source`), so two glTF textures
//! sharing an image share one [`crate::Texture`]. Samplers and `texCoord` sets other than 0 are not
//! modelled: the tracer samples UV0 with repeat wrapping. KHR_texture_transform is read per slot
//! (its `texCoord` override, like `texCoord`, is not modelled).

use crate::{Material, TextureSlot, UvTransform};
use glam::{Vec2, Vec3, Vec4};

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
        specular
            .as_ref()
            .and_then(|s| s.specular_texture())
            .map(|i| i.texture()),
        specular
            .as_ref()
            .and_then(|s| s.specular_color_texture())
            .map(|i| i.texture()),
    ];
    textures
        .into_iter()
        .flatten()
        .map(|t| t.source().index())
        .collect()
}

pub(crate) fn convert_material(m: &gltf::Material, map: ImageMap) -> Material {
    let image_of =
        |info: Option<gltf::texture::Info>| info.and_then(|i| map(i.texture().source().index()));
    let pbr = m.pbr_metallic_roughness();
    let specular = m.specular();
    Material {
        base_color: Vec4::from(pbr.base_color_factor()),
        base_color_texture: image_of(pbr.base_color_texture()),
        metallic: pbr.metallic_factor(),
        roughness: pbr.roughness_factor(),
        metallic_roughness_texture: image_of(pbr.metallic_roughness_texture()),
        normal_texture: m
            .normal_texture()
            .and_then(|t| map(t.texture().source().index())),
        normal_scale: m.normal_texture().map_or(1.0, |t| t.scale()),
        emissive: Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0),
        emissive_texture: image_of(m.emissive_texture()),
        // KHR_materials_specular defaults (factor 1, colour 1) when the extension is absent.
        specular_factor: specular.as_ref().map_or(1.0, |s| s.specular_factor()),
        specular_texture: specular
            .as_ref()
            .and_then(|s| image_of(s.specular_texture())),
        specular_color: specular
            .as_ref()
            .map_or(Vec3::ONE, |s| Vec3::from(s.specular_color_factor())),
        specular_color_texture: specular
            .as_ref()
            .and_then(|s| image_of(s.specular_color_texture())),
        ior: m.ior().unwrap_or(1.5),
        double_sided: m.double_sided(),
        alpha_cutoff: match m.alpha_mode() {
            gltf::material::AlphaMode::Mask => Some(m.alpha_cutoff().unwrap_or(0.5)),
            _ => None,
        },
        alpha_blend: m.alpha_mode() == gltf::material::AlphaMode::Blend,
        // Checked by validate::check_material before any material is converted.
        uv_transforms: uv_transforms(m).unwrap_or_default(),
    }
}

/// Each slot's KHR_texture_transform (identity where none), or which one is unusable and why.
pub(crate) fn uv_transforms(
    m: &gltf::Material,
) -> Result<[UvTransform; TextureSlot::COUNT], String> {
    let pbr = m.pbr_metallic_roughness();
    let specular = m.specular();
    let from_info = |info: Option<gltf::texture::Info>| {
        info.and_then(|i| i.texture_transform())
            .map(|t| UvTransform {
                offset: Vec2::from(t.offset()),
                rotation: t.rotation(),
                scale: Vec2::from(t.scale()),
            })
    };
    let normal = match m
        .normal_texture()
        .as_ref()
        .and_then(|t| t.extension_value("KHR_texture_transform"))
    {
        Some(value) => Some(normal_texture_transform(value)?),
        None => None,
    };
    let slots = [
        (
            "pbrMetallicRoughness.baseColorTexture",
            from_info(pbr.base_color_texture()),
        ),
        (
            "pbrMetallicRoughness.metallicRoughnessTexture",
            from_info(pbr.metallic_roughness_texture()),
        ),
        ("normalTexture", normal),
        ("emissiveTexture", from_info(m.emissive_texture())),
        (
            "extensions.KHR_materials_specular.specularTexture",
            specular
                .as_ref()
                .and_then(|s| from_info(s.specular_texture())),
        ),
        (
            "extensions.KHR_materials_specular.specularColorTexture",
            specular
                .as_ref()
                .and_then(|s| from_info(s.specular_color_texture())),
        ),
    ];
    let mut out = [UvTransform::IDENTITY; TextureSlot::COUNT];
    for (slot, (field, transform)) in out.iter_mut().zip(slots) {
        let Some(t) = transform else { continue };
        let values = [t.offset.x, t.offset.y, t.rotation, t.scale.x, t.scale.y];
        if let Some(v) = values
            .iter()
            .find(|v| !v.is_finite() || v.abs() > MAX_UV_TRANSFORM)
        {
            return Err(format!("{field}.extensions.KHR_texture_transform holds {v}: offset, rotation and scale must be finite and within ±{MAX_UV_TRANSFORM:e}"));
        }
        *slot = t;
    }
    Ok(out)
}

/// Beyond this a transform is an authoring error (uv at 1e6 has lost every texel of precision).
const MAX_UV_TRANSFORM: f32 = 1e6;

/// The gltf crate reads KHR_texture_transform only on textureInfo, not on normalTexture: read the
/// raw JSON (the extension's defaults where a member is absent).
fn normal_texture_transform(value: &gltf::json::Value) -> Result<UvTransform, String> {
    let field = "normalTexture.extensions.KHR_texture_transform";
    let number = |v: &gltf::json::Value, member: &str| {
        v.as_f64()
            .map(|x| x as f32)
            .ok_or(format!("{field}.{member} must be a number"))
    };
    let pair = |member: &str, default: Vec2| -> Result<Vec2, String> {
        match value.get(member) {
            None => Ok(default),
            Some(gltf::json::Value::Array(a)) if a.len() == 2 => {
                Ok(Vec2::new(number(&a[0], member)?, number(&a[1], member)?))
            }
            Some(_) => Err(format!("{field}.{member} must be an array of two numbers")),
        }
    };
    Ok(UvTransform {
        offset: pair("offset", Vec2::ZERO)?,
        rotation: value
            .get("rotation")
            .map_or(Ok(0.0), |r| number(r, "rotation"))?,
        scale: pair("scale", Vec2::ONE)?,
    })
}
