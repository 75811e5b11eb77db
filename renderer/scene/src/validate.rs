//! Checks the document before the gltf crate's accessors and readers touch it: several of them
//! `unwrap` or hit `unreachable!()` on input that its validator lets through (an index accessor of
//! floats, a camera whose `type` names the projection it lacks, an accessor reaching past its
//! view), and values that parse but give meaningless images (a field of view of 0 or π,
//! non-finite or negative emission) are refused here with the field that holds them.

use crate::SceneError;
use gltf::json::accessor::{ComponentType, Type};
use gltf::json::validation::Checked;
use std::path::Path;

/// Emission above this is refused as implausible (a unit mix-up or a corrupt file): the tracer
/// sums light powers in f32, and the brightest real-world glTF emitters stay far below it.
pub const MAX_EMISSIVE_STRENGTH: f32 = 1e6;

fn invalid(file: &Path, detail: String) -> SceneError {
    SceneError::Invalid {
        file: file.to_path_buf(),
        detail,
    }
}

/// Checks on the raw JSON, before `gltf::Document::from_json` (whose validator itself can panic).
pub(crate) fn check_json(json: &gltf::json::Root, file: &Path) -> Result<(), SceneError> {
    check_images_have_sources(json).map_err(|d| invalid(file, d))?;
    check_position_accessors_exist(json).map_err(|d| invalid(file, d))?;
    check_textures_have_sources(json).map_err(|d| invalid(file, d))?;
    check_camera_projections(json).map_err(|d| invalid(file, d))
}

/// `gltf::image::Image::source` unwraps a missing uri / mimeType.
fn check_images_have_sources(json: &gltf::json::Root) -> Result<(), String> {
    for (i, image) in json.images.iter().enumerate() {
        if image.uri.is_none() && (image.buffer_view.is_none() || image.mime_type.is_none()) {
            return Err(format!(
                "images[{i}] needs a uri, or a bufferView with a mimeType"
            ));
        }
    }
    Ok(())
}

/// gltf-json 1.4.1's validator indexes `accessors[POSITION]` unchecked (mesh.rs:151).
fn check_position_accessors_exist(json: &gltf::json::Root) -> Result<(), String> {
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let position = prim
                .attributes
                .get(&Checked::Valid(gltf::Semantic::Positions));
            if let Some(index) = position.filter(|i| i.value() >= json.accessors.len()) {
                return Err(format!(
                    "meshes[{m}].primitives[{p}].attributes.POSITION = {}: index out of range (there are {} accessors)",
                    index.value(),
                    json.accessors.len()
                ));
            }
        }
    }
    Ok(())
}

/// A texture whose only image sits in an extension (MSFT_texture_dds, EXT_texture_webp,
/// KHR_texture_basisu) has no `source`; gltf-json marks that with u32::MAX.
fn check_textures_have_sources(json: &gltf::json::Root) -> Result<(), String> {
    for (i, texture) in json.textures.iter().enumerate() {
        if texture.source.value() == u32::MAX as usize {
            return Err(format!(
                "textures[{i}] has no `source` image: its image is only in an extension (such as MSFT_texture_dds), \
                 and the renderer decodes only PNG and JPEG sources"
            ));
        }
    }
    Ok(())
}

/// `gltf::Camera::projection` unwraps the object its `type` names.
fn check_camera_projections(json: &gltf::json::Root) -> Result<(), String> {
    use gltf::json::camera::Type as CameraType;
    for (i, camera) in json.cameras.iter().enumerate() {
        let present = match camera.type_ {
            Checked::Valid(CameraType::Perspective) => camera.perspective.is_some(),
            Checked::Valid(CameraType::Orthographic) => camera.orthographic.is_some(),
            Checked::Invalid => true, // the validator reports the bad type itself
        };
        if !present {
            return Err(format!(
                "cameras[{i}]: its type names a projection object it does not have"
            ));
        }
    }
    Ok(())
}

/// Checks on the validated document: every accessor the loader reads, cameras, materials, lights.
pub(crate) fn check_document(document: &gltf::Document, file: &Path) -> Result<(), SceneError> {
    let json = document.as_json();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            check_primitive_accessors(json, prim)
                .map_err(|d| invalid(file, format!("meshes[{m}].primitives[{p}].{d}")))?;
        }
    }
    document
        .cameras()
        .try_for_each(|c| check_camera(&c))
        .map_err(|d| invalid(file, d))?;
    document
        .materials()
        .try_for_each(|m| check_material(&m))
        .map_err(|d| invalid(file, d))?;
    if let Some(mut lights) = document.lights() {
        lights
            .try_for_each(|l| check_light(&l))
            .map_err(|d| invalid(file, d))?;
    }
    Ok(())
}

use ComponentType::{F32, U16, U32, U8};

