//! Loader tests for hostile and broken input: URIs leaving the scene's folder, non-regular files,
//! declared sizes, budgets (the instancing bomb), images only an extension refers to, values that
//! make meaningless images, and a fuzz test over mutated real files that a panic fails.

use crate::limits::LoadLimits;
use crate::load::load_unguarded;
use crate::test_util::{base64, temp_dir};
use crate::{Scene, SceneError, TextureSlot, UvTransform};
use glam::Vec2;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

fn f32_bytes(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// Three positions (0,0,0) (1,0,0) (0,1,0) followed by u16 indices 0,1,2 (42 bytes).
fn triangle_bytes() -> Vec<u8> {
    let mut bytes = f32_bytes(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    bytes.extend([0u16, 1, 2].iter().flat_map(|i| i.to_le_bytes()));
    bytes
}

/// One indexed triangle whose buffer is `buffer_uri` (42 bytes declared).
fn triangle_doc(buffer_uri: &str) -> Value {
    json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": 42, "uri": buffer_uri}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}
        ],
        "meshes": [{"name": "tri", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0
    })
}

fn embedded_triangle_doc() -> Value {
    triangle_doc(&format!(
        "data:application/octet-stream;base64,{}",
        base64(&triangle_bytes())
    ))
}

fn write_doc(dir: &Path, doc: &Value) -> PathBuf {
    let path = dir.join("scene.gltf");
    std::fs::write(&path, doc.to_string()).unwrap();
    path
}

/// Loads without the panic backstop, so a panic anywhere fails the test instead of turning into
/// an error.
fn load(path: &Path) -> Result<Scene, SceneError> {
    load_unguarded(path, &LoadLimits::default())
}

fn error_text(result: Result<Scene, SceneError>) -> String {
    match result {
        Ok(_) => panic!("loading should fail"),
        Err(e) => e.to_string(),
    }
}

fn assert_mentions(msg: &str, needles: &[&str]) {
    for n in needles {
        assert!(msg.contains(n), "message lacks {n:?}: {msg}");
    }
}

#[test]
fn float_index_accessor_is_an_error_not_a_panic() {
    let dir = temp_dir("float_indices");
    let mut doc = embedded_triangle_doc();
    doc["accessors"][1]["componentType"] = json!(5126);
    doc["bufferViews"][1]["byteLength"] = json!(6);
    let msg = error_text(load(&write_doc(&dir, &doc)));
    assert_mentions(
        &msg,
        &[
            "scene.gltf",
            "meshes[0].primitives[0].indices",
            "accessors[1]",
            "componentType 5126",
            "Scalar of U16",
        ],
    );
    // A POSITION of the wrong shape trips a size assertion in the gltf crate's reader.
    let mut doc = embedded_triangle_doc();
    doc["accessors"][0]["type"] = json!("VEC2");
    assert_mentions(
        &error_text(load(&write_doc(&dir, &doc))),
        &["attributes.POSITION", "Vec2 of F32"],
    );
}

#[test]
fn accessors_reaching_past_their_view_or_with_count_zero_are_refused() {
    let dir = temp_dir("accessor_ranges");
    for (edit, needle) in [
        (("accessors", 0, "count", json!(0)), "count 0"),
        (
            ("accessors", 0, "byteOffset", json!(4)),
            "reaches past the end of bufferViews[0]",
        ),
        (
            ("accessors", 1, "count", json!(4)),
            "reaches past the end of bufferViews[1]",
        ),
        (
            ("bufferViews", 1, "byteOffset", json!(40)),
            "reaches past the end of buffers[0]",
        ),
        (
            ("accessors", 0, "byteOffset", json!(u64::MAX - 8)),
            "reaches past the end",
        ),
        (
            ("bufferViews", 0, "byteStride", json!(4)),
            "byteStride is 4",
        ),
    ] {
        let mut doc = embedded_triangle_doc();
        let (array, index, key, value) = edit;
        doc[array][index][key] = value;
        assert_mentions(&error_text(load(&write_doc(&dir, &doc))), &[needle]);
    }
}

#[test]
fn camera_whose_type_names_a_missing_projection_is_an_error() {
    let dir = temp_dir("camera_type");
    let mut doc = embedded_triangle_doc();
    doc["cameras"] = json!([{"type": "perspective", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}}]);
    doc["nodes"] = json!([{"mesh": 0}, {"camera": 0}]);
    doc["scenes"] = json!([{"nodes": [0, 1]}]);
    assert_mentions(
        &error_text(load(&write_doc(&dir, &doc))),
        &["cameras[0]", "projection"],
    );
}

