//! The Cornell box, after the Cornell Program of Computer Graphics' measured scene, scaled to a
//! 1 m box (their 555 mm ≈ 1 unit) with the floor at y = 0, the open side facing +Z.
//! Reflectances are the commonly used RGB fits of the measured spectra (as in Mitsuba's and
//! pbrt's versions); the light's radiance (17, 12, 4) gives a well-exposed image at exposure 1.

use super::gltf_writer::GltfWriter;
use super::shapes::{cuboid, quad};
use glam::{Mat4, Quat, Vec2, Vec3};
use serde_json::json;

/// Lambertian: metallic 0, roughness 1 and KHR_materials_specular factor 0 (no specular lobe).
fn diffuse(name: &str, rgb: [f32; 3]) -> serde_json::Value {
    json!({
        "name": name,
        "pbrMetallicRoughness": {"baseColorFactor": [rgb[0], rgb[1], rgb[2], 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0},
        "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}
    })
}

fn translation_rotation(m: Mat4) -> (Vec3, Quat) {
    let (_, r, t) = m.to_scale_rotation_translation();
    (t, r)
}

pub fn build() -> GltfWriter {
    let mut w = GltfWriter::default();
    let white = w.add_material(diffuse("white", [0.725, 0.71, 0.68]));
    let red = w.add_material(diffuse("red", [0.63, 0.065, 0.05]));
    let green = w.add_material(diffuse("green", [0.14, 0.45, 0.091]));
    let mut light_material = diffuse("light", [0.78, 0.78, 0.78]);
    light_material["emissiveFactor"] = json!([1.0, 12.0 / 17.0, 4.0 / 17.0]);
    light_material["extensions"]["KHR_materials_emissive_strength"] =
        json!({"emissiveStrength": 17.0});
    let light = w.add_material(light_material);

    let (x0, x1, y1, z0, z1) = (-0.5, 0.5, 1.0, -0.5, 0.5);
    let walls = [
        ("floor", Vec3::new(x0, 0.0, z1), Vec3::X, Vec3::NEG_Z, white),
        ("ceiling", Vec3::new(x0, y1, z0), Vec3::X, Vec3::Z, white),
        ("back wall", Vec3::new(x0, 0.0, z0), Vec3::X, Vec3::Y, white),
        (
            "left wall",
            Vec3::new(x0, 0.0, z1),
            Vec3::NEG_Z,
            Vec3::Y,
            red,
        ),
        (
            "right wall",
            Vec3::new(x1, 0.0, z0),
            Vec3::Z,
            Vec3::Y,
            green,
        ),
    ];
    for (name, corner, u, v, material) in walls {
        let mesh = w.add_mesh(name, &quad(corner, u, v, 1, Vec2::ONE), material);
        w.add_root_node(json!({"name": name, "mesh": mesh}));
    }
    // The light: 0.235 × 0.19 m (the original 130 × 105 mm), 1 mm under the ceiling, facing down.
    let (lw, ld) = (0.235, 0.19);
    let lamp = quad(
        Vec3::new(-lw / 2.0, y1 - 0.001, -ld / 2.0),
        Vec3::X * lw,
        Vec3::Z * ld,
        1,
        Vec2::ONE,
    );
    let lamp = w.add_mesh("light", &lamp, light);
    w.add_root_node(json!({"name": "light", "mesh": lamp}));

    // The two blocks, rotated about their vertical axes as in the original (short: front right,
    // tall: back left). One unit cube mesh, instanced with scale, exercises node transforms.
    let cube = w.add_mesh("block", &cuboid(Vec3::ONE), white);
    let blocks = [
        (
            "short block",
            Vec3::new(0.3, 0.3, 0.3),
            Vec3::new(0.19, 0.15, 0.2),
            -17.0f32,
        ),
        (
            "tall block",
            Vec3::new(0.3, 0.6, 0.3),
            Vec3::new(-0.165, 0.3, -0.2),
            17.0,
        ),
    ];
    for (name, size, centre, degrees) in blocks {
        let (t, r) = translation_rotation(Mat4::from_rotation_translation(
            Quat::from_rotation_y(degrees.to_radians()),
            centre,
        ));
        w.add_root_node(json!({"name": name, "mesh": cube, "translation": t.to_array(), "rotation": r.to_array(), "scale": size.to_array()}));
    }
    // A viewer's eyes 0.3 m in front of the 1 m opening, centred: the opening spans ±59°, so a
    // headset's 90–100° field of view (`--projection headset`) sees the room and not the void
    // around it. The 70° vertical field of view (`--projection scene-camera`) shows the back
    // wall, both blocks and the side walls, as the original camera (1.44 m out, 39.3°) did.
    w.add_camera(
        "camera",
        70f32.to_radians(),
        1.0,
        [0.0, 0.5, z1 + 0.3],
        [0.0, 0.0, 0.0, 1.0],
    );
    w
}
