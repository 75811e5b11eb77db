use super::*;
use fovea_renderer::scene::{Aabb, Material, Triangle, Vertex};
use glam::{Mat4, Vec2, Vec4};

/// One triangle spanning `lo`..`hi` (enough for bounds) with `material`.
fn scene_with(lo: Vec3, hi: Vec3, material: Material) -> Scene {
    let v = |p: Vec3| Vertex {
        position: p,
        normal: Vec3::Y,
        uv: Vec2::ZERO,
        tangent: Vec4::X,
    };
    Scene {
        vertices: vec![v(lo), v(Vec3::new(hi.x, lo.y, lo.z)), v(hi)],
        triangles: vec![Triangle {
            indices: [0, 1, 2],
            material: 0,
            mesh: 0,
        }],
        materials: vec![material],
        mesh_names: vec!["m".into()],
        ..Default::default()
    }
}

fn named_camera(name: &str, z: f32) -> Camera {
    Camera {
        world_from_view: Mat4::from_translation(Vec3::new(0.0, 0.0, z)),
        yfov: 0.8,
        aspect: None,
        znear: 0.01,
        name: name.into(),
    }
}

/// Every corner of `b` in the image of `camera` at `aspect` (pinhole, yfov kept).
fn corners_inside(camera: &Camera, b: &Aabb, aspect: f32) -> bool {
    let ty = (camera.yfov * 0.5).tan();
    let view_from_world = camera.world_from_view.inverse();
    (0..8).all(|i| {
        let c = Vec3::new(
            if i & 1 == 0 { b.min.x } else { b.max.x },
            if i & 2 == 0 { b.min.y } else { b.max.y },
            if i & 4 == 0 { b.min.z } else { b.max.z },
        );
        let p = view_from_world.transform_point3(c);
        p.z < 0.0 && (p.x / -p.z).abs() < ty * aspect && (p.y / -p.z).abs() < ty
    })
}

#[test]
fn framing_camera_sees_every_bound_corner_at_any_aspect() {
    let boxes = [
        (Vec3::splat(-1.0), Vec3::splat(1.0)),
        (Vec3::new(-30.0, 0.0, -12.0), Vec3::new(28.0, 14.0, 13.0)),
        (Vec3::new(5.0, 5.0, 5.0), Vec3::new(5.1, 9.0, 5.2)),
    ];
    for (lo, hi) in boxes {
        let scene = scene_with(lo, hi, Material::default());
        for aspect in [0.5, 0.889, 1.0, 16.0 / 9.0] {
            let (camera, framing) = CameraOptions::default()
                .camera_for(&scene, Framing::aspect(aspect))
                .unwrap();
            assert!(framing);
            assert!((camera.yfov - 60f32.to_radians()).abs() < 1e-6);
            assert!(
                corners_inside(&camera, &scene.bounds(), aspect),
                "{lo} {hi} aspect {aspect}"
            );
        }
    }
}

#[test]
fn camera_by_index_and_name_and_clear_errors() {
    let mut scene = scene_with(Vec3::ZERO, Vec3::ONE, Material::default());
    scene.cameras = vec![named_camera("front", 5.0), named_camera("back", -5.0)];
    let pick = |c: &str| {
        CameraOptions {
            camera: Some(c.into()),
            ..Default::default()
        }
        .camera_for(&scene, Framing::aspect(1.0))
    };
    assert_eq!(pick("1").unwrap().0.name, "back");
    assert_eq!(pick("front").unwrap().0.name, "front");
    let err = format!("{:#}", pick("side").unwrap_err());
    assert!(
        err.contains("0 \"front\"") && err.contains("1 \"back\""),
        "{err}"
    );
    assert!(format!("{:#}", pick("2").unwrap_err()).contains("--camera 2"));
    // No flag: the file's first camera.
    assert_eq!(
        CameraOptions::default()
            .camera_for(&scene, Framing::aspect(1.0))
            .unwrap()
            .0
            .name,
        "front"
    );
    let fov = CameraOptions {
        camera: Some("back".into()),
        fov: Some(90.0),
        projection: Projection::SceneCamera,
        ..Default::default()
    };
    assert!(
        (fov.camera_for(&scene, Framing::aspect(1.0)).unwrap().0.yfov - 90f32.to_radians()).abs()
            < 1e-6
    );
}