#[test]
fn meaningless_camera_emission_and_position_values_are_refused() {
    let dir = temp_dir("meaningless");
    let with_camera = |yfov: f64| {
        let mut doc = embedded_triangle_doc();
        doc["cameras"] =
            json!([{"type": "perspective", "perspective": {"yfov": yfov, "znear": 0.1}}]);
        doc["nodes"] = json!([{"mesh": 0}, {"camera": 0}]);
        doc["scenes"] = json!([{"nodes": [0, 1]}]);
        doc
    };
    for yfov in [0.0, -0.5, std::f64::consts::PI, 4.0] {
        let msg = error_text(load(&write_doc(&dir, &with_camera(yfov))));
        assert_mentions(&msg, &["cameras[0].perspective.yfov", "(0, π)"]);
    }
    // Beyond f32: refused by the validation, or by the JSON parser where the workspace enables
    // serde_json's exact float parsing; the parser's message then quotes the key.
    let msg = error_text(load(&write_doc(&dir, &with_camera(1e39))));
    let validated = msg.contains("cameras[0].perspective.yfov") && msg.contains("(0, π)");
    let parsed = msg.contains("out of range") && msg.contains("\"yfov\":1e");
    assert!(validated || parsed, "{msg}");
    assert!(load(&write_doc(&dir, &with_camera(0.8))).is_ok());

    for strength in [-1.0, 1e30, 1e39] {
        let mut doc = embedded_triangle_doc();
        doc["extensionsUsed"] = json!(["KHR_materials_emissive_strength"]);
        doc["materials"] = json!([{"emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": strength}}}]);
        doc["meshes"][0]["primitives"][0]["material"] = json!(0);
        let msg = error_text(load(&write_doc(&dir, &doc)));
        let validated = ["materials[0]", "emissiveStrength", "finite, ≥ 0"]
            .iter()
            .all(|n| msg.contains(n));
        let parsed = msg.contains("out of range") && msg.contains("\"emissiveStrength\":1e");
        assert!(validated || (strength == 1e39 && parsed), "{msg}");
    }

    // NaN and infinity cannot be written in JSON, but binary buffers hold them.
    for bad in [f32::NAN, f32::INFINITY] {
        let mut bytes = f32_bytes(&[0.0, 0.0, 0.0, bad, 0.0, 0.0, 0.0, 1.0, 0.0]);
        bytes.extend([0u16, 1, 2].iter().flat_map(|i| i.to_le_bytes()));
        let doc = triangle_doc(&format!(
            "data:application/octet-stream;base64,{}",
            base64(&bytes)
        ));
        assert_mentions(
            &error_text(load(&write_doc(&dir, &doc))),
            &["mesh 'tri'", "POSITION element 1", "finite"],
        );
    }
    // Finite transforms whose product is not.
    let mut doc = embedded_triangle_doc();
    doc["nodes"] = json!([{"children": [1], "scale": [1e30, 1e30, 1e30]}, {"mesh": 0, "scale": [1e30, 1e30, 1e30]}]);
    assert_mentions(
        &error_text(load(&write_doc(&dir, &doc))),
        &["nodes[1]", "not finite"],
    );
}

/// A folder with the scene in `scene/` and a secret file beside it, outside the folder.
fn folder_with_secret(test: &str) -> (PathBuf, PathBuf) {
    let root = temp_dir(test);
    let scene_dir = root.join("scene");
    std::fs::create_dir_all(&scene_dir).unwrap();
    let mut secret = b"SECRET-CONTENT-".to_vec();
    secret.extend(triangle_bytes());
    std::fs::write(root.join("secret.bin"), &secret).unwrap();
    (scene_dir, root.join("secret.bin"))
}

