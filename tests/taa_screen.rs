//! TAA after the remap to the screen (`--taa screen`, beyond the paper): error against
//! a converged reference next to the raw frame and to TAA in the sampling grid, fireflies, and
//! the disocclusion reset. The remap's placement of jittered samples is tested in vp_remap.rs.

use ash::vk;
use fovea_renderer::frame::{CameraPose, FrameInput, RenderSettings};
use fovea_renderer::graph::FrameRecorder;
use fovea_renderer::layouts::FrameData;
use fovea_renderer::passes::grid::{GBuffer, GridFrame};
use fovea_renderer::passes::taa::ScreenTaa;
use fovea_renderer::passes::taa::{TaaMode, TaaSettings};
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::{Cartesian, VisualPolar, VisualPolarParams};
use fovea_renderer::vk::{Buffer, Context, Image};
use fovea_renderer::way_back::blur::BlurSettings;
use fovea_tests::denoise::{assert_finite_non_negative, plain_materials, rmse_where};
use fovea_tests::{
    assert_clean, assert_pictures, gpu, inject_fireflies, owned_scene, read_image, save_preview,
    unit_hash, write_image, Picture, SpaceBuffers,
};
use glam::{UVec2, UVec4, Vec2, Vec4};
use std::sync::Arc;

const SCREEN: UVec2 = UVec2::new(64, 72);

fn vp_space() -> VisualPolar {
    VisualPolar::new(SCREEN, SCREEN.as_vec2() * 0.5, VisualPolarParams::default()).unwrap()
}

/// The blur is off: the comparison measures sampling and TAA only.
fn settings(taa: TaaMode) -> RenderSettings {
    RenderSettings {
        blur: BlurSettings {
            sigma_at_30: 0.0,
            ..Default::default()
        },
        taa,
        ..Default::default()
    }
}

fn frame(camera: CameraPose, frame_index: u32) -> FrameInput {
    FrameInput::mono(camera, frame_index, None).with_hdr(true)
}

fn luminance(p: &[f32; 4]) -> f32 {
    0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]
}

/// 16 frames of VP with TAA after the remap vs one raw frame, against 256 spp, beside TAA in the
/// VP grid. Pixels on the light (reference luminance > 1) are left out of the assertion: both
/// TAAs average them with Karis's 1/(1 + luma) weights, by design below the linear mean.
#[test]
fn screen_taa_reduces_error_beside_grid_taa() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], SCREEN.x, SCREEN.y);
    let mut reference_renderer = Renderer::new(
        &ctx,
        &scene,
        Box::new(Cartesian::new(SCREEN)),
        settings(TaaMode::Off),
    )
    .unwrap();
    let reference = reference_renderer
        .render_reference(&camera, 256, 3, |_| {})
        .unwrap();
    drop(reference_renderer);
    let lit: Vec<bool> = reference.iter().map(|p| luminance(p) > 1.0).collect();
    let run = |taa: TaaMode, frames: u32| {
        let mut r = Renderer::new(&ctx, &scene, Box::new(vp_space()), settings(taa)).unwrap();
        for f in 0..frames {
            r.render_frame(&frame(camera, f)).unwrap();
        }
        let mut out = Vec::new();
        r.read_hdr(&mut out).unwrap();
        let ms: f64 = r
            .timings()
            .iter()
            .filter(|t| t.name.starts_with("taa"))
            .map(|t| t.ms)
            .sum();
        let passes: Vec<&str> = r.timings().iter().map(|t| t.name).collect();
        (out, ms, passes.join(" "), r.taa_history_bytes())
    };
    let (raw, ..) = run(TaaMode::Off, 1);
    let (screen, screen_ms, screen_passes, screen_bytes) =
        run(TaaMode::Screen(TaaSettings::default()), 16);
    let (grid, grid_ms, _, grid_bytes) = run(TaaMode::SamplingGrid(TaaSettings::default()), 16);
    assert!(
        screen_passes.contains("taa_screen") && !screen_passes.contains("taa "),
        "passes: {screen_passes}"
    );
    assert_finite_non_negative("screen taa", &screen);
    save_preview("taa_screen_vp.png", SCREEN.x, SCREEN.y, &screen);
    save_preview("taa_screen_vp_raw.png", SCREEN.x, SCREEN.y, &raw);
    let unlit = |i: usize| !lit[i];
    let (e_raw, e_screen, e_grid) = (
        rmse_where(&raw, &reference, unlit),
        rmse_where(&screen, &reference, unlit),
        rmse_where(&grid, &reference, unlit),
    );
    println!(
        "VP {}×{}, RMSE without the light's pixels: raw 1 frame {e_raw:.4}; 16 frames TAA after the remap {e_screen:.4} \
         ({:.2}×, {screen_ms:.3} ms, history {screen_bytes} B); 16 frames TAA in the VP grid {e_grid:.4} ({:.2}×, \
         {grid_ms:.3} ms, history {grid_bytes} B)",
        SCREEN.x,
        SCREEN.y,
        e_raw / e_screen,
        e_raw / e_grid
    );
    assert_pictures(
        e_raw / e_screen >= 2.0,
        "screen taa",
        &Picture::hdr(SCREEN.x, SCREEN.y, &screen),
        &Picture::hdr(SCREEN.x, SCREEN.y, &reference),
        format_args!(
            "screen-space TAA cut the error only {:.2}×",
            e_raw / e_screen
        ),
    );
    assert_clean(&ctx);
}

