//! Scenes built in code for tests with analytic answers.

use fovea_scene::{Camera, Material, Scene, Triangle, Vertex};
use glam::{Mat4, Vec2, Vec3, Vec4};

/// Appends a quad (two triangles) with corners in counter-clockwise order seen from `normal`'s side.
pub fn add_quad(scene: &mut Scene, corners: [Vec3; 4], material: u32) {
    let normal = (corners[1] - corners[0])
        .cross(corners[2] - corners[0])
        .normalize();
    let base = scene.vertices.len() as u32;
    for (i, c) in corners.iter().enumerate() {
        scene.vertices.push(Vertex {
            position: *c,
            normal,
            uv: Vec2::new((i == 1 || i == 2) as u32 as f32, (i >= 2) as u32 as f32),
            tangent: Vec4::new(1.0, 0.0, 0.0, 1.0),
        });
    }
    let mesh = 0;
    scene.triangles.push(Triangle {
        indices: [base, base + 1, base + 2],
        material,
        mesh,
    });
    scene.triangles.push(Triangle {
        indices: [base, base + 2, base + 3],
        material,
        mesh,
    });
}

/// Appends a triangle with its face normal at each corner (zero for a degenerate one).
pub fn add_flat_triangle(scene: &mut Scene, corners: [Vec3; 3], material: u32) {
    let [a, b, c] = corners;
    let normal = (b - a).cross(c - a).normalize_or_zero();
    let base = scene.vertices.len() as u32;
    for position in corners {
        scene.vertices.push(Vertex {
            position,
            normal,
            uv: Vec2::ZERO,
            tangent: Vec4::X,
        });
    }
    scene.triangles.push(Triangle {
        indices: [base, base + 1, base + 2],
        material,
        mesh: 0,
    });
}

/// Appends a square floor facing up (+Y) at y = 0, reaching `half` from the origin along X and Z.
pub fn add_floor(scene: &mut Scene, half: f32, material: u32) {
    let s = half;
    add_quad(
        scene,
        [
            Vec3::new(-s, 0.0, -s),
            Vec3::new(-s, 0.0, s),
            Vec3::new(s, 0.0, s),
            Vec3::new(s, 0.0, -s),
        ],
        material,
    );
}

/// A Lambertian material of the given albedo (specular factor 0: exactly base_color / π).
pub fn lambert(albedo: f32, emission: f32) -> Material {
    Material {
        base_color: Vec4::new(albedo, albedo, albedo, 1.0),
        metallic: 0.0,
        roughness: 1.0,
        specular_factor: 0.0,
        emissive: Vec3::splat(emission),
        ..Default::default()
    }
}

/// A closed unit cube whose inner faces all have albedo `albedo` and emit `emission`, with the
/// camera at its centre: the furnace. Radiance with paths of D vertices is
/// emission × (1 + a + … + a^(D−1)).
pub fn furnace(albedo: f32, emission: f32) -> Scene {
    // Double-sided so the winding of the faces cannot hide the emission from the inside.
    let material = Material {
        double_sided: true,
        ..lambert(albedo, emission)
    };
    let mut scene = Scene {
        materials: vec![material],
        mesh_names: vec!["box".into()],
        ..Default::default()
    };
    let (lo, hi) = (-1.0f32, 1.0f32);
    let p = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    // Each face wound so its normal points into the box.
    add_quad(
        &mut scene,
        [p(lo, lo, lo), p(hi, lo, lo), p(hi, lo, hi), p(lo, lo, hi)],
        0,
    ); // floor, +y
    add_quad(
        &mut scene,
        [p(lo, hi, lo), p(lo, hi, hi), p(hi, hi, hi), p(hi, hi, lo)],
        0,
    ); // ceiling, −y
    add_quad(
        &mut scene,
        [p(lo, lo, lo), p(lo, lo, hi), p(lo, hi, hi), p(lo, hi, lo)],
        0,
    ); // left, +x
    add_quad(
        &mut scene,
        [p(hi, lo, lo), p(hi, hi, lo), p(hi, hi, hi), p(hi, lo, hi)],
        0,
    ); // right, −x
    add_quad(
        &mut scene,
        [p(lo, lo, lo), p(lo, hi, lo), p(hi, hi, lo), p(hi, lo, lo)],
        0,
    ); // back, +z
    add_quad(
        &mut scene,
        [p(lo, lo, hi), p(hi, lo, hi), p(hi, hi, hi), p(lo, hi, hi)],
        0,
    ); // front, −z
    scene.cameras.push(Camera {
        world_from_view: Mat4::IDENTITY,
        yfov: 1.2,
        aspect: None,
        znear: 0.01,
        name: "centre".into(),
    });
    scene
}

/// A flat-shaded UV sphere (convex: a ray leaving a facet never meets the sphere again), white
/// Lambertian, radius 1 at the origin.
pub fn white_sphere() -> Scene {
    let mut scene = Scene {
        materials: vec![lambert(1.0, 0.0)],
        mesh_names: vec!["sphere".into()],
        ..Default::default()
    };
    let (rings, segments) = (24, 48);
    let point = |i: u32, j: u32| {
        let (theta, phi) = (
            std::f32::consts::PI * i as f32 / rings as f32,
            std::f32::consts::TAU * j as f32 / segments as f32,
        );
        Vec3::new(
            theta.sin() * phi.cos(),
            theta.cos(),
            theta.sin() * phi.sin(),
        )
    };
    let mut push = |a: Vec3, b: Vec3, c: Vec3| {
        if (b - a).cross(c - a).length() >= 1e-9 {
            add_flat_triangle(&mut scene, [a, b, c], 0); // not the poles' degenerate halves
        }
    };
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (
                point(i, j),
                point(i + 1, j),
                point(i + 1, j + 1),
                point(i, j + 1),
            );
            // Counter-clockwise seen from outside.
            push(a, c, b);
            push(a, d, c);
        }
    }
    scene
}