#[test]
fn buffer_uris_leaving_the_scene_folder_are_refused_without_echoing_the_file() {
    let (scene_dir, secret) = folder_with_secret("traversal");
    let absolute = secret.display().to_string();
    std::os::unix::fs::symlink(&secret, scene_dir.join("link.bin")).unwrap();
    std::os::unix::fs::symlink(scene_dir.parent().unwrap(), scene_dir.join("up")).unwrap();
    for (uri, reason) in [
        ("../secret.bin".to_string(), "'..'"),
        ("sub/../../secret.bin".to_string(), "'..'"),
        ("%2E%2E/secret.bin".to_string(), "'..'"),
        (absolute.clone(), "absolute"),
        (format!("file://{absolute}"), "'file:' scheme"),
        ("link.bin".to_string(), "outside the scene's folder"),
        ("up/secret.bin".to_string(), "outside the scene's folder"),
    ] {
        let msg = error_text(load(&write_doc(&scene_dir, &triangle_doc(&uri))));
        assert_mentions(&msg, &["scene.gltf", "buffers[0]", &uri, reason]);
        assert!(
            !msg.contains("SECRET"),
            "the refused file's bytes leak into the message: {msg}"
        );
    }
    // A symbolic link that stays inside the folder is fine.
    std::fs::write(scene_dir.join("real.bin"), triangle_bytes()).unwrap();
    std::os::unix::fs::symlink("real.bin", scene_dir.join("alias.bin")).unwrap();
    assert_eq!(
        load(&write_doc(&scene_dir, &triangle_doc("alias.bin")))
            .unwrap()
            .triangles
            .len(),
        1
    );
    assert_eq!(
        load(&write_doc(&scene_dir, &triangle_doc("./real%2Ebin")))
            .unwrap()
            .triangles
            .len(),
        1
    );
}

/// Runs `f` on a thread and fails the test if it does not finish in time (a blocking open of a
/// FIFO would otherwise hang the whole test run).
fn within_seconds<T: Send + 'static>(seconds: u64, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(std::time::Duration::from_secs(seconds))
        .expect("the loader blocked or ran away")
}

fn mkfifo(path: &Path) {
    let status = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("run mkfifo");
    assert!(status.success(), "mkfifo {} failed", path.display());
}

#[test]
fn fifos_and_devices_are_never_opened_for_reading() {
    let dir = temp_dir("fifo");
    mkfifo(&dir.join("pipe.bin"));
    let path = write_doc(&dir, &triangle_doc("pipe.bin"));
    let msg = within_seconds(10, move || error_text(load(&path)));
    assert_mentions(
        &msg,
        &["buffers[0]", "pipe.bin", "FIFO", "not a regular file"],
    );

    // /dev/zero never ends: as the scene file, and through a link in the folder.
    let msg = within_seconds(10, || error_text(load(Path::new("/dev/zero"))));
    assert_mentions(&msg, &["/dev/zero", "a device, not a regular file"]);
    std::os::unix::fs::symlink("/dev/zero", dir.join("zero.bin")).unwrap();
    let path = write_doc(&dir, &triangle_doc("zero.bin"));
    let msg = within_seconds(10, move || error_text(load(&path)));
    assert_mentions(&msg, &["buffers[0]", "zero.bin"]);
    // Inside the folder's own view, a device is refused by type (not only by location).
    let mut budget = crate::limits::ByteBudget::new(1 << 20);
    let err = crate::source::read_bounded(Path::new("/dev/zero"), Some(16), &mut budget, "b")
        .unwrap_err();
    assert!(
        err.to_string().contains("a device, not a regular file"),
        "{err}"
    );
    // The scene file as a FIFO.
    mkfifo(&dir.join("pipe.gltf"));
    let fifo_scene = dir.join("pipe.gltf");
    let msg = within_seconds(10, move || error_text(load(&fifo_scene)));
    assert_mentions(&msg, &["pipe.gltf", "FIFO"]);
}

