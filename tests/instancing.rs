//! True instancing on the device: a glTF written here with one sphere mesh placed by several
//! nodes (translations, a rotation, a non-uniform scale, mirroring scales) is uploaded once; the
//! GPU's two-level traversal finds the CPU reference's hits; and it renders as the same scene
//! with the mesh duplicated by hand (every node its own mesh, so the loader flattens all) —
//! lit, emissive and alpha-masked. Uploaded triangle bytes grow with unique meshes only. The
//! renderer's trace kernel draws the same pictures with either BVH traversal.

use fovea_renderer::frame::{CameraPose, RenderSettings};
use fovea_renderer::gpu_scene::GpuScene;
use fovea_renderer::layouts::RayGpu;
use fovea_renderer::passes::raycast::RayCaster;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::Cartesian;
use fovea_renderer::traversal::{Traversal, TraversalChoice};
use fovea_renderer::vk::{Context, ContextOptions};
use fovea_scene::bvh::instanced::{SceneBvh, SceneBvh8};
use fovea_scene::bvh::BvhBuilder;
use fovea_scene::intersect::Ray;
use fovea_scene::Scene;
use fovea_tests::{artifacts_dir, assert_clean, assert_pictures, gpu, rmse, Picture};
use glam::{Quat, UVec2, Vec3};
use serde_json::{json, Value};
use std::sync::Arc;

const SIZE: UVec2 = UVec2::new(64, 72);

/// How the sphere looks: lit by a point light, emitting (the only light), or alpha-masked away.
#[derive(Clone, Copy, PartialEq)]
enum Look {
    Lit,
    Emissive,
    Masked,
}

/// Translations, a rotation, a non-uniform scale and two mirroring transforms; `extra` more
/// translated copies in a row behind them (the memory test's growing placements).
fn placements(extra: usize) -> Vec<Value> {
    let q = Quat::from_axis_angle(Vec3::new(1.0, 2.0, 0.5).normalize(), 0.7);
    let mut p = vec![
        json!({"translation": [-1.6, 0.0, 0.0]}),
        json!({"translation": [0.0, 0.1, -0.4], "rotation": q.to_array()}),
        json!({"translation": [1.5, -0.2, 0.2], "scale": [0.6, 1.3, 0.8]}),
        json!({"translation": [-0.6, 1.2, 0.5], "scale": [-0.7, 0.7, 0.7]}),
        json!({"matrix": [0.5, 0.0, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, -0.5, 0.0, 0.8, 1.1, 0.6, 1.0]}),
    ];
    p.extend((0..extra).map(
        |i| json!({"translation": [-2.0 + 0.5 * i as f32, 0.0, -3.0], "scale": [0.2, 0.2, 0.2]}),
    ));
    p
}