/// The layouts the gltf crate's readers accept for what the loader reads; anything else hits an
/// `unreachable!()` or a size assertion inside them.
const POSITION: &[(ComponentType, Type)] = &[(F32, Type::Vec3)];
const NORMAL: &[(ComponentType, Type)] = &[(F32, Type::Vec3)];
const TANGENT: &[(ComponentType, Type)] = &[(F32, Type::Vec4)];
const TEXCOORD: &[(ComponentType, Type)] =
    &[(F32, Type::Vec2), (U8, Type::Vec2), (U16, Type::Vec2)];
const INDICES: &[(ComponentType, Type)] =
    &[(U8, Type::Scalar), (U16, Type::Scalar), (U32, Type::Scalar)];

fn check_primitive_accessors(
    json: &gltf::json::Root,
    prim: &gltf::json::mesh::Primitive,
) -> Result<(), String> {
    use gltf::Semantic;
    let reads = [
        (Semantic::Positions, "POSITION", POSITION),
        (Semantic::Normals, "NORMAL", NORMAL),
        (Semantic::Tangents, "TANGENT", TANGENT),
        (Semantic::TexCoords(0), "TEXCOORD_0", TEXCOORD),
    ];
    for (semantic, name, allowed) in reads {
        if let Some(index) = prim.attributes.get(&Checked::Valid(semantic)) {
            check_accessor(json, index.value(), allowed)
                .map_err(|d| format!("attributes.{name}: {d}"))?;
        }
    }
    if let Some(index) = &prim.indices {
        check_accessor(json, index.value(), INDICES).map_err(|d| format!("indices: {d}"))?;
    }
    Ok(())
}

fn check_accessor(
    json: &gltf::json::Root,
    index: usize,
    allowed: &[(ComponentType, Type)],
) -> Result<(), String> {
    let a = json
        .accessors
        .get(index)
        .ok_or_else(|| format!("accessors[{index}] does not exist"))?;
    let here = |d: String| format!("accessors[{index}] {d}");
    let (Checked::Valid(component), Checked::Valid(kind)) = (a.component_type, a.type_) else {
        return Err(here("has an invalid componentType or type".into()));
    };
    let component = component.0;
    if !allowed.contains(&(component, kind)) {
        let names: Vec<String> = allowed.iter().map(|(c, t)| layout_name(*c, *t)).collect();
        return Err(here(format!(
            "is {}; expected {}",
            layout_name(component, kind),
            names.join(" or ")
        )));
    }
    let count = a.count.0;
    if count == 0 {
        return Err(here("has count 0 (glTF requires at least 1)".into()));
    }
    let element = (component.size() * kind.multiplicity()) as u64;
    if let Some(view) = a.buffer_view {
        let offset = a.byte_offset.map_or(0, |o| o.0);
        check_view_range(json, view.value(), offset, count, element).map_err(here)?;
    }
    if let Some(sparse) = &a.sparse {
        let n = sparse.count.0;
        if n == 0 || n > count {
            return Err(here(format!(
                "has sparse.count {n}; it must be in 1..={count}"
            )));
        }
        let index_size = match sparse.indices.component_type {
            Checked::Valid(c) => c.0.size() as u64,
            Checked::Invalid => {
                return Err(here("has an invalid sparse.indices.componentType".into()))
            }
        };
        let (indices, values) = (&sparse.indices, &sparse.values);
        check_view_range(
            json,
            indices.buffer_view.value(),
            indices.byte_offset.0,
            n,
            index_size,
        )
        .map_err(|d| here(format!("sparse.indices: {d}")))?;
        check_view_range(
            json,
            values.buffer_view.value(),
            values.byte_offset.0,
            n,
            element,
        )
        .map_err(|d| here(format!("sparse.values: {d}")))?;
    }
    Ok(())
}

fn layout_name(component: ComponentType, kind: Type) -> String {
    let code = match component {
        ComponentType::I8 => 5120,
        U8 => 5121,
        ComponentType::I16 => 5122,
        U16 => 5123,
        U32 => 5125,
        F32 => 5126,
    };
    format!("{kind:?} of {component:?} (componentType {code})")
}