#[test]
fn buffers_are_read_exactly_as_far_as_declared() {
    let dir = temp_dir("declared");
    std::fs::write(dir.join("short.bin"), &triangle_bytes()[..40]).unwrap();
    let msg = error_text(load(&write_doc(&dir, &triangle_doc("short.bin"))));
    assert_mentions(
        &msg,
        &[
            "buffers[0]",
            "short.bin",
            "has 40 bytes but byteLength declares 42",
        ],
    );
    // A longer file loads; only the declared bytes are read (the budget proves it: 42 + the
    // JSON fit, the whole file would not).
    let mut long = triangle_bytes();
    long.resize(1 << 20, 0xAB);
    std::fs::write(dir.join("long.bin"), &long).unwrap();
    let path = write_doc(&dir, &triangle_doc("long.bin"));
    let json_len = std::fs::metadata(&path).unwrap().len();
    let limits = LoadLimits {
        max_bytes: json_len + 42,
        ..LoadLimits::default()
    };
    assert_eq!(load_unguarded(&path, &limits).unwrap().triangles.len(), 1);
    let limits = LoadLimits {
        max_bytes: json_len + 41,
        ..LoadLimits::default()
    };
    assert_mentions(
        &error_text(load_unguarded(&path, &limits)),
        &["buffers[0]", "byte budget", "FOVEA_MAX_SCENE_BYTES"],
    );
    // A data URI shorter than declared.
    let short = triangle_doc(&format!(
        "data:application/octet-stream;base64,{}",
        base64(&triangle_bytes()[..30])
    ));
    assert_mentions(
        &error_text(load(&write_doc(&dir, &short))),
        &["buffers[0]", "holds 30 bytes but byteLength declares 42"],
    );
}

/// One mesh of `triangles` triangles (three shared vertices, indices repeated) placed by `nodes`
/// nodes; its buffer is a file that does not exist, so reaching the buffer read fails differently.
fn instancing_bomb(triangles: usize, nodes: usize) -> Value {
    let mut doc = triangle_doc("never-read.bin");
    let index_bytes = triangles * 6;
    doc["buffers"][0]["byteLength"] = json!(36 + index_bytes);
    doc["bufferViews"][1]["byteLength"] = json!(index_bytes);
    doc["accessors"][1]["count"] = json!(triangles * 3);
    doc["meshes"][0]["name"] = json!("bomb");
    doc["nodes"] = json!((0..nodes)
        .map(|i| json!({"mesh": 0, "translation": [i as f32, 0, 0]}))
        .collect::<Vec<_>>());
    doc["scenes"] = json!([{"nodes": (0..nodes).collect::<Vec<_>>()}]);
    doc
}

#[test]
fn the_instancing_bomb_is_instanced_and_its_budgets_are_checked_before_any_geometry_is_read() {
    let dir = temp_dir("bomb");
    // 12 M placed triangles but 20 000 uploaded: instancing makes it fit the triangle budget, so
    // the load gets as far as reading its (missing) buffer.
    let path = write_doc(&dir, &instancing_bomb(20_000, 600));
    assert_mentions(
        &error_text(load(&path)),
        &["buffers[0]", "never-read.bin", "cannot open"],
    );
    let limits = LoadLimits {
        max_triangles: 19_999,
        ..LoadLimits::default()
    };
    let msg = error_text(load_unguarded(&path, &limits));
    assert_mentions(
        &msg,
        &[
            "meshes: 20000 triangles to upload",
            "mesh 'bomb', 20000 triangles × 1 copies",
            "triangle budget of 19999",
            "FOVEA_MAX_TRIANGLES",
        ],
    );
    assert!(
        !msg.contains("never-read.bin"),
        "the budget must be checked before buffers are read: {msg}"
    );
    let limits = LoadLimits {
        max_instances: 599,
        ..LoadLimits::default()
    };
    assert_mentions(
        &error_text(load_unguarded(&path, &limits)),
        &[
            "nodes: 600 mesh instances",
            "mesh 'bomb', placed by 600 nodes",
            "instance budget of 599",
            "FOVEA_MAX_INSTANCES",
        ],
    );
    // Placed triangles beyond 32-bit ids are refused whatever the budgets, without expanding.
    let started = std::time::Instant::now();
    let path = write_doc(&dir, &instancing_bomb(1_500_000, 3_000));
    assert_mentions(
        &error_text(load(&path)),
        &["nodes: 4500000000 placed triangles", "32-bit id"],
    );
    assert!(
        started.elapsed().as_secs() < 5,
        "refusing must not expand the copies"
    );
}