/// A UV sphere (radius 0.6, `rings` × 2·`rings` quads, analytic normals) over a floor quad, a
/// camera and (unless emissive) a point light. With `by_hand` every sphere node has its own mesh
/// (the same accessors): nothing repeats. The floor comes first, so placed ids agree.
fn scene_doc(look: Look, transforms: &[Value], by_hand: bool, rings: u32) -> Value {
    let segments = 2 * rings;
    let (mut pos, mut nrm) = (Vec::new(), Vec::new());
    for r in 0..=rings {
        for s in 0..=segments {
            let (theta, phi) = (
                std::f32::consts::PI * r as f32 / rings as f32,
                std::f32::consts::TAU * s as f32 / segments as f32,
            );
            let n = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            pos.extend((n * 0.6).to_array());
            nrm.extend(n.to_array());
        }
    }
    let floor_first = (pos.len() / 3) as u32;
    pos.extend([
        -4.0, -0.7, -4.0, 4.0, -0.7, -4.0, 4.0, -0.7, 4.0, -4.0, -0.7, 4.0,
    ]);
    nrm.extend([0.0, 1.0, 0.0].repeat(4));
    let ring = segments + 1;
    let mut sphere: Vec<u32> = Vec::new();
    for r in 0..rings {
        for s in 0..segments {
            let (a, b, c, d) = (
                r * ring + s,
                (r + 1) * ring + s,
                (r + 1) * ring + s + 1,
                r * ring + s + 1,
            );
            sphere.extend([a, c, b, a, d, c]);
        }
    }
    let f = floor_first;
    let floor = [f, f + 2, f + 1, f, f + 3, f + 2];
    let mut bytes: Vec<u8> = pos
        .iter()
        .chain(&nrm)
        .flat_map(|x| x.to_le_bytes())
        .collect();
    let index_offset = bytes.len();
    bytes.extend(sphere.iter().chain(&floor).flat_map(|i| i.to_le_bytes()));
    let count = pos.len() / 3;
    let sphere_material = match look {
        Look::Lit => {
            json!({"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.3, 0.2, 1.0], "metallicFactor": 0.0}})
        }
        Look::Emissive => {
            json!({"pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.1, 0.1, 1.0], "metallicFactor": 0.0}, "emissiveFactor": [1.0, 0.8, 0.5]})
        }
        Look::Masked => {
            json!({"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.3, 0.2, 0.2], "metallicFactor": 0.0}, "alphaMode": "MASK", "alphaCutoff": 0.5})
        }
    };
    let prim = |indices: usize, material: usize| json!([{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": indices, "material": material}]);
    let spheres = if by_hand { transforms.len() } else { 1 };
    let mut meshes = vec![json!({"name": "floor", "primitives": prim(3, 0)})];
    meshes.extend((0..spheres).map(|_| json!({"name": "sphere", "primitives": prim(2, 1)})));
    let mut nodes = vec![json!({"mesh": 0})];
    for (i, t) in transforms.iter().enumerate() {
        let mut node = t.clone();
        node["mesh"] = json!(if by_hand { 1 + i } else { 1 });
        nodes.push(node);
    }
    nodes.push(json!({"camera": 0, "translation": [0.0, 1.5, 5.5], "rotation": Quat::from_rotation_x(-0.25).to_array()}));
    let mut doc = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": bytes.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&bytes))}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": count * 12},
            {"buffer": 0, "byteOffset": count * 12, "byteLength": count * 12},
            {"buffer": 0, "byteOffset": index_offset, "byteLength": sphere.len() * 4},
            {"buffer": 0, "byteOffset": index_offset + sphere.len() * 4, "byteLength": 24}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": count, "type": "VEC3", "min": [-4, -0.7, -4], "max": [4, 0.6, 4]},
            {"bufferView": 1, "componentType": 5126, "count": count, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5125, "count": sphere.len(), "type": "SCALAR"},
            {"bufferView": 3, "componentType": 5125, "count": 6, "type": "SCALAR"}
        ],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.7, 0.7, 1.0], "metallicFactor": 0.0}}, sphere_material],
        "meshes": meshes,
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "aspectRatio": 0.889, "znear": 0.01}}],
        "nodes": nodes,
        "scenes": [{"nodes": (0..transforms.len() + 2).collect::<Vec<_>>()}],
        "scene": 0
    });
    if look != Look::Emissive {
        doc["extensionsUsed"] = json!(["KHR_lights_punctual"]);
        doc["extensions"] =
            json!({"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 40.0}]}});
        let light = doc["nodes"].as_array().unwrap().len();
        doc["nodes"].as_array_mut().unwrap().push(json!({"translation": [1.0, 3.5, 2.0], "extensions": {"KHR_lights_punctual": {"light": 0}}}));
        doc["scenes"][0]["nodes"]
            .as_array_mut()
            .unwrap()
            .push(json!(light));
    }
    doc
}

fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            out.push(if k <= c.len() {
                A[(n >> (18 - 6 * k) & 63) as usize] as char
            } else {
                '='
            });
        }
    }
    out
}

fn load(name: &str, doc: &Value) -> Scene {
    let path = artifacts_dir().join(format!("instancing_{name}.gltf"));
    std::fs::write(&path, serde_json::to_vec(doc).unwrap()).unwrap();
    // Instance whatever repeats (by default scenes this small are flattened: faster on lavapipe).
    let limits = fovea_scene::LoadLimits {
        instance_above: 1,
        ..Default::default()
    };
    Scene::load_with_limits(&path, &limits).unwrap_or_else(|e| panic!("{e}"))
}

