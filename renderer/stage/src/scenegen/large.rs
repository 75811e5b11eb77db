//! The large benchmark scene (Sponza-class size; Sponza itself cannot be had here): a two-storey
//! colonnade around a courtyard — fluted columns, arches, a checkerboard floor — plus instanced
//! spheres, tori and bumpy blobs until at least `min_triangles` triangles. Deterministic (seeded),
//! with an emissive panel and a directional "sun". Instancing keeps the file small: the loader
//! flattens it to world space.

use super::gltf_writer::GltfWriter;
use super::shapes::{blob, cuboid, cylinder, quad, torus, uv_sphere, SplitMix64};
use super::textures::near_checker_png;
use glam::{Quat, Vec2, Vec3};
use serde_json::json;
use std::f32::consts::{FRAC_PI_2, PI};

/// Columns per long side and per storey; the courtyard is 2 × 12 bays along X, 2 × 4 along Z.
const BAYS_X: usize = 12;
const BAYS_Z: usize = 4;
const BAY: f32 = 2.5;

fn pbr(name: &str, rgb: [f32; 3], metallic: f32, roughness: f32) -> serde_json::Value {
    json!({"name": name, "pbrMetallicRoughness": {"baseColorFactor": [rgb[0], rgb[1], rgb[2], 1.0], "metallicFactor": metallic, "roughnessFactor": roughness}})
}

