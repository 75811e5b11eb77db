//! glTF `alphaMode: MASK`: a cut-out is no hit for camera, bounce and shadow rays. The Cornell
//! box's block made fully transparent converges to the box without the block (its shadow gone
//! too); made fully opaque through the mask, it renders bit for bit as the opaque block. `BLEND`
//! (stochastic transparency) does the same at alpha 0 and 1 and lies between them at 0.5.

use fovea_renderer::frame::{CameraPose, RenderSettings};
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::Cartesian;
use fovea_renderer::scene::Scene;
use fovea_tests::{
    assert_clean, assert_pictures, assert_pictures_equal, gpu, owned_scene, rmse, Picture,
};
use glam::UVec2;

const SIZE: UVec2 = UVec2::new(48, 54);

fn picture(texels: &[[f32; 4]]) -> Picture<'_> {
    Picture::hdr(SIZE.x, SIZE.y, texels)
}

/// The Cornell box with the block's triangles on a copy of their material, alpha `alpha`, masked
/// at 0.5 (or without the block at all when `alpha` is `None`).
fn cornell_with_block(alpha: Option<f32>) -> Scene {
    cornell_with(alpha, false)
}

/// As `cornell_with_block`, the block's alpha blended (stochastic) instead of masked.
fn cornell_with_blended_block(alpha: f32) -> Scene {
    cornell_with(Some(alpha), true)
}

fn cornell_with(alpha: Option<f32>, blend: bool) -> Scene {
    let mut scene = owned_scene("cornell-box");
    let block = scene
        .mesh_names
        .iter()
        .position(|n| n == "block")
        .expect("the block mesh") as u32;
    match alpha {
        Some(a) => {
            // The two blocks are one instanced mesh: its triangles are in `instancing.meshes`.
            let instanced = scene.instancing.meshes.iter().flat_map(|m| &m.triangles);
            let tri = *scene
                .triangles
                .iter()
                .chain(instanced)
                .find(|t| t.mesh == block)
                .unwrap();
            let mut material = scene.materials[tri.material as usize].clone();
            material.base_color.w = a;
            if blend {
                material.alpha_blend = true;
            } else {
                material.alpha_cutoff = Some(0.5);
            }
            scene.materials.push(material);
            let index = scene.materials.len() as u32 - 1;
            let instanced = scene
                .instancing
                .meshes
                .iter_mut()
                .flat_map(|m| &mut m.triangles);
            scene
                .triangles
                .iter_mut()
                .chain(instanced)
                .filter(|t| t.mesh == block)
                .for_each(|t| t.material = index);
        }
        None => {
            scene = scene.flattened();
            scene.triangles.retain(|t| t.mesh != block);
        }
    }
    scene
}

fn reference(scene: &Scene, spp: u32) -> Vec<[f32; 4]> {
    let ctx = gpu();
    let camera = CameraPose::from_scene_camera(scene.default_camera().unwrap(), SIZE.x, SIZE.y);
    let mut renderer = Renderer::new(
        &ctx,
        scene,
        Box::new(Cartesian::new(SIZE)),
        RenderSettings::default(),
    )
    .unwrap();
    let image = renderer.render_reference(&camera, spp, 3, |_| {}).unwrap();
    drop(renderer);
    assert_clean(&ctx);
    image
}

#[test]
fn a_transparent_cut_out_is_no_hit_and_an_opaque_one_is_the_opaque_surface() {
    let (transparent, removed, opaque) = (
        reference(&cornell_with_block(Some(0.0)), 64),
        reference(&cornell_with_block(None), 64),
        reference(&owned_scene("cornell-box"), 64),
    );
    let (gone, there) = (rmse(&transparent, &removed), rmse(&transparent, &opaque));
    // Both sides converge to the same picture (noise only), far from the one with the block.
    assert_pictures(
        gone < there / 4.0,
        "masked-out block against no block",
        &picture(&transparent),
        &picture(&removed),
        format_args!("masked-out block vs no block {gone}, vs the opaque block {there}"),
    );
    let masked_opaque = reference(&cornell_with_block(Some(1.0)), 4);
    assert_pictures_equal(
        "alpha 1 through the mask against the opaque block",
        &picture(&masked_opaque),
        &picture(&reference(&owned_scene("cornell-box"), 4)),
    );
}

#[test]
fn blended_alpha_is_stochastic_transparency() {
    let (removed, opaque) = (
        reference(&cornell_with_block(None), 64),
        reference(&owned_scene("cornell-box"), 64),
    );
    let gone = reference(&cornell_with_blended_block(0.0), 64);
    assert_pictures(
        rmse(&gone, &removed) < rmse(&gone, &opaque) / 4.0,
        "blended alpha 0 against no block",
        &picture(&gone),
        &picture(&removed),
        "alpha 0 blends to no block",
    );
    assert_pictures_equal(
        "blended alpha 1 against the opaque block",
        &picture(&reference(&cornell_with_blended_block(1.0), 4)),
        &picture(&reference(&owned_scene("cornell-box"), 4)),
    );
    let half = reference(&cornell_with_blended_block(0.5), 64);
    let apart = rmse(&removed, &opaque);
    assert!(
        rmse(&half, &removed) < apart && rmse(&half, &opaque) < apart,
        "alpha 0.5 lies between no block and the opaque one"
    );
}

/// The loader reads alphaMode MASK and its cutoff (Sponza's foliage and chains, when present).
#[test]
fn sponza_s_masked_materials_are_read() {
    let Some(path) = fovea_tests::shared_data("scenes/sponza/Sponza.gltf") else {
        return;
    };
    let scene = Scene::load(&path).unwrap();
    let masked: Vec<f32> = scene
        .materials
        .iter()
        .filter_map(|m| m.alpha_cutoff)
        .collect();
    assert!(
        !masked.is_empty() && masked.iter().all(|c| (0.0..=1.0).contains(c)),
        "{masked:?}"
    );
}