/// The instanced scene and its hand-made duplicate.
fn pair(look: Look) -> (Scene, Scene) {
    let name = match look {
        Look::Lit => "lit",
        Look::Emissive => "emissive",
        Look::Masked => "masked",
    };
    let instanced = load(name, &scene_doc(look, &placements(0), false, 8));
    let by_hand = load(
        &format!("{name}_by_hand"),
        &scene_doc(look, &placements(0), true, 8),
    );
    assert_eq!(instanced.instancing.instances.len(), 5);
    assert!(by_hand.instancing.instances.is_empty());
    (instanced, by_hand)
}

fn reference(scene: &Scene, spp: u32, seed: u32) -> Vec<[f32; 4]> {
    reference_with(scene, spp, seed, gpu())
}

/// [`reference`] on `ctx`, whose traversal the trace kernel runs.
fn reference_with(scene: &Scene, spp: u32, seed: u32, ctx: Arc<Context>) -> Vec<[f32; 4]> {
    let camera = CameraPose::from_scene_camera(scene.default_camera().unwrap(), SIZE.x, SIZE.y);
    let settings = RenderSettings {
        seed,
        ..RenderSettings::default()
    };
    let mut renderer =
        Renderer::new(&ctx, scene, Box::new(Cartesian::new(SIZE)), settings).unwrap();
    let image = renderer.render_reference(&camera, spp, 3, |_| {}).unwrap();
    drop(renderer);
    assert_clean(&ctx);
    image
}

/// The instanced render equals the hand-made one up to float rounding: far closer than two seeds
/// of the hand-made one are to each other, and nine pixels in ten equal to 1e-3 (a path that
/// grazes an edge may flip on the last bit of a transformed position and diverge).
fn assert_renders_alike(look: Look) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let (instanced, by_hand) = pair(look);
    let (a, b) = (reference(&instanced, 8, 1), reference(&by_hand, 8, 1));
    let noise = rmse(&b, &reference(&by_hand, 8, 2));
    let apart = rmse(&a, &b);
    let close = a
        .iter()
        .zip(&b)
        .filter(|(p, q)| (0..3).all(|c| (p[c] - q[c]).abs() <= 1e-3 * q[c].abs().max(1.0)))
        .count();
    println!("look {}: rmse instanced vs by hand {apart:.3e}, seed noise {noise:.3e}, {close}/{} pixels equal to 1e-3", look as u8, a.len());
    let (instanced, by_hand) = (
        Picture::hdr(SIZE.x, SIZE.y, &a),
        Picture::hdr(SIZE.x, SIZE.y, &b),
    );
    let label = format!("look {} instanced against by hand", look as u8);
    assert_pictures(
        apart < noise / 20.0,
        &label,
        &instanced,
        &by_hand,
        format_args!("instanced vs by hand {apart}, two seeds {noise}"),
    );
    assert_pictures(
        close * 10 >= a.len() * 9,
        &label,
        &instanced,
        &by_hand,
        format_args!("{close} of {} pixels agree", a.len()),
    );
    (a, b)
}