fn png_bytes(width: u32, height: u32) -> Vec<u8> {
    let mut png = Vec::new();
    image::RgbaImage::from_pixel(width, height, image::Rgba([200, 100, 50, 255]))
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    png
}

/// The embedded triangle with UVs and one material whose base colour is `textures[0]`.
fn textured_doc(images: Value, textures: Value) -> Value {
    let mut bytes = triangle_bytes();
    bytes.extend([0u8; 2]); // align the UVs
    bytes.extend(f32_bytes(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0]));
    let mut doc = triangle_doc(&format!(
        "data:application/octet-stream;base64,{}",
        base64(&bytes)
    ));
    doc["buffers"][0]["byteLength"] = json!(bytes.len());
    doc["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(json!({"buffer": 0, "byteOffset": 44, "byteLength": 24}));
    doc["accessors"]
        .as_array_mut()
        .unwrap()
        .push(json!({"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"}));
    doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(2);
    doc["meshes"][0]["primitives"][0]["material"] = json!(0);
    doc["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
    doc["images"] = images;
    doc["textures"] = textures;
    doc
}

/// Capsaicin's Sponza: every texture's `source` is a PNG, `MSFT_texture_dds` points at a DDS
/// alternative. The DDS files are never opened (here they do not even exist).
#[test]
fn dds_alternatives_are_skipped_and_png_sources_load() {
    let dir = temp_dir("dds");
    std::fs::write(dir.join("floor.png"), png_bytes(4, 2)).unwrap();
    let mut doc = textured_doc(
        json!([
            {"uri": "floor.dds", "mimeType": "image/vnd-ms.dds"},
            {"uri": "floor.png", "mimeType": "image/png"},
            {"uri": "unused.png"}
        ]),
        json!([{"source": 1, "extensions": {"MSFT_texture_dds": {"source": 0}}}]),
    );
    doc["extensionsUsed"] = json!([
        "MSFT_texture_dds",
        "EXT_texture_webp",
        "KHR_texture_transform"
    ]);
    let scene = load(&write_doc(&dir, &doc)).unwrap();
    assert_eq!(
        scene.textures.len(),
        1,
        "only the PNG a material samples is decoded"
    );
    assert_eq!((scene.textures[0].width, scene.textures[0].height), (4, 2));
    assert_eq!(&scene.textures[0].rgba8[..4], &[200, 100, 50, 255]);
    assert_eq!(scene.materials[0].base_color_texture, Some(0));
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    assert_mentions(
        &scene.warnings[0],
        &["MSFT_texture_dds, EXT_texture_webp", "does not understand"],
    );
    // Required, it is refused as before.
    doc["extensionsRequired"] = json!(["MSFT_texture_dds"]);
    assert_mentions(
        &error_text(load(&write_doc(&dir, &doc))),
        &["required extension MSFT_texture_dds"],
    );
}

#[test]
fn undecodable_images_are_named_with_uri_mime_type_and_reason() {
    let dir = temp_dir("bad_image");
    std::fs::write(dir.join("broken.png"), b"this is not a PNG").unwrap();
    let doc = textured_doc(json!([{"uri": "broken.png"}]), json!([{"source": 0}]));
    let msg = error_text(load(&write_doc(&dir, &doc)));
    assert_mentions(
        &msg,
        &[
            "scene.gltf",
            "images[0]",
            "uri \"broken.png\"",
            "mime type image/png",
            "cannot be loaded",
        ],
    );
    assert!(!msg.contains("this is not"), "{msg}");
    // A DDS used as a texture's only source: named, and never read.
    let doc = textured_doc(json!([{"uri": "missing.dds"}]), json!([{"source": 0}]));
    assert_mentions(
        &error_text(load(&write_doc(&dir, &doc))),
        &[
            "images[0]",
            "missing.dds",
            "image/vnd-ms.dds is not decoded",
        ],
    );
    // An embedded image with a lying mime type.
    let bogus = format!("data:image/jpeg;base64,{}", base64(&png_bytes(2, 2)));
    let doc = textured_doc(json!([{"uri": bogus}]), json!([{"source": 0}]));
    let msg = error_text(load(&write_doc(&dir, &doc)));
    assert_mentions(
        &msg,
        &[
            "images[0]",
            "data:image/jpeg;base64,…",
            "mime type image/jpeg",
        ],
    );
    // Image URIs are confined like buffer URIs.
    let doc = textured_doc(json!([{"uri": "../floor.png"}]), json!([{"source": 0}]));
    assert_mentions(
        &error_text(load(&write_doc(&dir, &doc))),
        &["images[0]", "'..'"],
    );
}

#[test]
fn texel_budget_is_enforced_before_decoding() {
    let dir = temp_dir("texels");
    std::fs::write(dir.join("big.png"), png_bytes(64, 64)).unwrap();
    let doc = textured_doc(json!([{"uri": "big.png"}]), json!([{"source": 0}]));
    let path = write_doc(&dir, &doc);
    let limits = LoadLimits {
        max_texels: 4095,
        ..LoadLimits::default()
    };
    assert_mentions(
        &error_text(load_unguarded(&path, &limits)),
        &[
            "images[0] (64×64",
            "texel budget of 4095",
            "FOVEA_MAX_TEXELS",
        ],
    );
    let limits = LoadLimits {
        max_texels: 4096,
        ..LoadLimits::default()
    };
    assert_eq!(load_unguarded(&path, &limits).unwrap().textures.len(), 1);
}

#[test]
fn unused_materials_keep_their_slot_but_decode_no_images() {
    let dir = temp_dir("unused_material");
    let png = format!("data:image/png;base64,{}", base64(&png_bytes(2, 2)));
    let mut doc = textured_doc(
        json!([{"uri": png}, {"uri": "does-not-exist.png"}]),
        json!([{"source": 0}, {"source": 1}]),
    );
    doc["materials"]
        .as_array_mut()
        .unwrap()
        .push(json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 1}}}));
    let scene = load(&write_doc(&dir, &doc)).unwrap();
    assert_eq!(scene.materials.len(), 2);
    assert_eq!(scene.textures.len(), 1);
    assert_eq!(scene.materials[1].base_color_texture, None);
}