#[test]
fn free_camera_looks_at_its_point_and_bad_values_are_refused() {
    let scene = scene_with(Vec3::ZERO, Vec3::ONE, Material::default());
    let free = |p: &str, l: &str, fov: Option<f32>| CameraOptions {
        position: Some(p.into()),
        look: Some(l.into()),
        fov,
        projection: Projection::SceneCamera,
        ..Default::default()
    };
    let (camera, _) = free("0,1,5", "0,1,0", Some(45.0))
        .camera_for(&scene, Framing::aspect(1.0))
        .unwrap();
    let forward = camera.world_from_view.transform_vector3(-Vec3::Z);
    assert!((forward - Vec3::new(0.0, 0.0, -1.0)).length() < 1e-5);
    assert!((camera.world_from_view.w_axis.truncate() - Vec3::new(0.0, 1.0, 5.0)).length() < 1e-5);
    // Straight down: no degenerate basis.
    let (down, _) = free("0,10,0", "0,0,0", None)
        .camera_for(&scene, Framing::aspect(1.0))
        .unwrap();
    assert!(down.world_from_view.is_finite());
    for (opts, needle) in [
        (free("1,1,1", "1,1,1", None), "other than its own position"),
        (free("NaN,1,1", "0,0,0", None), "finite"),
        (free("1,1", "0,0,0", None), "three numbers"),
        (free("1,1,x", "0,0,0", None), "not a number"),
        (free("0,0,1", "0,0,0", Some(170.0)), "--fov"),
        (free("0,0,1", "0,0,0", Some(1.0)), "--fov"),
        (
            CameraOptions {
                position: Some("0,0,1".into()),
                ..Default::default()
            },
            "--camera-look",
        ),
        (
            CameraOptions {
                camera: Some("0".into()),
                position: Some("0,0,1".into()),
                ..Default::default()
            },
            "one or the other",
        ),
    ] {
        let err = format!(
            "{:#}",
            opts.camera_for(&scene, Framing::aspect(1.0)).unwrap_err()
        );
        assert!(err.contains(needle), "{err}");
    }
}

#[test]
fn default_sun_and_sky_only_for_scenes_without_lights() {
    let mut dark = scene_with(Vec3::ZERO, Vec3::ONE, Material::default());
    assert!(apply_environment(&mut dark, &EnvironmentOptions::default())
        .unwrap()
        .contains("no lights in the scene"));
    assert_eq!(dark.punctual_lights.len(), 1);
    let PunctualLight::Directional {
        direction,
        illuminance,
    } = dark.punctual_lights[0]
    else {
        panic!("not a sun")
    };
    assert!(
        (direction + sun_direction(DEFAULT_SUN[0], DEFAULT_SUN[1])).length() < 1e-6
            && direction.y < 0.0
    );
    assert_eq!(illuminance, Vec3::splat(DEFAULT_SUN_INTENSITY));
    assert_eq!(dark.sky, default_sky(DEFAULT_SKY_INTENSITY));

    let lit_material = Material {
        emissive: Vec3::ONE,
        ..Default::default()
    };
    let mut lit = scene_with(Vec3::ZERO, Vec3::ONE, lit_material);
    assert!(apply_environment(
        &mut lit,
        &EnvironmentOptions {
            sun: Some([0.0, 45.0]),
            ..Default::default()
        }
    )
    .is_none());
    assert!(lit.punctual_lights.is_empty() && lit.sky.is_black());
    apply_environment(
        &mut lit,
        &EnvironmentOptions {
            sky_intensity: Some(2.0),
            ..Default::default()
        },
    );
    assert_eq!(lit.sky, default_sky(2.0));

    let mut off = scene_with(Vec3::ZERO, Vec3::ONE, Material::default());
    apply_environment(
        &mut off,
        &EnvironmentOptions {
            sun_intensity: Some(0.0),
            sky_intensity: Some(0.0),
            ..Default::default()
        },
    );
    assert!(off.punctual_lights.is_empty() && off.sky.is_black());
}