#[test]
fn one_mesh_placed_five_times_is_uploaded_once_and_traced_like_the_cpu_reference() {
    let (scene, by_hand) = pair(Look::Lit);
    assert_eq!(
        (
            scene.triangles.len(),
            scene.instancing.meshes.len(),
            scene.instancing.meshes[0].triangles.len()
        ),
        (2, 1, 256)
    );
    assert_eq!(
        (
            scene.unique_triangle_count(),
            scene.placed_triangle_count(),
            by_hand.triangles.len()
        ),
        (258, 1282, 1282)
    );
    // Both primitives read the whole 157-vertex accessor: the floor's copy, the sphere's once here
    // and once per node by hand.
    assert_eq!(
        (
            scene.vertices.len(),
            scene.instancing.meshes[0].vertices.len(),
            by_hand.vertices.len()
        ),
        (157, 157, 6 * 157)
    );
    let ctx = gpu();
    let cpu = SceneBvh::build(&scene, BvhBuilder::DEFAULT);
    let positions = scene.flat_positions();
    let world = fovea_scene::bvh::Bvh::build(&positions);
    let cpu8 = SceneBvh8::with_world(&scene, positions.clone(), &world, BvhBuilder::DEFAULT);
    let flat = fovea_scene::bvh::wide::Bvh4::from_binary(&fovea_scene::bvh::Bvh::build(
        &by_hand.triangle_positions(),
    ));
    let mut state = 0x1234_5678u32;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state as f32 / u32::MAX as f32
    };
    let mut rays = Vec::new();
    for _ in 0..6000 {
        let origin = Vec3::new(next() * 8.0 - 4.0, next() * 3.0 - 0.5, next() * 4.0 + 1.5);
        let target = Vec3::new(next() * 4.4 - 2.2, next() * 2.2 - 0.8, next() * 2.0 - 1.0);
        rays.push(Ray {
            origin,
            dir: (target - origin) * (0.5 + next()),
        });
    }
    let gpu_rays: Vec<RayGpu> = rays
        .iter()
        .map(|r| RayGpu {
            origin_tmin: r.origin.extend(0.0),
            direction_tmax: r.dir.extend(1e30),
        })
        .collect();
    let mut caster = RayCaster::new(&ctx).unwrap();
    for (traversal, any_hit) in Traversal::ALL
        .into_iter()
        .flat_map(|t| [(t, false), (t, true)])
    {
        let gpu_scene = GpuScene::upload_for(&ctx, &scene, &positions, &world, traversal).unwrap();
        let (hits, _) = caster.trace(&gpu_scene, &gpu_rays, any_hit).unwrap();
        let (mut instanced, mut differ) = (0, 0);
        for (ray, hit) in rays.iter().zip(&hits) {
            let want = cpu.intersect(ray, 1e30, any_hit);
            // The compressed levels (the GPU traversal's twin) find the same hits.
            let want8 = cpu8.intersect(ray, 1e30, any_hit, &mut Default::default());
            assert_eq!(want8.is_some(), want.is_some(), "{ray:?}");
            if !any_hit {
                assert_eq!(want8, want, "{ray:?}");
            }
            assert_eq!(
                hit.t_u_v.x >= 0.0,
                want.is_some(),
                "any_hit {any_hit}, {ray:?}: {hit:?} vs {want:?}"
            );
            // The by-hand flat scene: same hits up to the rounding of object-space tests.
            let flat_hit = flat.intersect(&by_hand.triangle_positions(), ray, 1e30, any_hit);
            assert_eq!(flat_hit.is_some(), want.is_some(), "{ray:?}");
            let (Some(w), false) = (want, any_hit) else {
                continue;
            };
            assert_eq!(hit.triangle.x, w.triangle, "{ray:?}");
            // Same algorithm, same arithmetic: lavapipe's floats should agree to the last bit.
            differ += usize::from(hit.t_u_v.x != w.t || hit.t_u_v.y != w.u || hit.t_u_v.z != w.v);
            assert!(
                (hit.t_u_v.x - w.t).abs() <= 1e-6 * w.t,
                "{ray:?}: {hit:?} vs {w:?}"
            );
            let f = flat_hit.unwrap();
            assert!(
                (f.t - w.t).abs() <= 1e-5 * w.t,
                "{ray:?}: flat {f:?} vs {w:?}"
            );
            instanced += usize::from(w.triangle >= 2);
        }
        println!(
            "{} traversal, any_hit {any_hit}: {instanced} instanced hits, {differ} differ in the last bits",
            traversal.name()
        );
        assert!(
            any_hit || instanced > 1500,
            "the rays must exercise the instances: {instanced}"
        );
    }
    drop(caster);
    assert_clean(&ctx);
}

#[test]
fn instanced_spheres_render_as_their_hand_made_copies() {
    assert_renders_alike(Look::Lit);
}

#[test]
fn an_instanced_emitter_lights_the_scene_as_its_copies_do() {
    let (a, _) = assert_renders_alike(Look::Emissive);
    // Next-event estimation finds every instance: the floor is lit (the only light is the spheres).
    let floor_row =
        &a[(SIZE.y as usize - 3) * SIZE.x as usize..(SIZE.y as usize - 2) * SIZE.x as usize];
    assert!(
        floor_row.iter().map(|p| p[0]).sum::<f32>() > 0.01 * SIZE.x as f32,
        "the floor in front of the spheres is dark"
    );
}