mod fuzz {
    //! Mutated real glTF files must load or fail with an error, never panic. `load_unguarded`
    //! has no panic backstop, so a panic fails the property.
    use super::*;
    use proptest::prelude::*;

    /// Seeds: the project's Cornell box, and a small textured file (images, UVs, materials).
    fn seeds() -> Vec<Value> {
        let cornell =
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.gltf");
        let cornell: Value = serde_json::from_str(
            &std::fs::read_to_string(cornell).expect("scenes/cornell-box.gltf"),
        )
        .unwrap();
        let png = format!("data:image/png;base64,{}", base64(&png_bytes(2, 2)));
        vec![
            cornell,
            textured_doc(json!([{"uri": png}]), json!([{"source": 0}])),
        ]
    }

    /// The triangle as a binary glTF (JSON chunk + BIN chunk): mutations hit the container's
    /// headers and chunk lengths.
    fn glb_triangle() -> Vec<u8> {
        let mut doc = embedded_triangle_doc();
        doc["buffers"] = json!([{"byteLength": 42}]);
        let mut json_chunk = doc.to_string().into_bytes();
        json_chunk.resize(json_chunk.len().next_multiple_of(4), b' ');
        let mut bin = triangle_bytes();
        bin.resize(bin.len().next_multiple_of(4), 0);
        let total = 12 + 8 + json_chunk.len() + 8 + bin.len();
        let mut glb = b"glTF".to_vec();
        for v in [2, total as u32, json_chunk.len() as u32] {
            glb.extend(v.to_le_bytes());
        }
        glb.extend(b"JSON");
        glb.extend(&json_chunk);
        glb.extend((bin.len() as u32).to_le_bytes());
        glb.extend(b"BIN\0");
        glb.extend(&bin);
        glb
    }

    #[test]
    fn the_glb_seed_loads_unmutated() {
        let dir = temp_dir("fuzz_glb_seed");
        let path = dir.join("scene.glb");
        std::fs::write(&path, glb_triangle()).unwrap();
        assert_eq!(load(&path).unwrap().triangles.len(), 1);
    }