/// `count` elements of `element` bytes at `offset`, `byteStride` apart, must lie inside the view,
/// and the view inside its buffer's declared byteLength (which is all the loader reads).
fn check_view_range(
    json: &gltf::json::Root,
    view_index: usize,
    offset: u64,
    count: u64,
    element: u64,
) -> Result<(), String> {
    let view = json
        .buffer_views
        .get(view_index)
        .ok_or_else(|| format!("bufferView {view_index} does not exist"))?;
    let stride = view.byte_stride.map_or(element, |s| s.0 as u64);
    if stride < element {
        return Err(format!(
            "has {element}-byte elements but bufferViews[{view_index}].byteStride is {stride}"
        ));
    }
    let end = stride
        .checked_mul(count - 1)
        .and_then(|v| v.checked_add(offset))
        .and_then(|v| v.checked_add(element));
    let view_len = view.byte_length.0;
    match end {
        Some(end) if end <= view_len => {}
        _ => {
            return Err(format!(
                "reaches past the end of bufferViews[{view_index}] (byteLength {view_len})"
            ))
        }
    }
    let buffer_index = view.buffer.value();
    let buffer = json
        .buffers
        .get(buffer_index)
        .ok_or_else(|| format!("buffer {buffer_index} does not exist"))?;
    let view_end = view.byte_offset.map_or(0, |o| o.0).checked_add(view_len);
    match view_end {
        Some(e) if e <= buffer.byte_length.0 => Ok(()),
        _ => Err(format!("uses bufferViews[{view_index}], which reaches past the end of buffers[{buffer_index}] (byteLength {})", buffer.byte_length.0)),
    }
}

fn check_camera(camera: &gltf::Camera) -> Result<(), String> {
    let i = camera.index();
    let gltf::camera::Projection::Perspective(p) = camera.projection() else {
        return Ok(()); // orthographic cameras are skipped by the loader
    };
    let yfov = p.yfov();
    if !(yfov > 0.0 && yfov < std::f32::consts::PI) {
        return Err(format!("cameras[{i}].perspective.yfov = {yfov}: the vertical field of view must be in (0, π) radians"));
    }
    let znear = p.znear();
    if !(znear > 0.0 && znear.is_finite()) {
        return Err(format!(
            "cameras[{i}].perspective.znear = {znear}: must be a finite distance above 0"
        ));
    }
    if let Some(aspect) = p.aspect_ratio().filter(|a| !(*a > 0.0 && a.is_finite())) {
        return Err(format!(
            "cameras[{i}].perspective.aspectRatio = {aspect}: must be finite and above 0"
        ));
    }
    Ok(())
}

fn check_material(m: &gltf::Material) -> Result<(), String> {
    let name = format!(
        "materials[{}]",
        m.index().map_or("default".into(), |i| i.to_string())
    );
    if let Some(s) = m.emissive_strength() {
        if !(s.is_finite() && (0.0..=MAX_EMISSIVE_STRENGTH).contains(&s)) {
            return Err(format!(
                "{name}.extensions.KHR_materials_emissive_strength.emissiveStrength = {s}: must be finite, ≥ 0 and ≤ {MAX_EMISSIVE_STRENGTH:e}"
            ));
        }
    }
    let pbr = m.pbr_metallic_roughness();
    let fields: [(&str, &[f32]); 5] = [
        ("emissiveFactor", &m.emissive_factor()),
        (
            "pbrMetallicRoughness.baseColorFactor",
            &pbr.base_color_factor(),
        ),
        (
            "pbrMetallicRoughness.metallicFactor",
            &[pbr.metallic_factor()],
        ),
        (
            "pbrMetallicRoughness.roughnessFactor",
            &[pbr.roughness_factor()],
        ),
        (
            "extensions.KHR_materials_ior.ior",
            &[m.ior().unwrap_or(1.5)],
        ),
    ];
    for (field, values) in fields {
        if let Some(v) = values.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
            return Err(format!("{name}.{field} holds {v}: must be finite and ≥ 0"));
        }
    }
    crate::load_material::uv_transforms(m).map_err(|e| format!("{name}.{e}"))?;
    Ok(())
}

fn check_light(light: &gltf::khr_lights_punctual::Light) -> Result<(), String> {
    let i = light.index();
    let colour = light.color();
    if let Some(v) = colour
        .iter()
        .chain([light.intensity()].iter())
        .find(|v| !(v.is_finite() && **v >= 0.0))
    {
        return Err(format!("KHR_lights_punctual.lights[{i}]: colour and intensity must be finite and ≥ 0 (found {v})"));
    }
    if let Some(r) = light.range().filter(|r| !(*r > 0.0 && r.is_finite())) {
        return Err(format!(
            "KHR_lights_punctual.lights[{i}].range = {r}: must be finite and above 0"
        ));
    }
    if let gltf::khr_lights_punctual::Kind::Spot {
        inner_cone_angle,
        outer_cone_angle,
    } = light.kind()
    {
        let ok = inner_cone_angle >= 0.0
            && inner_cone_angle < outer_cone_angle
            && outer_cone_angle <= std::f32::consts::FRAC_PI_2;
        if !ok {
            return Err(format!(
                "KHR_lights_punctual.lights[{i}].spot: cone angles {inner_cone_angle}, {outer_cone_angle} must satisfy 0 ≤ inner < outer ≤ π/2"
            ));
        }
    }
    Ok(())
}
