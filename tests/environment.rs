//! The default environment and cameras for real scenes: a uniform environment as the only light
//! (furnace, the baked sky and a loaded map), the
//! default sun's irradiance, and real glTF scenes without lights or cameras rendering lit.

use fovea_renderer::frame::{CameraPose, RenderSettings};
use fovea_renderer::passes::tonemap::ToneCurve;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::Cartesian;
use fovea_scene::{Camera, EnvironmentMap, Scene, Sky};
use fovea_stage::look::{self, EnvironmentOptions, NO_CAMERA_FLAGS};
use fovea_tests::scenes::{add_floor, lambert, white_sphere};
use fovea_tests::{assert_clean, gpu, mean_rgb, save_preview, shared_data};
use glam::{UVec2, Vec2, Vec3};
use std::sync::Arc;

fn reference(
    ctx: &Arc<fovea_renderer::vk::Context>,
    scene: &Scene,
    camera: &Camera,
    size: UVec2,
    spp: u32,
    depth: u32,
) -> Vec<[f32; 4]> {
    reference_seeded(ctx, scene, camera, size, spp, depth, 3)
}

fn reference_seeded(
    ctx: &Arc<fovea_renderer::vk::Context>,
    scene: &Scene,
    camera: &Camera,
    size: UVec2,
    spp: u32,
    depth: u32,
    seed: u32,
) -> Vec<[f32; 4]> {
    let settings = RenderSettings {
        seed,
        tone_curve: ToneCurve::Clamp,
        ..Default::default()
    };
    let mut r = Renderer::new(ctx, scene, Box::new(Cartesian::new(size)), settings).unwrap();
    r.render_reference(
        &CameraPose::from_scene_camera(camera, size.x, size.y),
        spp,
        depth,
        |_| {},
    )
    .unwrap()
}

/// Per-pixel means of `k` renders with seeds 1..=k, and the standard error of one such mean
/// pooled over `pixels` (green channel): the spread between the renders, from the samples alone.
fn means_and_error(
    k: u32,
    pixels: &[usize],
    mut render: impl FnMut(u32) -> Vec<[f32; 4]>,
) -> (Vec<[f32; 4]>, f64) {
    let images: Vec<Vec<[f32; 4]>> = (1..=k).map(&mut render).collect();
    let mut mean = images[0].clone();
    for (i, m) in mean.iter_mut().enumerate() {
        for c in 0..4 {
            m[c] = images.iter().map(|img| img[i][c]).sum::<f32>() / k as f32;
        }
    }
    let var: f64 = pixels
        .iter()
        .map(|&i| {
            images
                .iter()
                .map(|img| (img[i][1] - mean[i][1]) as f64)
                .map(|d| d * d)
                .sum::<f64>()
        })
        .sum::<f64>()
        / (pixels.len() as f64 * (k - 1) as f64);
    (mean, (var / k as f64).sqrt())
}