    /// Paths to every number, string and array element in the document (where values live).
    fn leaves(v: &Value, path: &mut Vec<Value>, out: &mut Vec<Vec<Value>>) {
        match v {
            Value::Object(map) => map.iter().for_each(|(k, c)| {
                path.push(json!(k));
                out.push(path.clone());
                leaves(c, path, out);
                path.pop();
            }),
            Value::Array(items) => items.iter().enumerate().for_each(|(i, c)| {
                path.push(json!(i));
                out.push(path.clone());
                leaves(c, path, out);
                path.pop();
            }),
            _ => {}
        }
    }

    fn at<'a>(v: &'a mut Value, path: &[Value]) -> Option<&'a mut Value> {
        path.iter().try_fold(v, |v, key| match key {
            Value::String(k) => v.get_mut(k.as_str()),
            Value::Number(i) => v.get_mut(i.as_u64()? as usize),
            _ => None,
        })
    }

    /// Values that break assumptions: zero, negatives, enum codes of the wrong kind, huge counts
    /// and offsets, out-of-range indices, non-finite-after-parse floats, wrong JSON types.
    fn nasty(k: usize) -> Value {
        let table = [
            json!(0),
            json!(-1),
            json!(1),
            json!(3),
            json!(4),
            json!(7),
            json!(255),
            json!(65535),
            json!(5120),
            json!(5121),
            json!(5122),
            json!(5123),
            json!(5125),
            json!(5126),
            json!(4294967295u64),
            json!(u64::MAX),
            json!(1e30),
            json!(-1e30),
            json!(1e39),
            json!(0.5),
            json!("VEC4"),
            json!("SCALAR"),
            json!("MAT4"),
            json!(""),
            json!("../x.bin"),
            json!("data:;base64,"),
            json!(null),
            json!([]),
            json!({}),
            json!(true),
        ];
        table[k % table.len()].clone()
    }

    fn mutate(mut doc: Value, picks: &[(usize, usize, bool)]) -> Value {
        for &(where_, what, delete) in picks {
            let mut paths = Vec::new();
            leaves(&doc, &mut Vec::new(), &mut paths);
            if paths.is_empty() {
                break;
            }
            let path = &paths[where_ % paths.len()];
            if delete {
                let (last, parent) = path.split_last().unwrap();
                match (at(&mut doc, parent), last) {
                    (Some(Value::Object(map)), Value::String(k)) => {
                        map.remove(k);
                    }
                    (Some(Value::Array(items)), Value::Number(i)) => {
                        let i = i.as_u64().unwrap() as usize;
                        if i < items.len() {
                            items.remove(i);
                        }
                    }
                    _ => {}
                }
            } else if let Some(slot) = at(&mut doc, path) {
                *slot = nasty(what);
            }
        }
        doc
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 300, failure_persistence: None, ..ProptestConfig::default() })]

        #[test]
        fn mutated_documents_never_panic(seed in 0usize..2, picks in proptest::collection::vec((any::<usize>(), any::<usize>(), proptest::bool::weighted(0.2)), 1..6)) {
            let dir = temp_dir("fuzz_json");
            let doc = mutate(seeds().swap_remove(seed), &picks);
            let _ = load(&write_doc(&dir, &doc));
        }

        #[test]
        fn mutated_bytes_never_panic(seed in 0usize..3, edits in proptest::collection::vec((any::<usize>(), any::<u8>()), 1..8), cut in proptest::option::of(any::<usize>())) {
            let dir = temp_dir("fuzz_bytes");
            let mut bytes = match seed {
                2 => glb_triangle(),
                _ => seeds().swap_remove(seed).to_string().into_bytes(),
            };
            for (at, byte) in edits {
                let i = at % bytes.len();
                bytes[i] = byte;
            }
            if let Some(cut) = cut {
                bytes.truncate(cut % (bytes.len() + 1));
            }
            let path = dir.join(if seed == 2 { "scene.glb" } else { "scene.gltf" });
            std::fs::write(&path, &bytes).unwrap();
            let _ = load(&path);
        }
    }
}

