//! Loader tests on tiny hand-written glTF files: features, and every kind of bad input.

use crate::test_util::{base64, temp_dir};
use crate::{PunctualLight, Scene, SceneError};
use glam::Vec3;
use serde_json::{json, Value};
use std::path::PathBuf;

fn f32_bytes(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// One triangle (0,0,0) (1,0,0) (0,1,0) with u16 indices; `edit` customises the document.
fn triangle_gltf(indices: [u16; 3], edit: impl FnOnce(&mut Value)) -> Value {
    let mut bytes = f32_bytes(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    bytes.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    let mut doc = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": bytes.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&bytes))}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}
        ],
        "meshes": [{"name": "tri", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0
    });
    edit(&mut doc);
    doc
}

fn write(test: &str, name: &str, contents: &[u8]) -> PathBuf {
    let path = temp_dir(test).join(name);
    std::fs::write(&path, contents).expect("write test file");
    path
}

fn load_json(test: &str, doc: &Value) -> Result<Scene, SceneError> {
    Scene::load(&write(test, "scene.gltf", doc.to_string().as_bytes()))
}

fn expect_error(test: &str, result: Result<Scene, SceneError>, needles: &[&str]) -> SceneError {
    let err = result.expect_err("loading should fail");
    let msg = err.to_string();
    assert!(msg.contains(test), "message names the file: {msg}");
    for needle in needles {
        assert!(msg.contains(needle), "message mentions {needle:?}: {msg}");
    }
    err
}

#[test]
fn missing_file_names_the_file() {
    let path = temp_dir("missing_file").join("nowhere.gltf");
    let err = expect_error(
        "missing_file",
        Scene::load(&path),
        &["nowhere.gltf", "cannot read"],
    );
    assert!(matches!(err, SceneError::Io { .. }));
}

#[test]
fn malformed_json_is_reported() {
    let path = write(
        "malformed_json",
        "broken.gltf",
        b"{ \"asset\": { \"version\": \"2.0\" ",
    );
    let err = expect_error(
        "malformed_json",
        Scene::load(&path),
        &["broken.gltf", "malformed"],
    );
    assert!(matches!(err, SceneError::Malformed { .. }));
}

#[test]
fn required_compression_extensions_are_refused_by_name() {
    for ext in [
        "KHR_draco_mesh_compression",
        "EXT_meshopt_compression",
        "KHR_texture_basisu",
    ] {
        let doc = triangle_gltf([0, 1, 2], |d| {
            d["extensionsUsed"] = json!([ext]);
            d["extensionsRequired"] = json!([ext]);
        });
        let err = expect_error("required_ext", load_json("required_ext", &doc), &[ext]);
        assert!(matches!(err, SceneError::Unsupported { .. }));
    }
    // Merely *used* unknown extensions are optional and ignored.
    let doc = triangle_gltf([0, 1, 2], |d| {
        d["extensionsUsed"] = json!(["EXT_some_future_thing"])
    });
    assert_eq!(load_json("used_ext", &doc).unwrap().triangles.len(), 1);
}

#[test]
fn line_and_point_primitives_are_refused() {
    for (mode, name) in [(0, "Points"), (1, "Lines"), (3, "LineStrip")] {
        let doc = triangle_gltf([0, 1, 2], |d| {
            d["meshes"][0]["primitives"][0]["mode"] = json!(mode)
        });
        let err = expect_error("line_mode", load_json("line_mode", &doc), &[name, "tri"]);
        assert!(matches!(err, SceneError::Unsupported { .. }));
    }
}

#[test]
fn out_of_range_vertex_index_is_reported() {
    let doc = triangle_gltf([0, 1, 7], |_| {});
    let err = expect_error(
        "bad_index",
        load_json("bad_index", &doc),
        &["index 7", "3 vertices", "tri"],
    );
    assert!(matches!(err, SceneError::BadPrimitive { .. }));
}

#[test]
fn out_of_range_json_references_are_reported() {
    let doc = triangle_gltf([0, 1, 2], |d| {
        d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(9)
    });
    expect_error(
        "bad_accessor",
        load_json("bad_accessor", &doc),
        &["accessors", "POSITION"],
    );
    let doc = triangle_gltf([0, 1, 2], |d| {
        d["meshes"][0]["primitives"][0]["material"] = json!(9)
    });
    expect_error(
        "bad_material",
        load_json("bad_material", &doc),
        &["material"],
    );
    let doc = triangle_gltf([0, 1, 2], |d| d["nodes"][0]["mesh"] = json!(9));
    expect_error("bad_mesh", load_json("bad_mesh", &doc), &["mesh"]);
    let doc = triangle_gltf([0, 1, 2], |d| {
        d["textures"] = json!([{"source": 9}]);
        d["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
    });
    expect_error("bad_texture", load_json("bad_texture", &doc), &["source"]);
    let doc = triangle_gltf([0, 1, 2], |d| {
        d["bufferViews"][0]["byteLength"] = json!(400)
    });
    let result = load_json("short_buffer", &doc);
    assert!(
        result.is_err(),
        "a view past the end of its buffer must not load"
    );
    expect_error("short_buffer", result, &[]);
}

#[test]
fn hierarchy_cameras_lights_and_materials() {
    let doc = triangle_gltf([0, 1, 2], |d| {
        d["nodes"] = json!([
            {"translation": [0, 0, -5], "children": [1, 2, 3, 4]},
            {"mesh": 0, "scale": [2, 2, 2]},
            {"camera": 0, "translation": [0, 1, 0], "scale": [3, 3, 3]},
            {"camera": 1},
            {"extensions": {"KHR_lights_punctual": {"light": 0}}, "rotation": [-0.70710677, 0, 0, 0.70710677]},
            {"mesh": 1}
        ]);
        d["scenes"] = json!([{"nodes": [0, 5]}]);
        d["cameras"] = json!([
            {"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.01, "aspectRatio": 1.5}},
            {"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.01, "zfar": 10}}
        ]);
        d["extensionsUsed"] = json!([
            "KHR_lights_punctual",
            "KHR_materials_specular",
            "KHR_materials_ior",
            "KHR_materials_emissive_strength"
        ]);
        d["extensions"] = json!({"KHR_lights_punctual": {"lights": [{"type": "spot", "color": [1, 0.5, 0.25], "intensity": 4, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6}}]}});
        d["materials"] = json!([{
            "doubleSided": true, "emissiveFactor": [1, 0.5, 0],
            "pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0.5},
            "extensions": {"KHR_materials_specular": {"specularFactor": 0}, "KHR_materials_ior": {"ior": 1.33},
                           "KHR_materials_emissive_strength": {"emissiveStrength": 5}}
        }]);
        d["meshes"][0]["primitives"][0]["material"] = json!(0);
        // Mesh 1: the same triangle non-indexed, as a strip, without a material.
        d["meshes"]
            .as_array_mut()
            .unwrap()
            .push(json!({"primitives": [{"attributes": {"POSITION": 0}, "mode": 5}]}));
    });
    let scene = load_json("features", &doc).expect("loads");
    assert_eq!(scene.triangles.len(), 2);
    assert_eq!(
        scene.mesh_names,
        vec!["tri".to_string(), "mesh1".to_string()]
    );
    let p = scene.triangle_positions();
    assert_eq!(
        p[0],
        [
            Vec3::new(0.0, 0.0, -5.0),
            Vec3::new(2.0, 0.0, -5.0),
            Vec3::new(0.0, 2.0, -5.0)
        ]
    );
    assert_eq!(p[1][1], Vec3::X);
    assert!(
        (scene.vertices[0].normal - Vec3::Z).length() < 1e-6,
        "flat normal generated"
    );
    // Material 0 from the file; material 1 is the appended default for mesh 1.
    assert_eq!(scene.materials.len(), 2);
    let m = &scene.materials[0];
    assert_eq!(
        (
            m.specular_factor,
            m.ior,
            m.double_sided,
            m.metallic,
            m.roughness
        ),
        (0.0, 1.33, true, 0.0, 0.5)
    );
    assert_eq!(m.emissive, Vec3::new(5.0, 2.5, 0.0));
    assert_eq!(
        (scene.triangles[0].material, scene.triangles[1].material),
        (0, 1)
    );
    assert_eq!(
        (scene.materials[1].specular_factor, scene.materials[1].ior),
        (1.0, 1.5)
    );
    // The orthographic camera is skipped; the perspective one has its scale removed.
    assert_eq!(scene.cameras.len(), 1);
    let cam = &scene.cameras[0];
    assert_eq!((cam.yfov, cam.aspect, cam.znear), (0.7, Some(1.5), 0.01));
    assert!((cam.world_from_view.w_axis.truncate() - Vec3::new(0.0, 1.0, -5.0)).length() < 1e-6);
    assert!((cam.world_from_view.x_axis.truncate().length() - 1.0).abs() < 1e-6);
    match scene.punctual_lights[..] {
        [PunctualLight::Spot {
            position,
            direction,
            intensity,
            inner_cone,
            outer_cone,
            range,
        }] => {
            assert!((position - Vec3::new(0.0, 0.0, -5.0)).length() < 1e-6);
            assert!(
                (direction - Vec3::NEG_Y).length() < 1e-5,
                "rotated −Z: {direction:?}"
            );
            assert_eq!(
                (intensity, inner_cone, outer_cone, range),
                (Vec3::new(4.0, 2.0, 1.0), 0.2, 0.6, None)
            );
        }
        ref other => panic!("expected one spot light, got {other:?}"),
    }
    assert_eq!(scene.bounds().max, Vec3::new(2.0, 2.0, 0.0));
}

/// A 2×2 grey PNG as base colour and normal map: grey expands to RGBA, tangents get generated.
#[test]
fn embedded_png_textures_and_generated_tangents() {
    let mut png = Vec::new();
    image::GrayImage::from_raw(2, 2, vec![0, 64, 128, 255])
        .unwrap()
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    let uvs = f32_bytes(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0]);
    let doc = triangle_gltf([0, 1, 2], |d| {
        d["buffers"].as_array_mut().unwrap().push(json!({"byteLength": uvs.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&uvs))}));
        d["bufferViews"]
            .as_array_mut()
            .unwrap()
            .push(json!({"buffer": 1, "byteLength": 24}));
        d["accessors"]
            .as_array_mut()
            .unwrap()
            .push(json!({"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"}));
        d["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(2);
        d["meshes"][0]["primitives"][0]["material"] = json!(0);
        d["images"] = json!([{"uri": format!("data:image/png;base64,{}", base64(&png))}]);
        d["textures"] = json!([{"source": 0}, {"source": 0}]);
        d["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}, "normalTexture": {"index": 1, "scale": 0.5}}]);
    });
    let scene = load_json("textures", &doc).expect("loads");
    assert_eq!(scene.textures.len(), 1, "two glTF textures share one image");
    let t = &scene.textures[0];
    assert_eq!((t.width, t.height), (2, 2));
    assert_eq!(&t.rgba8[4..8], &[64, 64, 64, 255]);
    let m = &scene.materials[0];
    assert_eq!(
        (m.base_color_texture, m.normal_texture, m.normal_scale),
        (Some(0), Some(0), 0.5)
    );
    for v in &scene.vertices {
        assert!(
            (v.tangent.truncate() - Vec3::X).length() < 1e-5 && v.tangent.w == 1.0,
            "tangent {:?}",
            v.tangent
        );
    }
}

#[test]
fn binary_glb_loads_and_truncated_glb_fails() {
    let mut bin = f32_bytes(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    let doc = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]
    });
    let mut json_chunk = doc.to_string().into_bytes();
    json_chunk.resize(json_chunk.len().next_multiple_of(4), b' ');
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + json_chunk.len() + 8 + bin.len();
    let mut glb = Vec::new();
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend((total as u32).to_le_bytes());
    glb.extend((json_chunk.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&json_chunk);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(&bin);
    let scene = Scene::load(&write("glb", "tri.glb", &glb)).expect("GLB loads");
    assert_eq!(scene.triangles.len(), 1);
    let truncated = write("glb_truncated", "cut.glb", &glb[..glb.len() - 20]);
    expect_error("glb_truncated", Scene::load(&truncated), &["cut.glb"]);
}