/// A `FrameData` buffer for a still camera (this frame = the previous one).
fn still_frame_data(ctx: &Arc<Context>, camera: &CameraPose) -> Buffer {
    let s = SCREEN.as_vec2();
    let data = FrameData {
        world_from_view: camera.world_from_view,
        prev_view_from_world: camera.world_from_view.inverse(),
        fov_tan: camera.fov_tan,
        prev_fov_tan: camera.fov_tan,
        screen: Vec4::new(s.x, s.y, 1.0 / s.x, 1.0 / s.y),
        frame: UVec4::ZERO,
        ..Default::default()
    };
    Buffer::with_data(ctx, "frame", &[data], vk::BufferUsageFlags::UNIFORM_BUFFER).unwrap()
}

fn resolve(
    ctx: &Arc<Context>,
    taa: &mut ScreenTaa,
    color: &Image,
    frame: &GridFrame,
) -> Vec<[f32; 4]> {
    let mut rec = FrameRecorder::new(ctx, 2).unwrap();
    rec.begin().unwrap();
    let out = taa.record(&mut rec, color, frame).unwrap();
    rec.submit_and_wait().unwrap();
    read_image(ctx, out)
}

/// Huge, infinite, NaN and negative colours injected into remapped Cornell frames: every output
/// pixel stays finite and non-negative.
#[test]
fn screen_taa_output_is_finite_and_non_negative_with_fireflies() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], SCREEN.x, SCREEN.y);
    let mut r = Renderer::new(&ctx, &scene, Box::new(vp_space()), settings(TaaMode::Off)).unwrap();
    let mut taa = ScreenTaa::new(&ctx, SCREEN, TaaSettings::default()).unwrap();
    let frame_data = still_frame_data(&ctx, &camera);
    let color = Image::new(
        &ctx,
        "remapped",
        SCREEN.x,
        SCREEN.y,
        vk::Format::R32G32B32A32_SFLOAT,
    )
    .unwrap();
    let mut peak = 0f32;
    for f in 0..6 {
        r.render_frame(&frame(camera, f)).unwrap();
        let mut hdr = Vec::new();
        r.read_hdr(&mut hdr).unwrap();
        write_image(&ctx, &color, &hdr);
        inject_fireflies(&ctx, &color, f);
        let space = r.space().params();
        let buffers = SpaceBuffers::new(&ctx, r.space(), f, 1);
        let sequence = (space, (f > 0).then_some(space));
        let input = GridFrame {
            frame_data: &frame_data,
            ..buffers.grid_frame(&r.view(0).gbuffer, sequence, &r.scene.materials)
        };
        let out = resolve(&ctx, &mut taa, &color, &input);
        assert_finite_non_negative(&format!("frame {f}"), &out);
        peak = peak.max(
            out.iter()
                .flat_map(|p| p[..3].iter().copied())
                .fold(0.0, f32::max),
        );
    }
    println!("brightest screen-TAA output with fireflies {peak:.1}");
    assert_clean(&ctx);
}