pub fn build(min_triangles: usize) -> GltfWriter {
    let mut w = GltfWriter::default();
    let mut rng = SplitMix64::new(0x5350_4f4e_5a41); // fixed seed
    let checker = w.add_png_texture(
        "floor checker",
        &near_checker_png(512, 4, [60, 50, 40], [200, 185, 160], &mut rng),
    );
    let mut floor_mat = pbr("floor", [1.0, 1.0, 1.0], 0.0, 0.7);
    floor_mat["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": checker});
    let floor_mat = w.add_material(floor_mat);
    let stone = w.add_material(pbr("stone", [0.7, 0.66, 0.6], 0.0, 0.9));
    let brass = w.add_material(pbr("brass", [0.9, 0.7, 0.4], 1.0, 0.3));
    let ceramic = w.add_material(pbr("ceramic", [0.2, 0.35, 0.6], 0.0, 0.25));
    let clay = w.add_material(pbr("clay", [0.6, 0.3, 0.2], 0.0, 0.6));
    let mut lamp = pbr("lamp", [0.8, 0.8, 0.8], 0.0, 1.0);
    lamp["emissiveFactor"] = json!([1.0, 0.95, 0.85]);
    lamp["extensions"] = json!({"KHR_materials_emissive_strength": {"emissiveStrength": 20.0}});
    let lamp = w.add_material(lamp);

    let (half_x, half_z) = (BAYS_X as f32 * BAY / 2.0, BAYS_Z as f32 * BAY / 2.0);
    let floor = quad(
        Vec3::new(-half_x - 4.0, 0.0, half_z + 4.0),
        Vec3::X * (2.0 * half_x + 8.0),
        Vec3::NEG_Z * (2.0 * half_z + 8.0),
        16,
        Vec2::splat(12.0),
    );
    let floor = w.add_mesh("floor", &floor, floor_mat);
    w.add_root_node(json!({"name": "floor", "mesh": floor}));

    // Fluted column shaft (the bulk of the architecture's triangles), base and capital blocks.
    let column = w.add_mesh("column", &cylinder(0.3, 3.6, 48, 20, 16, 0.08), stone);
    let block = w.add_mesh("column block", &cuboid(Vec3::new(0.8, 0.2, 0.8)), stone);
    // A semicircular arch between neighbouring columns (half torus standing in the XY plane).
    let arch = w.add_mesh("arch", &torus(BAY / 2.0, 0.18, 32, 12, PI), stone);
    let slab = w.add_mesh(
        "gallery slab",
        &cuboid(Vec3::new(2.0 * half_x + 2.0, 0.3, 2.0)),
        stone,
    );

    let mut columns = Vec::new();
    for i in 0..=BAYS_X {
        let x = -half_x + i as f32 * BAY;
        columns.push((Vec3::new(x, 0.0, -half_z), 0.0f32));
        columns.push((Vec3::new(x, 0.0, half_z), 0.0));
    }
    for k in 1..BAYS_Z {
        let z = -half_z + k as f32 * BAY;
        columns.push((Vec3::new(-half_x, 0.0, z), FRAC_PI_2));
        columns.push((Vec3::new(half_x, 0.0, z), FRAC_PI_2));
    }
    for storey in 0..2 {
        let y = storey as f32 * 4.6;
        for &(base, _) in &columns {
            let p = base + Vec3::Y * y;
            w.add_root_node(json!({"mesh": column, "translation": (p + Vec3::Y * 0.2).to_array()}));
            w.add_root_node(json!({"mesh": block, "translation": (p + Vec3::Y * 0.1).to_array()}));
            w.add_root_node(json!({"mesh": block, "translation": (p + Vec3::Y * 3.9).to_array()}));
        }
        // Arches span each bay along the long sides, their springing on the capitals.
        for i in 0..BAYS_X {
            let x = -half_x + (i as f32 + 0.5) * BAY;
            for z in [-half_z, half_z] {
                let up = Quat::from_rotation_x(FRAC_PI_2); // torus around Y → arch in the XY plane
                w.add_root_node(json!({"mesh": arch, "translation": [x, y + 4.0, z], "rotation": up.to_array()}));
            }
        }
        for z in [-half_z - 0.6, half_z + 0.6] {
            w.add_root_node(json!({"mesh": slab, "translation": [0.0, y + 4.45 + 1.3, z]}));
        }
    }

    // Instanced props in the courtyard until the triangle budget is met.
    let props = [
        w.add_mesh("prop sphere", &uv_sphere(0.3, 48, 96), brass),
        w.add_mesh("prop torus", &torus(0.3, 0.09, 96, 32, 2.0 * PI), ceramic),
        w.add_mesh("prop blob", &blob(0.35, 64, 128, &mut rng), clay),
    ];
    let mut k = 0usize;
    while w.scene_triangles < min_triangles {
        let p = Vec3::new(
            rng.range(-half_x + 1.0, half_x - 1.0),
            rng.range(0.3, 2.0),
            rng.range(-half_z + 1.0, half_z - 1.0),
        );
        let r = Quat::from_axis_angle(rng.unit_vector(), rng.range(0.0, 2.0 * PI));
        w.add_root_node(json!({"mesh": props[k % props.len()], "translation": p.to_array(), "rotation": r.to_array()}));
        k += 1;
    }

    let panel = w.add_mesh(
        "light panel",
        &quad(
            Vec3::new(-2.0, 9.0, -1.0),
            Vec3::X * 4.0,
            Vec3::Z * 2.0,
            1,
            Vec2::ONE,
        ),
        lamp,
    );
    w.add_root_node(json!({"name": "light panel", "mesh": panel}));
    let sun = Quat::from_rotation_arc(Vec3::NEG_Z, Vec3::new(-0.4, -0.8, -0.45).normalize());
    w.add_light(
        json!({"name": "sun", "type": "directional", "color": [1.0, 0.95, 0.85], "intensity": 3.0}),
        json!({"name": "sun", "rotation": sun.to_array()}),
    );
    // From a corner of the courtyard towards the courtyard's centre (yaw, then pitch: no roll).
    let eye = Vec3::new(half_x - 2.2, 1.7, half_z - 1.2);
    let dir = (Vec3::new(0.0, 1.0, 0.0) - eye).normalize();
    let look = Quat::from_rotation_y((-dir.x).atan2(-dir.z)) * Quat::from_rotation_x(dir.y.asin());
    w.add_camera(
        "camera",
        60f32.to_radians(),
        1280.0 / 1440.0,
        eye.to_array(),
        look.normalize().to_array(),
    );
    w
}
