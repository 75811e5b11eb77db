use super::*;
use fovea_scene::bvh::BvhBuilder;
use fovea_scene::{build_light_table, Bvh, LightKind, PunctualLight, Scene};
use std::path::PathBuf;

fn scenes_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

fn temp_path(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fovea-scenegen-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("create temp dir");
    let path = dir.join(name);
    let _ = std::fs::remove_file(&path);
    path
}

fn generate_and_load(kind: &SceneKind) -> (SceneStats, Scene) {
    let path = temp_path(kind.file_name());
    let stats = write_scene(kind, &path, false).expect("write scene");
    // The checks look at world-space triangles: repeated meshes (the Cornell box's blocks, the
    // stress scene's posts) load instanced, so expand them in placed-id order.
    let scene = Scene::load(&path)
        .unwrap_or_else(|e| panic!("{e}"))
        .flattened();
    assert_eq!(
        scene.triangles.len(),
        stats.triangles,
        "stats count the placed triangles"
    );
    assert!(scene
        .triangles
        .iter()
        .all(|t| (t.material as usize) < scene.materials.len()));
    (stats, scene)
}

#[test]
fn cornell_box_loads_with_its_light_camera_and_lambertian_materials() {
    let (stats, scene) = generate_and_load(&SceneKind::CornellBox);
    assert_eq!(
        stats.triangles, 36,
        "5 walls, 2 light triangles, 2 blocks of 12"
    );
    assert_eq!(
        scene.materials.len(),
        4,
        "white, red, green, light; no default material needed"
    );
    for m in &scene.materials {
        assert_eq!(
            (m.metallic, m.roughness, m.specular_factor),
            (0.0, 1.0, 0.0),
            "{m:?} must be exactly Lambertian"
        );
    }
    let camera = scene.default_camera().expect("a camera");
    assert!((camera.yfov.to_degrees() - 70.0).abs() < 1e-3);
    // 0.3 m before the 1 m opening: the opening spans ±59°, wider than a headset's view.
    let eye = camera.world_from_view.w_axis.truncate();
    assert!(
        (eye - glam::Vec3::new(0.0, 0.5, 0.8)).length() < 1e-5,
        "{eye}"
    );
    assert!((0.5f32 / (eye.z - 0.5)).atan().to_degrees() > 55.0);
    let b = scene.bounds();
    assert!(
        (b.min - glam::Vec3::new(-0.5, 0.0, -0.5)).length() < 1e-5
            && (b.max - glam::Vec3::new(0.5, 1.0, 0.5)).length() < 1e-5
    );
    assert!(
        !b.contains_point(camera.world_from_view.w_axis.truncate()),
        "camera outside the box, looking in"
    );
    let lights = build_light_table(&scene);
    assert_eq!(lights.entries.len(), 2);
    assert!(lights
        .entries
        .iter()
        .all(|e| e.kind == LightKind::EmissiveTriangle));
    let emitter =
        &scene.materials[scene.triangles[lights.entries[0].index as usize].material as usize];
    assert!((emitter.emissive - glam::Vec3::new(17.0, 12.0, 4.0)).length() < 1e-4);
    // The light faces down, into the box.
    let tri = scene.triangles[lights.entries[0].index as usize];
    let p = tri.indices.map(|i| scene.vertices[i as usize].position);
    assert!((p[1] - p[0]).cross(p[2] - p[0]).y < 0.0);
}

#[test]
fn stress_scene_has_what_foveation_is_tested_against() {
    let (stats, scene) = generate_and_load(&SceneKind::Stress);
    assert!(stats.triangles < 50_000, "{} triangles", stats.triangles);
    assert!(stats.bytes < 2 << 20, "{} bytes", stats.bytes);
    assert_eq!(scene.textures.len(), 2);
    assert!(scene
        .textures
        .iter()
        .any(|t| (t.width, t.height) == (512, 512)));
    let mats = &scene.materials;
    assert!(
        mats.iter().any(|m| m.metallic == 1.0 && m.roughness == 0.0),
        "a mirror"
    );
    assert!(
        mats.iter()
            .any(|m| m.metallic == 1.0 && (0.2..=0.4).contains(&m.roughness)),
        "glossy metal"
    );
    assert!(
        mats.iter()
            .any(|m| m.metallic == 0.0 && (0.2..=0.4).contains(&m.roughness)),
        "glossy dielectric"
    );
    assert!(matches!(
        scene.punctual_lights[..],
        [PunctualLight::Spot { .. }]
    ));
    let lights = build_light_table(&scene);
    assert!(lights
        .entries
        .iter()
        .any(|e| e.kind == LightKind::EmissiveTriangle));
    assert_eq!(scene.cameras.len(), 1);
    // Thin geometry: the fence wires are 2 mm across.
    let wire = scene
        .mesh_names
        .iter()
        .position(|n| n == "fence wire")
        .expect("fence wire mesh") as u32;
    let wire_vertices: Vec<_> = scene
        .triangles
        .iter()
        .filter(|t| t.mesh == wire)
        .flat_map(|t| t.indices)
        .collect();
    assert!(!wire_vertices.is_empty());
}

