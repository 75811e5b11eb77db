//! Pixel blocks (Mohanto et al. 2023, comparators.md §F): the atlas's units as the GPU sees them
//! equal the Rust twin's (which units trace, how many samples, where), a frame traces exactly
//! that many samples, the block fill reproduces a linear image exactly away from the borders,
//! the frames converge to what one sample per pixel gives, and the filters are refused.

use fovea_renderer::frame::{CameraPose, FrameInput, RenderSettings};
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::{BlockShape, PixelBlocks, SamplingSpace, VisualPolarParams};
use fovea_renderer::vk::Image;
use fovea_renderer::way_back::block_fill::BlockFillPass;
use fovea_tests::{assert_clean, gpu, owned_scene, probe, SpaceBuffers};
use glam::{IVec2, UVec2, Vec2};

fn blocks(screen: UVec2, gaze: Vec2) -> PixelBlocks {
    let mut s =
        PixelBlocks::new(screen, VisualPolarParams::default(), BlockShape::default()).unwrap();
    s.set_gaze(gaze).unwrap();
    s
}

/// Where the Rust twin puts a texel's sample at jitter (½, ½): the middle of its block's part on
/// the screen.
fn host_position(s: &PixelBlocks, texel: IVec2) -> Option<Vec2> {
    let (level, block) = s.unit(texel)?;
    if !s.traced(level, block) {
        return None;
    }
    let b = 1 << level;
    let lo = block * b;
    let extent = ((lo + b).min(s.screen_size().as_ivec2()) - lo).as_vec2();
    Some(lo.as_vec2() + 0.5 * extent)
}

#[test]
fn pixel_blocks_units_agree_between_rust_and_glsl_and_frames_trace_exactly_their_samples() {
    let ctx = gpu();
    for (screen, gaze) in [
        (UVec2::new(64, 72), Vec2::new(20.0, 50.0)),
        (UVec2::new(322, 361), Vec2::new(300.0, 40.5)),
    ] {
        let s = blocks(screen, gaze);
        let g = s.grid_size();
        for (i, got) in probe(&ctx, &s, 0, 1).iter().enumerate() {
            let t = IVec2::new((i as u32 % g.x) as i32, (i as u32 / g.x) as i32);
            assert_eq!(got.samples, s.samples_in_texel(t), "{screen} texel {t}");
            assert_eq!(got.position, host_position(&s, t), "{screen} texel {t}");
        }
    }
    let screen = UVec2::new(64, 72);
    let scene = owned_scene("cornell-box");
    let camera = CameraPose::from_scene_camera(scene.default_camera().unwrap(), screen.x, screen.y);
    let gaze = Vec2::new(40.0, 30.0);
    let host = blocks(screen, gaze);
    let mut r = Renderer::new(
        &ctx,
        &scene,
        Box::new(blocks(screen, screen.as_vec2() * 0.5)),
        RenderSettings::default(),
    )
    .unwrap();
    for f in 0..2 {
        let stats = r
            .render_frame(&FrameInput::mono(camera, f, Some(gaze)))
            .unwrap();
        assert_eq!(stats.samples_traced, host.sample_count(), "frame {f}");
    }
    assert_clean(&ctx);
}

/// A linear image given to the units (each at its block's centre) comes back exactly wherever a
/// pixel's four block neighbours lie inside the level (bilinear interpolation of a linear
/// function is the function), and every fovea pixel is its own unit.
#[test]
fn the_block_fill_reproduces_a_linear_image() {
    let ctx = gpu();
    let (screen, gaze) = (UVec2::new(96, 108), Vec2::new(40.0, 60.0));
    let s = blocks(screen, gaze);
    let g = s.grid_size();
    let truth = |p: Vec2| [p.x / 96.0, p.y / 108.0, 0.25, 1.0];
    let atlas: Vec<[f32; 4]> = (0..g.y as i32)
        .flat_map(|y| (0..g.x as i32).map(move |x| IVec2::new(x, y)))
        .map(|t| match s.unit(t) {
            Some((level, block)) if s.traced(level, block) => {
                truth((block.as_vec2() + 0.5) * (1 << level) as f32)
            }
            _ => [0.0; 4],
        })
        .collect();
    let grid = Image::new(
        &ctx,
        "atlas",
        g.x,
        g.y,
        ash::vk::Format::R32G32B32A32_SFLOAT,
    )
    .unwrap();
    fovea_tests::write_image(&ctx, &grid, &atlas);
    let out = Image::new(
        &ctx,
        "filled",
        screen.x,
        screen.y,
        ash::vk::Format::R32G32B32A32_SFLOAT,
    )
    .unwrap();
    let fill = BlockFillPass::new(&ctx, s.shader_variant()).unwrap();
    let buffers = SpaceBuffers::new(&ctx, &s, 0, 1);
    let mut rec = fovea_renderer::graph::FrameRecorder::new(&ctx, 2).unwrap();
    rec.begin().unwrap();
    fill.record(&mut rec, &buffers.sampling, &grid, &out)
        .unwrap();
    rec.submit_and_wait().unwrap();
    let got: Vec<[f32; 4]> = fovea_tests::read_image(&ctx, &out);
    let mut checked = [0u32; 3];
    for y in 0..screen.y {
        for x in 0..screen.x {
            let p = Vec2::new(x as f32, y as f32) + 0.5;
            let level = s.level_of(p);
            let b = (1 << level) as f32;
            let i0 = (p / b - 0.5).floor().as_ivec2();
            // Beyond the first and last block centres the fill clamps (holds the edge value).
            if level > 0
                && (i0.cmplt(IVec2::ZERO).any() || (i0 + 1).cmpge(s.level_size(level)).any())
            {
                continue;
            }
            let (have, want) = (got[(y * screen.x + x) as usize], truth(p));
            for c in 0..4 {
                assert!(
                    (have[c] - want[c]).abs() < 1e-5,
                    "pixel {p} level {level}: {have:?} vs {want:?}"
                );
            }
            checked[level] += 1;
        }
    }
    assert!(checked.iter().all(|&n| n > 50), "{checked:?}");
    assert_clean(&ctx);
}

#[test]
fn pixel_blocks_converge_like_one_sample_per_pixel_and_refuse_the_filters() {
    let ctx = gpu();
    let screen = UVec2::new(64, 72);
    let scene = owned_scene("cornell-box");
    let camera = CameraPose::from_scene_camera(scene.default_camera().unwrap(), screen.x, screen.y);
    let gaze = Vec2::new(30.0, 40.0);
    let check = |f: u32, hdr: &[[f32; 4]]| {
        assert!(
            hdr.iter()
                .all(|p| p.iter().all(|c| c.is_finite()) && p[3] == 1.0),
            "frame {f}"
        )
    };
    let mut r = Renderer::new(
        &ctx,
        &scene,
        Box::new(blocks(screen, gaze)),
        RenderSettings::default(),
    )
    .unwrap();
    fovea_tests::assert_mean_like_cartesian(&ctx, &scene, &mut r, camera, gaze, 16, check);
    fovea_tests::assert_refuses_svgf(&ctx, &scene, Box::new(blocks(screen, gaze)));
    assert_clean(&ctx);

    let report = fovea_tests::render_report("pixel-blocks", Default::default());
    assert_eq!(report["method"], "pixel-blocks");
    for pass in ["block_fill", "accumulate", "trace"] {
        assert!(
            report["passes"][pass].as_f64().is_some(),
            "{pass}: {}",
            report["passes"]
        );
    }
}