#[test]
fn preetham_sky_travels_as_a_map_around_the_sun() {
    use crate::sky_model::{preetham_map, SkyModel};
    let preetham = EnvironmentOptions {
        sun: Some([120.0, 35.0]),
        sky: Some(SkyModel::Preetham),
        ..Default::default()
    };
    let mut dark = scene_with(Vec3::ZERO, Vec3::ONE, Material::default());
    let notice = apply_environment(&mut dark, &preetham).unwrap();
    assert!(notice.contains("preetham sky"), "{notice}");
    assert!(dark.sky.is_black() && dark.punctual_lights.len() == 1);
    assert_eq!(
        dark.environment,
        Some(preetham_map(
            sun_direction(120.0, 35.0),
            DEFAULT_SKY_INTENSITY
        ))
    );
    // A scene with lights: only on request, and then around the default sun's position.
    let mut lit = scene_with(
        Vec3::ZERO,
        Vec3::ONE,
        Material {
            emissive: Vec3::ONE,
            ..Default::default()
        },
    );
    apply_environment(
        &mut lit,
        &EnvironmentOptions {
            sky: Some(SkyModel::Preetham),
            ..Default::default()
        },
    );
    assert!(lit.environment.is_none());
    apply_environment(
        &mut lit,
        &EnvironmentOptions {
            sky: Some(SkyModel::Preetham),
            sky_intensity: Some(2.0),
            ..Default::default()
        },
    );
    assert_eq!(
        lit.environment,
        Some(preetham_map(
            sun_direction(DEFAULT_SUN[0], DEFAULT_SUN[1]),
            2.0
        ))
    );
    assert!(lit.punctual_lights.is_empty());
    let mut off = scene_with(Vec3::ZERO, Vec3::ONE, Material::default());
    apply_environment(
        &mut off,
        &EnvironmentOptions {
            sky_intensity: Some(0.0),
            ..preetham
        },
    );
    assert!(off.environment.is_none() && off.sky.is_black());
}

#[test]
fn environment_values_are_checked_with_the_name() {
    let flags = EnvironmentNames::flags();
    assert!(EnvironmentOptions {
        sun: Some([10.0, 90.0]),
        sun_intensity: Some(0.0),
        sky_intensity: Some(1e6),
        ..Default::default()
    }
    .validate(&flags)
    .is_ok());
    for (env, needle) in [
        (
            EnvironmentOptions {
                sun: Some([0.0, 0.0]),
                ..Default::default()
            },
            "--sun",
        ),
        (
            EnvironmentOptions {
                sun: Some([f32::NAN, 10.0]),
                ..Default::default()
            },
            "--sun",
        ),
        (
            EnvironmentOptions {
                sun_intensity: Some(-1.0),
                ..Default::default()
            },
            "--sun-intensity",
        ),
        (
            EnvironmentOptions {
                sky_intensity: Some(f32::INFINITY),
                ..Default::default()
            },
            "--sky-intensity",
        ),
    ] {
        assert!(format!("{:#}", env.validate(&flags).unwrap_err()).contains(needle));
    }
    let key = EnvironmentOptions {
        sky_intensity: Some(-2.0),
        ..Default::default()
    }
    .validate(&EnvironmentNames::profile("p.toml"));
    assert!(format!("{:#}", key.unwrap_err()).contains("p.toml: [environment].sky_intensity"));
    assert_eq!(parse_sun("-20, 35").unwrap(), [-20.0, 35.0]);
    assert!(parse_sun("20").is_err() && parse_sun("a,b").is_err());
}

