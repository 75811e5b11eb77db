use super::*;
use crate::test_util::TestRng;
use crate::{Material, Triangle, Vertex};
use glam::{Vec2, Vec4};

/// A vertex at `p` facing +Z (the light table reads positions only).
fn vertex(p: Vec3) -> Vertex {
    Vertex {
        position: p,
        normal: Vec3::Z,
        uv: Vec2::ZERO,
        tangent: Vec4::X,
    }
}

fn random_weights(rng: &mut TestRng, n: usize) -> Vec<f64> {
    // A wide dynamic range, with a few tiny ones, as real scenes have.
    (0..n)
        .map(|i| {
            if i % 7 == 3 {
                1e-3
            } else {
                (rng.f32() as f64 * 4.0).exp()
            }
        })
        .collect()
}

#[test]
fn alias_table_is_exact() {
    let mut rng = TestRng::new(11);
    for n in [1, 2, 5, 37, 200] {
        let w = random_weights(&mut rng, n);
        let total: f64 = w.iter().sum();
        let slots = build_alias_table(&w);
        // Probability mass that each entry receives from all slots, computed analytically.
        let mut mass = vec![0.0f64; n];
        for (i, s) in slots.iter().enumerate() {
            mass[i] += s.threshold as f64 / n as f64;
            mass[s.alias as usize] += (1.0 - s.threshold as f64) / n as f64;
        }
        for i in 0..n {
            assert!(
                (mass[i] - w[i] / total).abs() < 1e-6,
                "n={n} entry {i}: {} vs {}",
                mass[i],
                w[i] / total
            );
            assert!((slots[i].pdf as f64 - w[i] / total).abs() < 1e-6);
        }
        let pdf_sum: f64 = slots.iter().map(|s| s.pdf as f64).sum();
        assert!((pdf_sum - 1.0).abs() < 1e-5, "pdfs sum to {pdf_sum}");
    }
}

/// Pearson χ² of 400k uniform samples against the pdfs; 39 degrees of freedom, critical value
/// 72.1 at p = 0.001 (fixed seed, so this is deterministic).
#[test]
fn alias_sampling_reproduces_pdfs_chi_square() {
    let mut rng = TestRng::new(12);
    let w = random_weights(&mut rng, 40);
    let slots = build_alias_table(&w);
    let samples = 400_000;
    let mut counts = vec![0u64; w.len()];
    for _ in 0..samples {
        counts[sample_alias(&slots, rng.f32())] += 1;
    }
    let chi2: f64 = counts
        .iter()
        .zip(&slots)
        .map(|(&c, s)| {
            let expected = s.pdf as f64 * samples as f64;
            (c as f64 - expected).powi(2) / expected
        })
        .sum();
    assert!(chi2 < 72.1, "χ² = {chi2}");
}

#[test]
fn empty_scene_gives_empty_table() {
    let table = build_light_table(&Scene::default());
    assert!(table.entries.is_empty() && table.alias.is_empty());
    assert_eq!(table.total_power, 0.0);
}

#[test]
fn powers_follow_the_documented_formulas() {
    let mut scene = Scene {
        vertices: vec![
            vertex(Vec3::ZERO),
            vertex(Vec3::new(2.0, 0.0, 0.0)),
            vertex(Vec3::new(0.0, 1.0, 0.0)),
        ],
        triangles: vec![
            Triangle {
                indices: [0, 1, 2],
                material: 1,
                mesh: 0,
            },
            Triangle {
                indices: [0, 1, 2],
                material: 0,
                mesh: 0,
            },
        ],
        materials: vec![
            Material::default(),
            Material {
                emissive: Vec3::splat(3.0),
                ..Material::default()
            },
        ],
        ..Scene::default()
    };
    scene.punctual_lights = vec![
        PunctualLight::Point {
            position: Vec3::ONE,
            intensity: Vec3::splat(2.0),
            range: None,
        },
        PunctualLight::Spot {
            position: Vec3::ONE,
            direction: Vec3::NEG_Y,
            intensity: Vec3::splat(2.0),
            range: None,
            inner_cone: 0.1,
            outer_cone: 0.5,
        },
        PunctualLight::Directional {
            direction: Vec3::NEG_Y,
            illuminance: Vec3::splat(5.0),
        },
        PunctualLight::Point {
            position: Vec3::ONE,
            intensity: Vec3::ZERO,
            range: None,
        },
    ];
    let table = build_light_table(&scene);
    let kinds: Vec<_> = table.entries.iter().map(|e| (e.kind, e.index)).collect();
    assert_eq!(
        kinds,
        vec![
            (LightKind::EmissiveTriangle, 0),
            (LightKind::Point, 0),
            (LightKind::Spot, 1),
            (LightKind::Directional, 2)
        ]
    );
    let r = scene.bounds().bounding_sphere_radius();
    let expected = [
        3.0 * 1.0 * PI,
        4.0 * PI * 2.0,
        2.0 * PI * (1.0 - 0.5f32.cos()) * 2.0,
        5.0 * PI * r * r,
    ];
    for (e, x) in table.entries.iter().zip(expected) {
        assert!(
            (e.power - x).abs() < 1e-4 * x,
            "{:?}: {} vs {x}",
            e.kind,
            e.power
        );
    }
    assert!((table.total_power - expected.iter().sum::<f32>()).abs() < 1e-3);
}