#[test]
fn large_scene_reaches_its_triangle_budget_and_builds_a_bvh() {
    let (stats, scene) = generate_and_load(&SceneKind::Large {
        min_triangles: DEFAULT_LARGE_TRIANGLES,
    });
    assert!(
        stats.triangles >= DEFAULT_LARGE_TRIANGLES
            && stats.triangles < DEFAULT_LARGE_TRIANGLES + 20_000,
        "{}",
        stats.triangles
    );
    assert!(matches!(
        scene.punctual_lights[..],
        [PunctualLight::Directional { .. }]
    ));
    assert!(build_light_table(&scene)
        .entries
        .iter()
        .any(|e| e.kind == LightKind::EmissiveTriangle));
    let bvh = Bvh::build_with(&scene.triangle_positions(), BvhBuilder::BINNED);
    assert_eq!(bvh.tri_order.len(), stats.triangles);
    // The default builder (spatial splits) keeps every triangle and stays within its budget.
    let sbvh = Bvh::build(&scene.triangle_positions());
    assert!(
        sbvh.tri_order.len() >= stats.triangles && sbvh.tri_order.len() <= stats.triangles * 3 / 2
    );
    // Determinism: the same request writes the same bytes.
    assert_eq!(
        scene_json(&SceneKind::Large {
            min_triangles: 300_000
        }),
        scene_json(&SceneKind::Large {
            min_triangles: 300_000
        })
    );
}

#[test]
fn write_scene_refuses_to_overwrite_unless_asked() {
    let path = temp_path("exists.gltf");
    std::fs::write(&path, "keep me").unwrap();
    let err = write_scene(&SceneKind::CornellBox, &path, false).expect_err("must refuse");
    assert!(err.to_string().contains("already exists"));
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "keep me");
    write_scene(&SceneKind::CornellBox, &path, true).expect("overwrite when asked");
}

/// The stored scenes are exactly what the generators write (so they can always be regenerated).
#[test]
fn stored_scenes_match_their_generators() {
    for kind in [SceneKind::CornellBox, SceneKind::Stress] {
        let stored = scenes_dir().join(kind.file_name());
        let text = std::fs::read_to_string(&stored).unwrap_or_else(|e| {
            panic!("{}: {e}; regenerate (see the module doc)", stored.display())
        });
        let expected = serde_json::to_string(&scene_json(&kind).0).unwrap();
        assert!(
            text == expected,
            "{} differs from its generator; regenerate (see the module doc)",
            stored.display()
        );
        assert!(text.len() < 2 << 20);
    }
}

/// Writes `scenes/cornell-box.gltf` and `scenes/stress.gltf` (run on purpose; see the module doc).
#[test]
#[ignore]
fn regenerate_owned_scenes() {
    for kind in [SceneKind::CornellBox, SceneKind::Stress] {
        let path = scenes_dir().join(kind.file_name());
        let stats = write_scene(&kind, &path, true).expect("write");
        println!("{}: {stats:?}", path.display());
    }
}

/// BVH build rate and memory on the large scene; run with `--release -- --ignored --nocapture`.
#[test]
#[ignore]
fn large_scene_bvh_build_rate() {
    let (stats, scene) = generate_and_load(&SceneKind::Large {
        min_triangles: DEFAULT_LARGE_TRIANGLES,
    });
    let tris = scene.triangle_positions();
    let mut best = f64::INFINITY;
    let mut bvh = Bvh::default();
    let mut best_cpu = f64::INFINITY;
    for _ in 0..3 {
        let (start, start_cpu) = (std::time::Instant::now(), thread_cpu_seconds());
        bvh = Bvh::build(&tris);
        best = best.min(start.elapsed().as_secs_f64());
        best_cpu = best_cpu.min(thread_cpu_seconds() - start_cpu);
    }
    println!(
        "large scene: {} triangles ({} bytes of glTF); BVH build {:.3} s wall = {:.2} M triangles/s, {:.3} s CPU = {:.2} M triangles/s (best of 3); {} nodes, depth {}, {:.1} MiB GPU",
        stats.triangles,
        stats.bytes,
        best,
        tris.len() as f64 / best / 1e6,
        best_cpu,
        tris.len() as f64 / best_cpu / 1e6,
        bvh.nodes.len(),
        bvh.depth(),
        bvh.memory_bytes() as f64 / (1u64 << 20) as f64
    );
}

/// This thread's CPU time (Linux schedstat), so the rate is meaningful on a shared, busy machine;
/// NaN elsewhere.
fn thread_cpu_seconds() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(f64::NAN, |ns| ns * 1e-9)
}