/// The furnace: a white Lambertian sphere (convex: every bounce escapes) inside a uniform
/// environment of radiance L has radiance L everywhere — with next-event estimation of the
/// environment and MIS, which only balance as they should if neither strategy double-counts. Run
/// for the default sky (baked into the equirectangular table) and for a loaded map (rotated and
/// scaled), 64×72, depths 2–4 (depth counts vertices: at 1 the sphere only shows emission, none).
#[test]
fn furnace_white_sphere_in_a_uniform_environment_has_its_radiance_at_every_depth() {
    let ctx = gpu();
    let l = 0.7f32;
    let mut sky = white_sphere();
    sky.sky = Sky::uniform(Vec3::splat(l));
    let mut map = white_sphere();
    let mut env = EnvironmentMap::new(8, 4, vec![Vec3::splat(l / 2.0); 32]).unwrap();
    (env.rotation, env.intensity) = (37f32.to_radians(), 2.0);
    map.environment = Some(env);
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 3.5), Vec3::ZERO, 0.7, "test");
    let size = UVec2::new(64, 72);
    // Pixels whose whole footprint lies on the sphere (its image is a disc of tan-radius 1/√(d²−1)),
    // and pixels that see only the environment.
    let (ty, disc) = ((camera.yfov * 0.5).tan(), 1.0 / (3.5f32 * 3.5 - 1.0).sqrt());
    let radius = |i: u32| {
        let p = (Vec2::new((i % size.x) as f32, (i / size.x) as f32) + 0.5) / size.as_vec2() * 2.0
            - 1.0;
        (p * Vec2::new(size.x as f32 / size.y as f32, 1.0)).length() * ty
    };
    let pixel = 2.0 * ty / size.y as f32;
    let on_sphere: Vec<usize> = (0..size.x * size.y)
        .filter(|&i| radius(i) + 1.5 * pixel <= disc)
        .map(|i| i as usize)
        .collect();
    let background: Vec<usize> = (0..size.x * size.y)
        .filter(|&i| radius(i) - 1.5 * pixel > disc)
        .map(|i| i as usize)
        .collect();
    assert!(
        on_sphere.len() > 1000 && background.len() > 1000,
        "{} sphere, {} background pixels",
        on_sphere.len(),
        background.len()
    );
    for (name, scene) in [("sky", &sky), ("map", &map)] {
        let direct = reference(&ctx, scene, &camera, size, 2, 1);
        assert!(
            on_sphere.iter().all(|&i| direct[i][..3] == [0.0; 3]),
            "{name}: depth 1 sphere not black"
        );
        for depth in [2, 3, 4] {
            let (image, error) = means_and_error(4, &on_sphere, |seed| {
                reference_seeded(&ctx, scene, &camera, size, 16, depth, seed)
            });
            save_preview(
                &format!("environment_furnace_{name}_depth{depth}.png"),
                size.x,
                size.y,
                &image,
            );
            for &i in &background {
                assert!(
                    (image[i][1] - l).abs() < 1e-5,
                    "{name} depth {depth}: background pixel {i} = {:?}",
                    image[i]
                );
            }
            // Per pixel within 6 standard errors (≈ 3000 pixels: a fair pass fails with p < 1e-5);
            // the sphere's mean within 4 of its own.
            let worst = on_sphere
                .iter()
                .map(|&i| (image[i][1] - l).abs() as f64)
                .fold(0.0, f64::max);
            let mean = mean_rgb(&on_sphere.iter().map(|&i| image[i]).collect::<Vec<_>>())[1];
            println!("{name} depth {depth}: sphere mean {mean:.5} (L {l}), worst pixel error {worst:.4}, standard error per pixel {error:.4}");
            assert!(
                worst < 6.0 * error + 1e-4,
                "{name} depth {depth}: a pixel is {worst} from L (standard error {error})"
            );
            assert!(
                (mean - l as f64).abs() < 4.0 * error / (on_sphere.len() as f64).sqrt() + 1e-5,
                "{name} depth {depth}: mean {mean} vs {l}"
            );
            assert!(error < 0.05 * l as f64, "{name} depth {depth}: standard error {error} (the MIS estimator should be far less noisy)");
        }
    }
    assert_clean(&ctx);
}

#[test]
fn default_sun_lights_an_upward_plane_with_cos_theta_times_its_illuminance() {
    let ctx = gpu();
    let albedo = 0.8f32;
    for (azimuth, elevation, intensity) in [
        (30.0f32, 60.0f32, 3.0f32),
        (200.0, 25.0, 5.0),
        (0.0, 90.0, 1.0),
    ] {
        let mut scene = Scene {
            materials: vec![lambert(albedo, 0.0)],
            mesh_names: vec!["floor".into()],
            ..Default::default()
        };
        add_floor(&mut scene, 50.0, 0);
        let env = EnvironmentOptions {
            sun: Some([azimuth, elevation]),
            sun_intensity: Some(intensity),
            sky_intensity: Some(0.0),
            ..Default::default()
        };
        assert!(look::apply_environment(&mut scene, &env).is_some());
        let camera = Camera::look_at(
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(0.0, 0.0, -0.01),
            0.5,
            "down",
        );
        let image = reference(&ctx, &scene, &camera, UVec2::splat(8), 1, 2);
        let expected = albedo * elevation.to_radians().sin() * intensity / std::f32::consts::PI;
        for p in &image {
            assert!(
                (p[1] - expected).abs() < 1e-3 * expected,
                "sun {azimuth},{elevation}: {} vs {expected}",
                p[1]
            );
        }
    }
    assert_clean(&ctx);
}

fn luminance(pixels: &[[f32; 4]]) -> f64 {
    let [r, g, b] = mean_rgb(pixels);
    0.2126 * r + 0.7152 * g + 0.0722 * b
}

