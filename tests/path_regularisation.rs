//! Path regularisation (`RenderSettings::path_regularisation`, shaders/common/brdf.glsl
//! `regularise`): sunlight reflected by a near-specular wall onto a diffuse floor (a caustic that
//! only next-event estimation from the wall can find after the floor's diffuse bounce) makes
//! fireflies without it and none with it, at little cost in brightness; primary vertices and
//! direct light are untouched.

use fovea_renderer::frame::{CameraPose, RenderSettings};
use fovea_renderer::passes::tonemap::ToneCurve;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::Cartesian;
use fovea_scene::{Camera, Material, PunctualLight, Scene};
use fovea_tests::scenes::{add_quad, lambert};
use fovea_tests::{assert_clean, assert_pictures_equal, gpu, mean_rgb, save_preview, Picture};
use glam::{UVec2, Vec3, Vec4};
use std::sync::Arc;

const SIZE: UVec2 = UVec2::new(64, 72);

/// A white floor (y = 0), a metal wall of roughness 0.1 behind it (z = −1, facing +z) and a
/// sun whose mirror image off the wall lands on the floor in front of it.
fn caustic_scene() -> (Scene, Camera) {
    let wall = Material {
        base_color: Vec4::ONE,
        metallic: 1.0,
        roughness: 0.1,
        ..lambert(1.0, 0.0)
    };
    let mut scene = Scene {
        materials: vec![lambert(0.8, 0.0), wall],
        mesh_names: vec!["quads".into()],
        ..Default::default()
    };
    let v = Vec3::new;
    add_quad(
        &mut scene,
        [
            v(-3.0, 0.0, -1.0),
            v(-3.0, 0.0, 3.0),
            v(3.0, 0.0, 3.0),
            v(3.0, 0.0, -1.0),
        ],
        0,
    );
    add_quad(
        &mut scene,
        [
            v(-3.0, 0.0, -1.0),
            v(3.0, 0.0, -1.0),
            v(3.0, 2.5, -1.0),
            v(-3.0, 2.5, -1.0),
        ],
        1,
    );
    // Light travels along −direction: down and toward the wall, which sends it back down onto the floor.
    scene.punctual_lights.push(PunctualLight::Directional {
        direction: v(0.0, -1.0, -0.6).normalize(),
        illuminance: Vec3::splat(3.0),
    });
    let camera = Camera::look_at(v(0.0, 1.6, 3.5), v(0.0, 0.3, 0.0), 0.9, "floor");
    (scene, camera)
}

fn render(
    ctx: &Arc<fovea_renderer::vk::Context>,
    scene: &Scene,
    camera: &Camera,
    spp: u32,
    depth: u32,
    seed: u32,
    strength: f32,
) -> Vec<[f32; 4]> {
    let settings = RenderSettings {
        seed,
        tone_curve: ToneCurve::Clamp,
        path_regularisation: strength,
        ..Default::default()
    };
    let mut r = Renderer::new(ctx, scene, Box::new(Cartesian::new(SIZE)), settings).unwrap();
    r.render_reference(
        &CameraPose::from_scene_camera(camera, SIZE.x, SIZE.y),
        spp,
        depth,
        |_| {},
    )
    .unwrap()
}

fn luminance(p: &[f32; 4]) -> f64 {
    (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) as f64
}

/// Mean squared difference of a 1-spp image from a converged one: the 1-spp estimator's
/// variance (plus the converged image's own, 1/spp of it), averaged over the frame.
fn one_spp_variance(one: &[[f32; 4]], converged: &[[f32; 4]]) -> f64 {
    one.iter()
        .zip(converged)
        .map(|(a, b)| (luminance(a) - luminance(b)).powi(2))
        .sum::<f64>()
        / one.len() as f64
}

/// Pixels of the 1-spp image brighter than 10 times the converged frame's mean luminance.
fn fireflies(one: &[[f32; 4]], frame_mean: f64) -> usize {
    one.iter()
        .filter(|p| luminance(p) > 10.0 * frame_mean)
        .count()
}

#[test]
fn regularisation_removes_caustic_fireflies_and_keeps_the_brightness() {
    let ctx = gpu();
    let (scene, camera) = caustic_scene();
    let mut stats = Vec::new();
    for strength in [0.0f32, 1.0] {
        let converged = render(&ctx, &scene, &camera, 256, 3, 7, strength);
        let mean = mean_rgb(&converged)
            .iter()
            .zip([0.2126, 0.7152, 0.0722])
            .map(|(c, w)| c * w)
            .sum::<f64>();
        let (mut variance, mut count) = (0.0, 0);
        for seed in 1..=8 {
            let one = render(&ctx, &scene, &camera, 1, 3, seed, strength);
            variance += one_spp_variance(&one, &converged) / 8.0;
            count += fireflies(&one, mean);
        }
        save_preview(
            &format!("path_regularisation_{strength}.png"),
            SIZE.x,
            SIZE.y,
            &converged,
        );
        println!("strength {strength}: frame mean {mean:.4}, 1-spp variance {variance:.4}, fireflies in 8 frames {count}");
        stats.push((mean, variance, count));
    }
    let [(mean_off, var_off, ff_off), (mean_on, var_on, ff_on)] = [stats[0], stats[1]];
    assert!(
        ff_off >= 8,
        "the unregularised caustic should make fireflies (got {ff_off}): the scene tests nothing"
    );
    assert_eq!(ff_on, 0, "regularised: {ff_on} fireflies");
    assert!(
        var_off > 10.0 * var_on,
        "1-spp variance {var_off:.4} without vs {var_on:.4} with regularisation"
    );
    // The bias: the widened lobe spreads the caustic (partly out of the frame) and GGX loses a
    // little energy to single scattering; measured 10 % darker on this deliberately caustic-only
    // worst case.
    assert!(
        (mean_on - mean_off).abs() < 0.15 * mean_off,
        "frame mean {mean_on:.4} with vs {mean_off:.4} without"
    );
    assert_clean(&ctx);
}

#[test]
fn primary_vertices_and_direct_light_are_not_regularised() {
    let ctx = gpu();
    let (scene, _) = caustic_scene();
    // Looking at the wall: at depth 2 every vertex is primary (its light sample and the escaping
    // BRDF ray), so the images must be identical.
    let at_wall = Camera::look_at(
        Vec3::new(0.5, 1.5, 2.0),
        Vec3::new(0.0, 1.0, -1.0),
        0.9,
        "wall",
    );
    let off = render(&ctx, &scene, &at_wall, 4, 2, 3, 0.0);
    let on = render(&ctx, &scene, &at_wall, 4, 2, 3, 1.0);
    assert_pictures_equal(
        "depth 2, regularisation on against off",
        &Picture::hdr(SIZE.x, SIZE.y, &on),
        &Picture::hdr(SIZE.x, SIZE.y, &off),
    );
    assert!(off.iter().any(|p| luminance(p) > 0.0));
    assert_clean(&ctx);
}