/// The shared real scenes (`../shared/data/scenes`) load within the default budgets, with no
/// warnings, exactly as their README describes them.
#[test]
fn shared_real_scenes_load_within_the_default_budgets() {
    for (file, triangles, cameras) in [
        ("sponza/Sponza.gltf", 262_087, 4),
        ("breakfast-room/BreakfastRoom.gltf", 262_687, 3),
        ("flight-helmet/FlightHelmet.gltf", 94_722, 0),
    ] {
        let Some(path) = fovea_test_kit::data::shared_data(&format!("scenes/{file}")) else {
            continue;
        };
        let scene = load(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            (scene.placed_triangle_count(), scene.cameras.len()),
            (triangles, cameras),
            "{file}"
        );
        println!(
            "{file}: {} flattened triangles, {} instanced meshes ({} triangles) placed by {} instances",
            scene.triangles.len(),
            scene.instancing.meshes.len(),
            scene.unique_triangle_count() - scene.triangles.len(),
            scene.instancing.instances.len()
        );
        assert!(!scene.textures.is_empty(), "{file}");
        assert!(scene.warnings.is_empty(), "{file}: {:?}", scene.warnings);
    }
}

/// KHR_texture_transform on a textureInfo (the gltf crate's typed reader) and on normalTexture
/// (raw JSON), with the extension's defaults for absent members; a non-finite member is refused
/// naming the material and slot.
#[test]
fn texture_transforms_are_read_per_slot_and_checked() {
    let dir = temp_dir("texture-transform");
    std::fs::write(dir.join("floor.png"), png_bytes(4, 2)).unwrap();
    let mut doc = textured_doc(json!([{"uri": "floor.png"}]), json!([{"source": 0}]));
    doc["extensionsUsed"] = json!(["KHR_texture_transform"]);
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] = json!({"KHR_texture_transform": {"offset": [0.5, 0.25], "rotation": 1.5707964, "scale": [2, 3]}});
    doc["materials"][0]["normalTexture"] =
        json!({"index": 0, "extensions": {"KHR_texture_transform": {"scale": [4, 4]}}});
    let scene = load(&write_doc(&dir, &doc)).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let m = &scene.materials[0];
    let base = m.uv_transforms[TextureSlot::BaseColor as usize];
    assert_eq!(
        (base.offset, base.rotation, base.scale),
        (Vec2::new(0.5, 0.25), 1.5707964, Vec2::new(2.0, 3.0))
    );
    // Rotated a quarter turn: u' = 3v + 0.5, v' = −2u + 0.25.
    let moved = base.apply(Vec2::new(1.0, 1.0));
    assert!((moved - Vec2::new(3.5, -1.75)).length() < 1e-5, "{moved}");
    let normal = m.uv_transforms[TextureSlot::Normal as usize];
    assert_eq!(
        (normal.offset, normal.rotation, normal.scale),
        (Vec2::ZERO, 0.0, Vec2::splat(4.0))
    );
    assert_eq!(
        m.uv_transforms[TextureSlot::Emissive as usize],
        UvTransform::IDENTITY
    );

    doc["materials"][0]["normalTexture"]["extensions"]["KHR_texture_transform"]["rotation"] =
        json!("a lot");
    assert_mentions(
        &error_text(load(&write_doc(&dir, &doc))),
        &[
            "materials[0].normalTexture.extensions.KHR_texture_transform.rotation",
            "number",
        ],
    );
    doc["materials"][0]["normalTexture"]["extensions"]["KHR_texture_transform"]["rotation"] =
        json!(0);
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]
        ["KHR_texture_transform"]["scale"] = json!([1e30, 1]);
    assert_mentions(
        &error_text(load(&write_doc(&dir, &doc))),
        &[
            "materials[0].pbrMetallicRoughness.baseColorTexture.extensions.KHR_texture_transform",
            "finite",
        ],
    );
}

#[test]
fn a_glb_header_shorter_than_itself_is_malformed_not_a_panic() {
    let dir = temp_dir("glb-short-header");
    let json = br#"{"asset":{"version":"2.0"}}"#;
    let mut glb = b"glTF".to_vec();
    glb.extend_from_slice(&2u32.to_le_bytes());
    glb.extend_from_slice(&0u32.to_le_bytes()); // total length below the 12-byte header
    glb.extend_from_slice(&(json.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"JSON");
    glb.extend_from_slice(json);
    let path = dir.join("short.glb");
    std::fs::write(&path, &glb).unwrap();
    let msg = error_text(load(&path));
    assert_mentions(&msg, &["short.glb", "GLB header", "length 0"]);
}