#[test]
fn an_environment_map_replaces_the_sky_and_the_sun_needs_asking_for() {
    let dir = std::env::temp_dir().join(format!("fovea-look-env-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("grey.hdr");
    let pixels = vec![image::Rgb([0.5f32, 0.5, 0.5]); 8 * 4];
    image::codecs::hdr::HdrEncoder::new(std::fs::File::create(&file).unwrap())
        .encode(&pixels, 8, 4)
        .unwrap();
    let env = EnvironmentOptions {
        env: Some(file.clone()),
        env_rotation: Some(45.0),
        env_intensity: Some(2.0),
        ..Default::default()
    };

    let mut dark = scene_with(Vec3::ZERO, Vec3::ONE, Material::default());
    let notice = apply_environment_map(&mut dark, &env).unwrap().unwrap();
    assert!(
        notice.contains("grey.hdr") && notice.contains("no sun"),
        "{notice}"
    );
    assert!(dark.punctual_lights.is_empty() && dark.sky.is_black());
    let map = dark.environment.as_ref().unwrap();
    assert_eq!(
        (map.width, map.height, map.intensity, map.rotation),
        (8, 4, 2.0, 45f32.to_radians())
    );

    let mut sunny = scene_with(Vec3::ZERO, Vec3::ONE, Material::default());
    let with_sun = EnvironmentOptions {
        sun: Some([10.0, 50.0]),
        ..env.clone()
    };
    assert!(apply_environment_map(&mut sunny, &with_sun)
        .unwrap()
        .unwrap()
        .contains("sun at azimuth 10°"));
    assert_eq!(sunny.punctual_lights.len(), 1);

    // A scene with its own lights gets the map, never the sun, and no notice.
    let mut lit = scene_with(
        Vec3::ZERO,
        Vec3::ONE,
        Material {
            emissive: Vec3::ONE,
            ..Default::default()
        },
    );
    assert!(apply_environment_map(&mut lit, &with_sun)
        .unwrap()
        .is_none());
    assert!(lit.punctual_lights.is_empty() && lit.environment.is_some());

    let missing = EnvironmentOptions {
        env: Some(dir.join("none.exr")),
        ..Default::default()
    };
    let err = format!(
        "{:#}",
        apply_environment_map(
            &mut scene_with(Vec3::ZERO, Vec3::ONE, Material::default()),
            &missing
        )
        .unwrap_err()
    );
    assert!(err.contains("none.exr"), "{err}");
}

#[test]
fn replay_description_of_the_default_environment_is_unchanged() {
    // What the committed baselines (tests/replay/baseline/*/baseline.json) recorded.
    assert_eq!(
        EnvironmentOptions::default().describe(),
        "EnvironmentOptions { sun: None, sun_intensity: None, sky_intensity: None }"
    );
    assert!(EnvironmentOptions {
        env_intensity: Some(2.0),
        ..Default::default()
    }
    .describe()
    .contains("env_intensity: Some(2.0)"));
}

/// A 2 m floor (no emission) with one emissive triangle of `emitter_area` m² and strength 1.
fn model_with_a_small_emitter(emitter_area: f32) -> Scene {
    let mut scene = scene_with(
        Vec3::new(-1.0, 0.0, -1.0),
        Vec3::new(1.0, 0.0, 1.0),
        Material::default(),
    );
    scene.materials.push(Material {
        emissive: Vec3::ONE,
        ..Default::default()
    });
    // A right triangle of legs a: area a²/2.
    let a = (2.0 * emitter_area).sqrt();
    let v = |p: Vec3| Vertex {
        position: p,
        normal: Vec3::Z,
        uv: Vec2::ZERO,
        tangent: Vec4::X,
    };
    let base = scene.vertices.len() as u32;
    scene.vertices.extend([
        v(Vec3::new(0.0, 0.5, 0.0)),
        v(Vec3::new(a, 0.5, 0.0)),
        v(Vec3::new(0.0, 0.5 + a, 0.0)),
    ]);
    scene.triangles.push(Triangle {
        indices: [base, base + 1, base + 2],
        material: 1,
        mesh: 0,
    });
    scene
}

#[test]
fn the_default_light_follows_the_scenes_own_power_not_its_presence() {
    // 10 cm² of emitters on a 2 m model: present, but far too weak to light it.
    let mut detail = model_with_a_small_emitter(1e-3);
    assert!(detail.has_lights());
    let share = own_light_share(&detail);
    assert!(share > 0.0 && share < MIN_OWN_LIGHT_SHARE, "{share}");
    let notice = apply_environment(&mut detail, &EnvironmentOptions::default())
        .expect("the default light is added");
    assert!(
        notice.contains("default sun and sky") && notice.contains("% of the default sun's power"),
        "{notice}"
    );
    assert_eq!(detail.punctual_lights.len(), 1);
    assert_eq!(detail.sky, default_sky(DEFAULT_SKY_INTENSITY));

    // A third of a square metre at strength 1 lights the same model.
    let mut lamp = model_with_a_small_emitter(0.3);
    assert!(own_light_share(&lamp) >= MIN_OWN_LIGHT_SHARE);
    assert!(apply_environment(&mut lamp, &EnvironmentOptions::default()).is_none());
    assert!(lamp.punctual_lights.is_empty() && lamp.sky.is_black());

    // The share is the emitted power over the sun's through the bounding sphere: 1e-3 m² at
    // radiance 1 sends out π·1e-3; the sun 3·π·r², r = half the bounds' diagonal.
    let r = detail.bounds().bounding_sphere_radius();
    let expected = 1e-3 / (DEFAULT_SUN_INTENSITY * r * r);
    assert!(
        (share - expected).abs() < 1e-3 * expected,
        "{share} vs {expected}"
    );
}

#[test]
fn default_light_on_and_off_override_the_rule() {
    let on = EnvironmentOptions {
        default_light: Some(DefaultLight::On),
        ..Default::default()
    };
    let mut lamp = model_with_a_small_emitter(0.3);
    let notice = apply_environment(&mut lamp, &on).expect("forced on");
    assert!(notice.contains("--default-light on"), "{notice}");
    assert_eq!(lamp.punctual_lights.len(), 1);

    let off = EnvironmentOptions {
        default_light: Some(DefaultLight::Off),
        ..Default::default()
    };
    let mut dark = scene_with(Vec3::ZERO, Vec3::ONE, Material::default());
    assert!(apply_environment(&mut dark, &off).is_none());
    assert!(dark.punctual_lights.is_empty() && dark.sky.is_black());
    assert_eq!(DefaultLight::parse("on").unwrap(), DefaultLight::On);
    let err = DefaultLight::parse("bright").unwrap_err().to_string();
    assert!(
        err.contains("--default-light bright") && err.contains("auto"),
        "{err}"
    );
}

#[test]
fn the_cornell_box_is_lit_by_its_own_ceiling_light() {
    let scene = crate::scenes::load("cornell-box").unwrap();
    let share = own_light_share(&scene);
    assert!((0.1..0.5).contains(&share), "{share}");
}

#[test]
fn fov_belongs_to_the_scene_camera_projection() {
    let scene = scene_with(Vec3::ZERO, Vec3::ONE, Material::default());
    let headset = CameraOptions {
        fov: Some(50.0),
        ..Default::default()
    };
    let err = format!(
        "{:#}",
        headset
            .camera_for(&scene, Framing::aspect(1.0))
            .unwrap_err()
    );
    assert!(
        err.contains("--fov 50") && err.contains("scene-camera"),
        "{err}"
    );
    // The framing camera fits the scene into the view it is given (a headset's inscribed one).
    let framing = Framing {
        yfov: Some(100f32.to_radians()),
        aspect: 0.9,
    };
    let (camera, framed) = CameraOptions::default()
        .camera_for(&scene, framing)
        .unwrap();
    assert!(framed);
    assert!((camera.yfov - 100f32.to_radians()).abs() < 1e-6);
    assert!(corners_inside(&camera, &scene.bounds(), 0.9));
}