#[test]
fn an_instanced_alpha_masked_mesh_cuts_out_as_its_copies_do() {
    let (a, _) = assert_renders_alike(Look::Masked);
    // Cut out entirely (alpha 0.2 < 0.5): the scene without the spheres.
    let mut none = load(
        "masked_none",
        &scene_doc(Look::Masked, &placements(0), false, 8),
    );
    none.instancing = Default::default();
    let without = reference(&none, 8, 1);
    let lit = reference(&pair(Look::Lit).0, 8, 1);
    assert!(
        rmse(&a, &without) < rmse(&a, &lit) / 10.0,
        "masked spheres: {} from none, {} from opaque",
        rmse(&a, &without),
        rmse(&a, &lit)
    );
}

#[test]
fn uploaded_triangle_bytes_grow_with_unique_meshes_not_placements() {
    let ctx = gpu();
    let upload = |extra: usize, by_hand: bool| {
        let scene = load(
            &format!("memory_{extra}_{by_hand}"),
            &scene_doc(Look::Lit, &placements(extra), by_hand, 8),
        );
        let g = GpuScene::upload(&ctx, &scene).unwrap();
        (
            g.triangles.size,
            g.vertices.size,
            g.bvh_triangles.size,
            g.instances.size,
            g.instancing_stats.bytes_saved,
        )
    };
    let (few, many) = (upload(0, false), upload(40, false));
    assert_eq!(
        (few.0, few.1),
        (many.0, many.1),
        "triangles and vertices do not grow with placements"
    );
    assert_eq!(
        many.2 - few.2,
        40 * 16,
        "leaf triangles do not grow either: only the top level's 16-byte entry per instance"
    );
    assert!(
        many.3 > few.3,
        "per-instance data grows: {} vs {} bytes",
        many.3,
        few.3
    );
    let flat = upload(40, true);
    assert!(
        flat.0 >= 40 * many.0 / 2,
        "flattening 45 copies: {} vs {} triangle bytes",
        flat.0,
        many.0
    );
    assert!(
        many.4 > few.4 && many.4 > 0,
        "bytes saved {} (45 placements) vs {} (5)",
        many.4,
        few.4
    );
    assert_clean(&ctx);
}

/// The trace kernel compiled for each traversal (the context's, `--traversal`) draws the same
/// pictures of the instanced scenes (two-level walk) and their flattened copies (one level), lit
/// and alpha-masked: both traversals find the same hits, so every pixel agrees to float rounding
/// in nine of ten and the whole far closer than two seeds do.
#[test]
fn both_traversals_render_the_same_pictures() {
    let with = |traversal| {
        let ctx = Context::new(&ContextOptions {
            validation: true,
            traversal: TraversalChoice::Forced(traversal),
            ..Default::default()
        })
        .expect("Vulkan device with validation layers");
        assert_eq!(ctx.traversal, traversal);
        ctx
    };
    for look in [Look::Lit, Look::Masked] {
        let (instanced, by_hand) = pair(look);
        for (name, scene) in [("instanced", &instanced), ("flattened", &by_hand)] {
            let a = reference_with(scene, 8, 1, with(Traversal::CpuDriver));
            let b = reference_with(scene, 8, 1, with(Traversal::Gpu));
            let noise = rmse(&a, &reference(scene, 8, 2));
            let apart = rmse(&a, &b);
            let close = a
                .iter()
                .zip(&b)
                .filter(|(p, q)| (0..3).all(|c| (p[c] - q[c]).abs() <= 1e-3 * q[c].abs().max(1.0)))
                .count();
            println!(
                "look {} {name}: rmse cpu-driver vs gpu traversal {apart:.3e}, seed noise {noise:.3e}, {close}/{} pixels equal to 1e-3",
                look as u8,
                a.len()
            );
            let pictures = (
                Picture::hdr(SIZE.x, SIZE.y, &a),
                Picture::hdr(SIZE.x, SIZE.y, &b),
            );
            let label = format!(
                "look {} {name}, cpu-driver against gpu traversal",
                look as u8
            );
            assert_pictures(
                apart < noise / 20.0 && close * 10 >= a.len() * 9,
                &label,
                &pictures.0,
                &pictures.1,
                format_args!(
                    "{apart} apart, two seeds {noise}; {close} of {} pixels agree",
                    a.len()
                ),
            );
        }
    }
}
