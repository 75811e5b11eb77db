//! Each eye is rendered through its headset frustum: with the gaze straight ahead on an
//! asymmetric profile, the fovea lies where the eye's view direction crosses the rendered image,
//! and eccentricities measured on that image (`fovea eval --headset`'s axis) are true angles.

use fovea_stage::look::{CameraOptions, DefaultLight, EnvironmentOptions};
use fovea_stage::scenegen::gltf_writer::GltfWriter;
use fovea_stage::scenegen::shapes::quad;
use fovea_tools::commands::render::{run as render, RenderArgs};
use glam::{UVec2, Vec2, Vec3};
use serde_json::json;
use std::path::Path;

/// Distance of the markers from the eye (metres).
const DISTANCE: f32 = 4.0;
/// The second marker's angle to the right of the left eye's view direction (degrees).
const OFF_AXIS_DEG: f32 = 20.0;
/// PSVR2 (61.5° temporal, 43.5° nasal, ±53°) at 0.1 of its 2400×2448 eye.
const SIZE: UVec2 = UVec2::new(240, 245);

/// Two small emissive squares facing the head (the camera at the origin looking down −Z): one
/// on the left eye's view axis, one `OFF_AXIS_DEG` to its right; nothing else.
fn marker_scene(path: &Path) {
    let left_eye = Vec3::new(-0.0315, 0.0, 0.0);
    let half = 0.04;
    let mut w = GltfWriter::default();
    let emitter = w.add_material(json!({
        "name": "marker",
        "emissiveFactor": [1.0, 1.0, 1.0],
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}},
        "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0]}
    }));
    let a = OFF_AXIS_DEG.to_radians();
    for (name, direction) in [
        ("ahead", Vec3::NEG_Z),
        ("off-axis", Vec3::new(a.sin(), 0.0, -a.cos())),
    ] {
        let centre = left_eye + direction * DISTANCE;
        // A square facing the eye: its sides along the eye's right and up.
        let right = Vec3::Y.cross(-direction).normalize();
        let corner = centre - (right + Vec3::Y) * half;
        let mesh = w.add_mesh(
            name,
            &quad(
                corner,
                right * 2.0 * half,
                Vec3::Y * 2.0 * half,
                1,
                Vec2::ONE,
            ),
            emitter,
        );
        w.add_root_node(json!({"name": name, "mesh": mesh}));
    }
    w.add_camera("head", 1.0, 1.0, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]);
    std::fs::write(path, serde_json::to_vec(&w.finish()).unwrap()).unwrap();
}

/// Brightness-weighted centroids (continuous pixels) of the bright pixels left and right of
/// column `split`.
fn centroids(rgba: &[u8], split: f32) -> [Vec2; 2] {
    let mut sums = [(Vec2::ZERO, 0.0f32); 2];
    for (i, p) in rgba.chunks_exact(4).enumerate() {
        let v = p[0] as f32;
        if v < 40.0 {
            continue;
        }
        let at = Vec2::new(
            (i as u32 % SIZE.x) as f32 + 0.5,
            (i as u32 / SIZE.x) as f32 + 0.5,
        );
        let side = usize::from(at.x > split);
        sums[side].0 += at * v;
        sums[side].1 += v;
    }
    sums.map(|(s, w)| {
        assert!(w > 0.0, "a marker is missing from the image");
        s / w
    })
}

#[test]
fn the_fovea_and_the_rings_describe_the_image_the_headset_shows() {
    let dir = std::env::temp_dir().join(format!("fovea-headset-frustum-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("markers.gltf");
    marker_scene(&scene);
    let out = dir.join("render");
    let camera = CameraOptions::default();
    let profile = fovea_tools::render_profile::RenderProfile {
        environment: EnvironmentOptions {
            default_light: Some(DefaultLight::Off),
            ..Default::default()
        },
        ..Default::default()
    };
    let args = RenderArgs {
        headset: "psvr2",
        gaze: "center",
        width: Some(SIZE.x),
        height: Some(SIZE.y),
        frames: 1,
        exr: false,
        camera_path: fovea_stage::camera_path::CameraMotion::Still,
        camera: &camera,
        profile,
        ..fovea_tests::small_render_args(scene.to_str().unwrap(), &out)
    };
    render(&args).unwrap();
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["projection"], "headset");
    let gaze = report["gaze"][0].as_array().unwrap();
    let gaze = Vec2::new(
        gaze[0].as_f64().unwrap() as f32,
        gaze[1].as_f64().unwrap() as f32,
    );
    // The PSVR2's left eye sees 61.5° to the left and 43.5° to the right: straight ahead lies
    // right of the image's centre.
    let expected_x = 61.5f32.to_radians().tan()
        / (61.5f32.to_radians().tan() + 43.5f32.to_radians().tan())
        * SIZE.x as f32;
    assert!(
        (gaze.x - expected_x).abs() < 1.0 && gaze.x > SIZE.x as f32 * 0.55,
        "gaze {gaze}, expected x ≈ {expected_x}"
    );

    let png = image::open(out.join("frame_0000.png")).unwrap().to_rgba8();
    let [ahead, off_axis] = centroids(png.as_raw(), gaze.x + 20.0);
    // Half a pixel: the gaze's pixel convention (a pixel's index at its centre) against the
    // image's continuous coordinates, at most half of the headset's own pixel scaled.
    assert!(
        (ahead - gaze).length() < 0.75,
        "the fovea at {gaze}, the view direction's marker at {ahead}"
    );

    let hmd = fovea_hal::HmdDescription::resolve("psvr2").unwrap();
    let fov = fovea_tools::render_profile::fov_tangents(&hmd.eye(fovea_hal::Eye::Left).fov);
    let axis = fovea_renderer::sampling::HeadsetAxis::new(fov, SIZE, ahead);
    let measured = axis.eccentricity(off_axis - ahead);
    // One pixel at this size spans about 0.45°.
    assert!(
        (measured - OFF_AXIS_DEG).abs() < 0.5,
        "the off-axis marker measured at {measured}° on the image, placed at {OFF_AXIS_DEG}°"
    );
}