/// The Preetham sky is scaled to the gradient sky's irradiance on an upward plane, so a white
/// floor under either (sun off) has radiance albedo · E / π: the rendered luminance checks the
/// bake, its scale and the importance sampling of a map with a circumsolar peak at once.
#[test]
fn preetham_and_gradient_skies_light_an_upward_plane_alike() {
    use fovea_stage::sky_model::{upward_irradiance, SkyModel};
    let ctx = gpu();
    let albedo = 0.8f32;
    let luminance = |p: &[f32; 4]| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    let mut means = Vec::new();
    for sky in [SkyModel::Gradient, SkyModel::Preetham] {
        let mut scene = Scene {
            materials: vec![lambert(albedo, 0.0)],
            mesh_names: vec!["floor".into()],
            ..Default::default()
        };
        add_floor(&mut scene, 50.0, 0);
        let env = EnvironmentOptions {
            sun: Some([40.0, 25.0]),
            sun_intensity: Some(0.0),
            sky_intensity: Some(1.0),
            sky: Some(sky),
            ..Default::default()
        };
        look::apply_environment(&mut scene, &env);
        let map = scene.environment_map().unwrap().into_owned();
        let expected = albedo * upward_irradiance(&map) / std::f32::consts::PI;
        let camera = Camera::look_at(
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(0.0, 0.0, -0.01),
            0.5,
            "down",
        );
        let image = reference(&ctx, &scene, &camera, UVec2::splat(8), 256, 2);
        let mean = image.iter().map(luminance).sum::<f32>() / image.len() as f32;
        println!(
            "{} sky: floor luminance {mean:.5}, expected {expected:.5}",
            sky.name()
        );
        assert!(
            (mean - expected).abs() < 0.02 * expected,
            "{}: {mean} vs {expected}",
            sky.name()
        );
        means.push(expected);
    }
    assert!((means[0] - means[1]).abs() < 1e-3 * means[0], "{means:?}");
    assert_clean(&ctx);
}

/// A real scene loaded as every command loads it (default sun, sky, camera), 64×72, 4 spp.
fn real_scene_luminance(name: &str, file: &str) -> Option<f64> {
    let path = shared_data(&format!("scenes/{name}/{file}"))?;
    let ctx = gpu();
    let size = UVec2::new(64, 72);
    let (scene, camera) = look::load(
        path.to_str().unwrap(),
        &NO_CAMERA_FLAGS,
        &EnvironmentOptions::default(),
        look::Framing::aspect(64.0 / 72.0),
    )
    .unwrap();
    let image = reference(&ctx, &scene, &camera, size, 4, 3);
    save_preview(&format!("environment_{name}.png"), size.x, size.y, &image);
    assert_clean(&ctx);
    Some(luminance(&image))
}

#[test]
fn sponza_renders_lit_with_the_default_sun_and_sky() {
    if let Some(l) = real_scene_luminance("sponza", "Sponza.gltf") {
        // Black before the default environment (exactly 0); interiors lit by a sun through their
        // openings stay dim at depth 3 (measured 0.016 Sponza, 0.011 Breakfast Room at 4 spp).
        assert!(l > 0.005, "mean luminance {l}");
    }
}

#[test]
fn breakfast_room_renders_lit_with_the_default_sun_and_sky() {
    if let Some(l) = real_scene_luminance("breakfast-room", "BreakfastRoom.gltf") {
        // Black before the default environment (exactly 0); interiors lit by a sun through their
        // openings stay dim at depth 3 (measured 0.016 Sponza, 0.011 Breakfast Room at 4 spp).
        assert!(l > 0.005, "mean luminance {l}");
    }
}

#[test]
fn flight_helmet_renders_through_fovea_render_with_the_default_camera() {
    let Some(path) = shared_data("scenes/flight-helmet/FlightHelmet.gltf") else {
        return;
    };
    let out = fovea_tests::artifacts_dir().join("environment_flight_helmet");
    let _ = std::fs::remove_dir_all(&out);
    let scene = path.to_str().unwrap();
    let args = fovea_tools::commands::render::RenderArgs {
        frames: 1,
        camera_path: Default::default(),
        ..fovea_tests::small_render_args(scene, &out)
    };
    fovea_tools::commands::render::run(&args).unwrap();
    let png = image::open(out.join("frame_0000.png")).unwrap().to_rgb8();
    let mean = png
        .pixels()
        .map(|p| p.0.iter().map(|&c| c as f64).sum::<f64>() / 3.0)
        .sum::<f64>()
        / png.pixels().len() as f64;
    // The helmet fills the middle of the frame, lit, in front of the sky.
    assert!(mean > 20.0, "mean sRGB value {mean}");
}
