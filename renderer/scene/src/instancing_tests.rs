//! Instancing: the loader keeps one copy of a repeated mesh, and the two-level traversal finds the
//! hits of the same scene flattened (the reference), placed ids included.

use crate::bvh::instanced::SceneBvh;
use crate::bvh::BvhBuilder;
use crate::intersect::{brute_force, Ray};
use crate::test_util::{base64, temp_dir, TestRng};
use crate::Scene;
use glam::{Quat, Vec3};
use serde_json::{json, Value};

/// A unit cube (12 triangles, no normals: flat ones are generated) and a floor quad; the cube is
/// placed by one node per transform. With `duplicate`, every cube node gets its own mesh (the
/// same accessors), so nothing repeats and the loader flattens all: the hand-made reference.
fn cubes_doc(transforms: &[Value], duplicate: bool) -> Value {
    let mut p: Vec<f32> = (0..8)
        .flat_map(|k| [(k & 1) as f32, ((k >> 1) & 1) as f32, ((k >> 2) & 1) as f32])
        .collect();
    p.extend([
        -4.0, -1.0, -4.0, 4.0, -1.0, -4.0, 4.0, -1.0, 4.0, -4.0, -1.0, 4.0,
    ]);
    let cube: [u16; 36] = [
        0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6,
        1, 3, 5, 3, 7, 5,
    ];
    let floor: [u16; 6] = [8, 10, 9, 8, 11, 10];
    let mut bytes: Vec<u8> = p.iter().flat_map(|x| x.to_le_bytes()).collect();
    bytes.extend(cube.iter().chain(&floor).flat_map(|i| i.to_le_bytes()));
    let prim = |indices: usize| json!([{"attributes": {"POSITION": 0}, "indices": indices}]);
    let cubes = if duplicate { transforms.len() } else { 1 };
    let mut meshes = vec![json!({"name": "floor", "primitives": prim(2)})];
    meshes.extend((0..cubes).map(|_| json!({"name": "cube", "primitives": prim(1)})));
    // The floor first: its triangles are placed ids 0 and 1 in both forms.
    let mut nodes = vec![json!({"mesh": 0})];
    for (i, t) in transforms.iter().enumerate() {
        let mut node = t.clone();
        node["mesh"] = json!(if duplicate { 1 + i } else { 1 });
        nodes.push(node);
    }
    json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": bytes.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&bytes))}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 144},
            {"buffer": 0, "byteOffset": 144, "byteLength": 72},
            {"buffer": 0, "byteOffset": 216, "byteLength": 12}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 12, "type": "VEC3", "min": [-4, -1, -4], "max": [4, 1, 4]},
            {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"},
            {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}
        ],
        "meshes": meshes,
        "nodes": nodes,
        "scenes": [{"nodes": (0..=transforms.len()).collect::<Vec<_>>()}],
        "scene": 0
    })
}

/// Translations, a rotation, a non-uniform scale and a mirroring scale.
fn placements() -> Vec<Value> {
    let q = Quat::from_axis_angle(Vec3::new(1.0, 2.0, 0.5).normalize(), 0.7);
    vec![
        json!({"translation": [-3.0, 0.0, -2.0]}),
        json!({"translation": [1.5, 0.2, -2.5], "rotation": q.to_array()}),
        json!({"translation": [-1.0, -0.5, 1.0], "scale": [2.0, 0.5, 1.25]}),
        json!({"translation": [2.0, 0.0, 1.5], "scale": [-1.0, 1.0, 1.0]}),
        json!({"matrix": [0.5, 0.0, 0.0, 0.0, 0.0, 1.5, 0.0, 0.0, 0.0, 0.0, -0.75, 0.0, 0.0, 1.0, 3.0, 1.0]}),
    ]
}

