//! The stress scene: what foveated sampling is tested against. A near-checkerboard floor (squares
//! of 3 ± 1 texels, ~2–4 px at 1280×1440 in the middle distance), a fine-grid wall, a mirror,
//! glossy metal and dielectric spheres, a fence of 4 mm posts and 2 mm wires, one emissive quad
//! and one spot light.

use super::gltf_writer::GltfWriter;
use super::shapes::{cuboid, cylinder, quad, torus, uv_sphere, SplitMix64};
use super::textures::{fine_grid_png, near_checker_png};
use glam::{Quat, Vec2, Vec3};
use serde_json::{json, Value};
use std::f32::consts::{FRAC_PI_2, TAU};

fn pbr(name: &str, rgb: [f32; 3], metallic: f32, roughness: f32) -> Value {
    json!({"name": name, "pbrMetallicRoughness": {"baseColorFactor": [rgb[0], rgb[1], rgb[2], 1.0], "metallicFactor": metallic, "roughnessFactor": roughness}})
}

fn textured(name: &str, texture: usize) -> Value {
    json!({"name": name, "pbrMetallicRoughness": {"baseColorTexture": {"index": texture}, "metallicFactor": 0.0, "roughnessFactor": 0.8}})
}

pub fn build() -> GltfWriter {
    let mut w = GltfWriter::default();
    let mut rng = SplitMix64::new(0x5745_5353); // fixed seed: the stored file is reproducible
    let checker = w.add_png_texture(
        "near-checker",
        &near_checker_png(512, 3, [30, 30, 34], [215, 210, 200], &mut rng),
    );
    let grid = w.add_png_texture(
        "fine-grid",
        &fine_grid_png(256, 4, [180, 170, 150], [40, 40, 60]),
    );

    let floor_mat = w.add_material(textured("checker floor", checker));
    let wall_mat = w.add_material(textured("grid wall", grid));
    let mirror_mat = w.add_material(pbr("mirror", [0.95, 0.95, 0.95], 1.0, 0.0));
    let gold = w.add_material(pbr("glossy gold", [1.0, 0.78, 0.34], 1.0, 0.25));
    let plastic = w.add_material(pbr("glossy red plastic", [0.7, 0.08, 0.06], 0.0, 0.3));
    let mut glaze = pbr("glossy blue glaze", [0.1, 0.2, 0.6], 0.0, 0.4);
    glaze["extensions"] = json!({"KHR_materials_ior": {"ior": 1.6}, "KHR_materials_specular": {"specularFactor": 1.0}});
    let glaze = w.add_material(glaze);
    let steel = w.add_material(pbr("fence steel", [0.55, 0.56, 0.58], 1.0, 0.35));
    let mut lamp = pbr("lamp", [0.8, 0.8, 0.8], 0.0, 1.0);
    lamp["emissiveFactor"] = json!([1.0, 0.9, 0.75]);
    lamp["extensions"] = json!({"KHR_materials_emissive_strength": {"emissiveStrength": 12.0}});
    let lamp = w.add_material(lamp);
    let frame = w.add_material(pbr("dark frame", [0.05, 0.05, 0.05], 0.0, 0.6));

    // Floor 8 × 8 m, texture repeated 4× per side: a texel is ~4 mm, a square ~12 mm.
    let floor = w.add_mesh(
        "floor",
        &quad(
            Vec3::new(-4.0, 0.0, 4.0),
            Vec3::X * 8.0,
            Vec3::NEG_Z * 8.0,
            8,
            Vec2::splat(4.0),
        ),
        floor_mat,
    );
    w.add_root_node(json!({"name": "floor", "mesh": floor}));
    let wall = w.add_mesh(
        "back wall",
        &quad(
            Vec3::new(-4.0, 0.0, -4.0),
            Vec3::X * 8.0,
            Vec3::Y * 3.0,
            4,
            Vec2::new(8.0, 3.0),
        ),
        wall_mat,
    );
    w.add_root_node(json!({"name": "back wall", "mesh": wall}));

    // A 1.2 × 1.8 m mirror on the left, turned towards the centre, in a thin frame.
    let mirror = w.add_mesh(
        "mirror",
        &quad(
            Vec3::new(-0.6, 0.1, 0.0),
            Vec3::X * 1.2,
            Vec3::Y * 1.8,
            1,
            Vec2::ONE,
        ),
        mirror_mat,
    );
    let mirror_frame = w.add_mesh("mirror frame", &cuboid(Vec3::new(1.3, 1.9, 0.03)), frame);
    let turn = Quat::from_rotation_y(40f32.to_radians()).to_array();
    w.add_root_node(json!({"name": "mirror", "mesh": mirror, "translation": [-2.2, 0.0, -1.5], "rotation": turn}));
    w.add_root_node(json!({"name": "mirror frame", "mesh": mirror_frame, "translation": [-2.2 - 0.016 * 0.643, 1.0, -1.5 - 0.016 * 0.766], "rotation": turn}));

    // Glossy objects: two spheres and a torus (metal and dielectric, roughness 0.25–0.4).
    let sphere = uv_sphere(0.35, 48, 96);
    let gold_sphere = w.add_mesh("gold sphere", &sphere, gold);
    let red_sphere = w.add_mesh("red sphere", &sphere, plastic);
    w.add_root_node(
        json!({"name": "gold sphere", "mesh": gold_sphere, "translation": [-0.5, 0.35, -0.8]}),
    );
    w.add_root_node(
        json!({"name": "red sphere", "mesh": red_sphere, "translation": [0.6, 0.35, -0.3]}),
    );
    let ring = w.add_mesh("blue torus", &torus(0.4, 0.12, 64, 24, TAU), glaze);
    let stand_up = Quat::from_rotation_x(FRAC_PI_2) * Quat::from_rotation_z(0.3);
    w.add_root_node(json!({"name": "blue torus", "mesh": ring, "translation": [1.6, 0.52, -1.6], "rotation": stand_up.normalize().to_array()}));

    // The fence: 4 mm posts every 10 cm and 2 mm wires, 3 m long, diagonal through the view.
    let post = w.add_mesh("fence post", &cylinder(0.002, 1.2, 8, 1, 0, 0.0), steel);
    let wire = w.add_mesh("fence wire", &cylinder(0.001, 3.0, 6, 1, 0, 0.0), steel);
    let (start, along) = (
        Vec3::new(-0.5, 0.0, 1.2),
        Vec3::new(1.0, 0.0, -0.35).normalize(),
    );
    for i in 0..=30 {
        let p = start + along * (i as f32 * 0.1);
        w.add_root_node(
            json!({"name": format!("post {i}"), "mesh": post, "translation": p.to_array()}),
        );
    }
    // Wires lie along `along`: rotate the +Y cylinder onto that direction.
    let lay = Quat::from_rotation_arc(Vec3::Y, along);
    for k in 0..6 {
        let p = start + Vec3::Y * (0.2 + 0.18 * k as f32);
        w.add_root_node(json!({"name": format!("wire {k}"), "mesh": wire, "translation": p.to_array(), "rotation": lay.to_array()}));
    }

    // Area light: a 1 × 0.5 m emissive panel 2.8 m up, facing down. Spot light: a warm key from
    // the right, aimed at the spheres (glTF lights shine along the node's −Z).
    let panel = w.add_mesh(
        "light panel",
        &quad(
            Vec3::new(-0.5, 2.8, -1.25),
            Vec3::X,
            Vec3::Z * 0.5,
            1,
            Vec2::ONE,
        ),
        lamp,
    );
    w.add_root_node(json!({"name": "light panel", "mesh": panel}));
    let spot_at = Vec3::new(2.5, 2.5, 1.5);
    let aim = Quat::from_rotation_arc(
        Vec3::NEG_Z,
        (Vec3::new(0.0, 0.4, -0.6) - spot_at).normalize(),
    );
    w.add_light(
        json!({"name": "spot", "type": "spot", "color": [1.0, 0.85, 0.7], "intensity": 40.0, "spot": {"innerConeAngle": 0.35, "outerConeAngle": 0.6}}),
        json!({"name": "spot", "translation": spot_at.to_array(), "rotation": aim.to_array()}),
    );
    // Camera at eye height looking slightly down into the scene; aspect of one 1280×1440 eye.
    let look = Quat::from_rotation_x(-12f32.to_radians());
    w.add_camera(
        "camera",
        60f32.to_radians(),
        1280.0 / 1440.0,
        [0.0, 1.6, 3.2],
        look.to_array(),
    );
    w
}