/// A still camera and a synthetic VP G-buffer: frame 0 sees a wall at depth 1 everywhere, frame 1
/// sees the background (depth 5) where the wall has gone (samples right of the screen's middle).
/// Both frames show random red/blue pixels, so a clip box admits the history: pixels
/// whose surface is new must come out exactly as this frame's colour (history dropped), pixels
/// on the remaining wall must blend with their history.
#[test]
fn screen_taa_drops_history_where_the_background_is_uncovered() {
    let ctx = gpu();
    let scene = owned_scene("cornell-box");
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], SCREEN.x, SCREEN.y);
    let vp = vp_space();
    let grid = vp.grid_size();
    let gbuffer = GBuffer::new(&ctx, grid).unwrap();
    let frame_data = still_frame_data(&ctx, &camera);
    let mut taa = ScreenTaa::new(&ctx, SCREEN, TaaSettings::default()).unwrap();
    let color = Image::new(
        &ctx,
        "remapped",
        SCREEN.x,
        SCREEN.y,
        vk::Format::R32G32B32A32_SFLOAT,
    )
    .unwrap();
    let texels = (grid.x * grid.y) as usize;
    let uncovered = |x: u32, y: u32| {
        vp.vp_to_screen(Vec2::new(x as f32 + 0.5, y as f32 + 0.5)).x > SCREEN.x as f32 * 0.5
    };
    let space = vp.sampling_params();
    let buffers = SpaceBuffers::new(&ctx, &vp, 0, 1);
    let materials = plain_materials(&ctx);
    let mut out = Vec::new();
    let mut current: Vec<[f32; 4]> = Vec::new();
    let mut previous = Vec::new();
    for f in 0..2u32 {
        let depth = |x, y| if f == 1 && uncovered(x, y) { 5.0 } else { 1.0 };
        let normal_depth: Vec<[f32; 4]> = (0..texels)
            .map(|i| [0.0, 0.0, 1.0, depth(i as u32 % grid.x, i as u32 / grid.x)])
            .collect();
        write_image(&ctx, &gbuffer.normal_depth, &normal_depth);
        write_image(
            &ctx,
            &gbuffer.position,
            &vec![[0.0, 0.0, 0.0, 0.01]; texels],
        );
        // Red or blue at random, drawn afresh each frame: the history often differs from this
        // frame's colour, and any neighbourhood holds both.
        previous = std::mem::take(&mut current);
        current = (0..SCREEN.x * SCREEN.y)
            .map(|i| {
                if unit_hash(i * 7 + f * 7919) < 0.5 {
                    [1.0, 0.0, 0.0, 1.0]
                } else {
                    [0.0, 0.0, 1.0, 1.0]
                }
            })
            .collect();
        write_image(&ctx, &color, &current);
        let input = GridFrame {
            frame_data: &frame_data,
            ..buffers.grid_frame(&gbuffer, (space, (f > 0).then_some(space)), &materials)
        };
        out = resolve(&ctx, &mut taa, &color, &input);
    }
    let (mut fresh, mut blended, mut new_pixels, mut wall_pixels) = (0, 0, 0, 0);
    for y in 0..SCREEN.y {
        for x in 0..SCREEN.x {
            let i = (y * SCREEN.x + x) as usize;
            // The shader's own rule: the depth of the VP sample nearest to the pixel.
            let g = vp.screen_to_vp(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            let col = (g.x.max(0.0) as u32).min(grid.x - 1);
            let row = (g.y.max(0.0) as u32).min(vp.rows_in_column(col) - 1);
            let same = (0..3).all(|c| (out[i][c] - current[i][c]).abs() < 1e-6);
            if uncovered(col, row) {
                new_pixels += 1;
                fresh += same as u32;
            } else if previous[i] != current[i] {
                // (Where the colour did not change, blending cannot show.)
                wall_pixels += 1;
                blended += !same as u32;
            }
        }
    }
    println!("uncovered: {fresh} of {new_pixels} pixels fresh; wall, colour changed: {blended} of {wall_pixels} blended with history");
    assert!(
        new_pixels > 500 && wall_pixels > 250,
        "{new_pixels} / {wall_pixels}"
    );
    assert_eq!(
        fresh, new_pixels,
        "uncovered pixels kept history from the wall"
    );
    assert!(
        blended as f32 > 0.95 * wall_pixels as f32,
        "the wall's history was dropped: {blended} of {wall_pixels}"
    );
    assert_clean(&ctx);
}