fn load(test: &str, doc: &Value) -> Scene {
    let path = temp_dir(test).join("scene.gltf");
    std::fs::write(&path, serde_json::to_vec(doc).unwrap()).unwrap();
    // Instance whatever repeats (by default scenes this small are flattened).
    let limits = crate::LoadLimits {
        instance_above: 1,
        ..Default::default()
    };
    Scene::load_with_limits(&path, &limits).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_mesh_placed_by_several_nodes_is_kept_once_and_flattens_to_the_hand_made_copies() {
    let instanced = load("instancing_once", &cubes_doc(&placements(), false));
    let by_hand = load("instancing_by_hand", &cubes_doc(&placements(), true));
    assert_eq!(
        instanced.triangles.len(),
        2,
        "the floor (placed once) stays flattened"
    );
    assert_eq!(instanced.instancing.meshes.len(), 1);
    assert_eq!(instanced.instancing.meshes[0].triangles.len(), 12);
    assert_eq!(
        instanced.instancing.meshes[0].vertices.len(),
        36,
        "flat normals: one vertex per corner, once"
    );
    assert_eq!(instanced.instancing.instances.len(), 5);
    assert_eq!(instanced.unique_triangle_count(), 14);
    assert_eq!(instanced.placed_triangle_count(), 62);
    assert_eq!(
        by_hand.triangles.len(),
        62,
        "nothing repeats: all flattened"
    );
    assert!(by_hand.instancing.instances.is_empty());
    let ids: Vec<u32> = instanced
        .instancing
        .instances
        .iter()
        .map(|i| i.first_id)
        .collect();
    assert_eq!(ids, [2, 14, 26, 38, 50]);
    assert!(
        instanced.instancing.instances[3].mirrors() && !instanced.instancing.instances[1].mirrors()
    );
    // The flattened form is the hand-made one: same corners (winding included), normals, ids.
    let flat = instanced.flattened();
    assert_eq!(instanced.triangle_positions(), by_hand.triangle_positions());
    assert_eq!(flat.triangle_positions(), by_hand.triangle_positions());
    for (a, b) in flat.triangles.iter().zip(&by_hand.triangles) {
        for (i, j) in a.indices.iter().zip(&b.indices) {
            let (va, vb) = (flat.vertices[*i as usize], by_hand.vertices[*j as usize]);
            assert_eq!(va.position, vb.position);
            assert!(
                (va.normal - vb.normal).length() < 1e-6,
                "{:?} vs {:?}",
                va.normal,
                vb.normal
            );
        }
    }
    assert_eq!(instanced.bounds(), by_hand.bounds());
}

#[test]
fn small_scenes_are_flattened_by_default() {
    let path = temp_dir("instancing_default").join("scene.gltf");
    std::fs::write(
        &path,
        serde_json::to_vec(&cubes_doc(&placements(), false)).unwrap(),
    )
    .unwrap();
    let scene = Scene::load(&path).unwrap();
    assert!(
        scene.instancing.instances.is_empty() && scene.triangles.len() == 62,
        "62 placed triangles are below the threshold"
    );
}

#[test]
fn the_two_level_traversal_finds_the_flat_references_hits() {
    let scene = load("instancing_traverse", &cubes_doc(&placements(), false));
    let flat = scene.triangle_positions();
    let mut rng = TestRng::new(7);
    for builder in [BvhBuilder::SBVH, BvhBuilder::BINNED] {
        let bvh = SceneBvh::build(&scene, builder);
        let (mut hits, mut instanced_hits) = (0, 0);
        for _ in 0..4000 {
            let origin = Vec3::new(
                rng.range(-6.0, 6.0),
                rng.range(-0.5, 4.0),
                rng.range(-6.0, 6.0),
            );
            let target = Vec3::new(
                rng.range(-4.0, 4.0),
                rng.range(-1.0, 2.0),
                rng.range(-4.0, 4.0),
            );
            let ray = Ray {
                origin,
                dir: (target - origin) * rng.range(0.2, 3.0),
            };
            let got = bvh.intersect(&ray, 1e30, false);
            let want = brute_force(&flat, &ray, 1e30, false);
            assert_eq!(
                got.is_some(),
                want.is_some(),
                "{ray:?}: {got:?} vs {want:?}"
            );
            if let (Some(g), Some(w)) = (got, want) {
                // Object-space tests round differently: t agrees closely, the id exactly unless
                // two triangles are that close along the ray.
                assert!(
                    (g.t - w.t).abs() <= 1e-5 * w.t.max(1.0),
                    "{ray:?}: {g:?} vs {w:?}"
                );
                if g.triangle != w.triangle {
                    let other = brute_force(&[flat[g.triangle as usize]], &ray, 1e30, false)
                        .expect("the id names a hit triangle");
                    assert!(
                        (other.t - w.t).abs() <= 1e-5 * w.t.max(1.0),
                        "{ray:?}: {g:?} vs {w:?}"
                    );
                }
                hits += 1;
                instanced_hits += usize::from(w.triangle >= 2);
            }
            let shadow = bvh.intersect(&ray, 1e30, true);
            assert_eq!(shadow.is_some(), want.is_some(), "any-hit {ray:?}");
        }
        assert!(
            hits > 1500 && instanced_hits > 800,
            "the rays must exercise the instances: {hits} hits, {instanced_hits} instanced"
        );
    }
}