#[test]
fn emissive_texture_mean_scales_triangle_power() {
    let scene = Scene {
        vertices: vec![vertex(Vec3::ZERO), vertex(Vec3::X), vertex(Vec3::Y)],
        triangles: vec![Triangle {
            indices: [0, 1, 2],
            material: 0,
            mesh: 0,
        }],
        materials: vec![Material {
            emissive: Vec3::ONE,
            emissive_texture: Some(0),
            ..Material::default()
        }],
        // Half the texels white, half black: mean linear colour 0.5.
        textures: vec![Texture {
            width: 2,
            height: 1,
            rgba8: vec![255, 255, 255, 255, 0, 0, 0, 255],
        }],
        ..Scene::default()
    };
    let table = build_light_table(&scene);
    assert!((table.entries[0].power - 0.5 * 0.5 * PI).abs() < 1e-5);
}

#[test]
fn emission_scale_dims_or_drops_a_materials_triangles() {
    let scene = Scene {
        vertices: vec![vertex(Vec3::ZERO), vertex(Vec3::X), vertex(Vec3::Y)],
        triangles: vec![
            Triangle {
                indices: [0, 1, 2],
                material: 0,
                mesh: 0,
            },
            Triangle {
                indices: [0, 1, 2],
                material: 1,
                mesh: 1,
            },
        ],
        materials: vec![
            Material {
                emissive: Vec3::ONE,
                ..Material::default()
            },
            Material {
                emissive: Vec3::ONE,
                ..Material::default()
            },
        ],
        ..Scene::default()
    };
    let full = build_light_table(&scene);
    let dimmed = build_light_table_scaled(&scene, &[0.25]);
    assert_eq!(dimmed.entries.len(), 2);
    assert!((dimmed.entries[0].power - 0.25 * full.entries[0].power).abs() < 1e-6);
    assert_eq!(
        dimmed.entries[1].power, full.entries[1].power,
        "materials beyond the slice keep their emission"
    );
    assert!(
        (dimmed.alias[0].pdf - 0.2).abs() < 1e-6,
        "pdfs follow the new powers"
    );
    let off = build_light_table_scaled(&scene, &[1.0, 0.0]);
    assert_eq!(
        off.entries.iter().map(|e| e.index).collect::<Vec<_>>(),
        vec![0]
    );
    assert!(build_light_table_scaled(&scene, &[0.0, 0.0])
        .entries
        .is_empty());
}

/// The shaders find an emissive triangle's entry by binary search over the table's first entries
/// and the environment's as the last (resampling.glsl: `triangle_light_entry`,
/// `draw_brdf_light_point`): emissive triangles first by ascending placed id, then punctual
/// lights, the environment last.
#[test]
fn triangles_come_first_by_placed_id_and_the_environment_last() {
    let triangle = |material| Triangle {
        indices: [0, 1, 2],
        material,
        mesh: 0,
    };
    let mut scene = Scene {
        vertices: vec![vertex(Vec3::ZERO), vertex(Vec3::X), vertex(Vec3::Y)],
        triangles: [1, 0, 1, 1, 0, 0, 1].map(triangle).to_vec(),
        materials: vec![
            Material::default(),
            Material {
                emissive: Vec3::ONE,
                ..Material::default()
            },
        ],
        ..Scene::default()
    };
    scene.punctual_lights = vec![PunctualLight::Point {
        position: Vec3::ONE,
        intensity: Vec3::ONE,
        range: None,
    }];
    scene.sky = crate::Sky::uniform(Vec3::ONE);
    let table = build_light_table(&scene);
    let kinds: Vec<_> = table.entries.iter().map(|e| (e.kind, e.index)).collect();
    assert_eq!(
        kinds,
        vec![
            (LightKind::EmissiveTriangle, 0),
            (LightKind::EmissiveTriangle, 2),
            (LightKind::EmissiveTriangle, 3),
            (LightKind::EmissiveTriangle, 6),
            (LightKind::Point, 0),
            (LightKind::Environment, 0),
        ]
    );
}
