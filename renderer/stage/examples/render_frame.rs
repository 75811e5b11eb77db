//! A program embedding fovea with its libraries alone (no command line crate): a scene lit and
//! framed as `fovea render` sees it, both eyes of the FOVE 0 through their own frusta, the
//! simulated eye tracker timed to the frames, Visual-Polar sampling around each eye's gaze in the
//! screen-clipped layout with BMFR and TAA in the grid, no foveated blur, automatic exposure (the
//! settings of `fovea render`'s default profile), and the last frame's left and right eyes
//! written side by side as a PNG.
//!
//! ```text
//! cargo run --release -p fovea-stage --example render_frame -- [SCENE] [OUT.png]
//! ```
//! SCENE is a name (`cornell-box`, the default; `breakfast-room` with the shared scenes) or a
//! glTF path; OUT defaults to `render_frame.png`.

use anyhow::{Context as _, Result};
use fovea_hal::{Eye, HmdDescription};
use fovea_renderer::frame::{CrossEyeReuse, FrameInput, RenderSettings, ViewInput};
use fovea_renderer::passes::denoise::{bmfr::BmfrSettings, DenoiserSettings};
use fovea_renderer::passes::exposure::Exposure;
use fovea_renderer::passes::taa::{TaaMode, TaaSettings};
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::{SamplingSpace, VisualPolar, VisualPolarParams, VpLayout};
use fovea_renderer::vk::{Context, ContextOptions};
use fovea_renderer::way_back::blur::BlurSettings;
use fovea_stage::gaze::GazeDriver;
use fovea_stage::look::{CameraOptions, EnvironmentOptions};
use fovea_stage::projection::EyeRig;
use glam::UVec2;
use image::ImageEncoder;
use std::path::Path;
use std::sync::Arc;

/// What to render.
pub struct Options<'a> {
    pub scene: &'a str,
    /// One eye's image in pixels.
    pub width: u32,
    pub height: u32,
    /// Frames rendered; the last is returned (the temporal filters and the exposure settle).
    pub frames: u32,
    /// `sim[:seed]`, `center`, `X,Y` or a gaze trace (as `fovea render --gaze`).
    pub gaze: &'a str,
}

/// The last frame: each eye's tonemapped RGBA8 pixels, and the device (for its validation
/// messages).
pub struct Rendered {
    pub eyes: [Vec<u8>; 2],
    pub ctx: Arc<Context>,
}

pub fn render(options: &Options) -> Result<Rendered> {
    let hmd = HmdDescription::resolve("fove0")?;
    let rig = EyeRig {
        projection: Default::default(), // through the headset's per-eye frusta
        hmd: hmd.clone(),
        stereo: true,
        width: options.width,
        height: options.height,
        metres_per_unit: 1.0,
    };
    // The scene with the default sun and sky when its own lights do not light it, and its camera
    // (or one framing its bounds) as the head.
    let (scene, camera) = fovea_stage::look::load(
        options.scene,
        &CameraOptions::default(),
        &EnvironmentOptions::default(),
        rig.framing(),
    )?;
    let head = rig.head(&camera);
    let eyes = [Eye::Left, Eye::Right];

    let ctx = Context::new(&ContextOptions {
        validation: cfg!(debug_assertions),
        ..Default::default()
    })
    .context("opening the Vulkan device")?;
    let screen = UVec2::new(options.width, options.height);
    let centre = screen.as_vec2() * 0.5;
    let params = VisualPolarParams {
        layout: VpLayout::ScreenClipped,
        ..Default::default()
    };
    let spaces = eyes
        .iter()
        .map(|_| Ok(Box::new(VisualPolar::new(screen, centre, params)?) as Box<dyn SamplingSpace>))
        .collect::<Result<Vec<_>>>()?;
    let settings = RenderSettings {
        exposure: Exposure::auto(),
        denoiser: DenoiserSettings::Bmfr(BmfrSettings::default()),
        taa: TaaMode::SamplingGrid(TaaSettings::default()),
        // The renderer's default is the paper's blur; fovea's profile turns it off.
        blur: BlurSettings {
            sigma_at_30: 0.0,
            ..Default::default()
        },
        // The renderer's default is off; fovea's profile lets the eyes share where they can.
        cross_eye_reuse: CrossEyeReuse::Auto,
        ..Default::default()
    };
    let gpu_scene = fovea_renderer::gpu_scene::GpuScene::upload(&ctx, &scene)?;
    let mut renderer = Renderer::with_views(&ctx, gpu_scene, spaces, settings, 2)?;

    let mut gaze = GazeDriver::open(options.gaze, &hmd, options.width, options.height)?;
    let period = 1.0 / hmd.refresh_hz;
    let mut last = None;
    for index in 0..options.frames {
        let g = gaze.frame(index, &eyes)?;
        let views = eyes.map(|eye| ViewInput {
            camera: rig.eye(&head, eye),
            gaze: Some(g.pixels[eye.index()]),
        });
        let mut input = FrameInput::views(&views, index)?;
        input.frame_seconds = period;
        last = Some(renderer.submit(&input, None)?);
    }
    let frame = last.context("no frame rendered (frames = 0)")?;
    renderer.wait_frame(frame)?;
    let mut pixels = [Vec::new(), Vec::new()];
    for (view, out) in pixels.iter_mut().enumerate() {
        renderer.read_view_ldr(frame, view, out)?;
    }
    Ok(Rendered { eyes: pixels, ctx })
}

/// The two eyes side by side, written whole or not at all.
pub fn write_side_by_side(path: &Path, width: u32, height: u32, eyes: &[Vec<u8>; 2]) -> Result<()> {
    let row = 4 * width as usize;
    let mut both = Vec::with_capacity(2 * eyes[0].len());
    for y in 0..height as usize {
        for eye in eyes {
            both.extend_from_slice(&eye[y * row..(y + 1) * row]);
        }
    }
    fovea_stage::files::write_atomic(path, |out| {
        image::codecs::png::PngEncoder::new(out).write_image(
            &both,
            2 * width,
            height,
            image::ExtendedColorType::Rgba8,
        )?;
        Ok(())
    })
}

#[allow(dead_code)] // a module of the embedding test, which calls `render` itself
fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    let scene = args.next().unwrap_or_else(|| "cornell-box".to_string());
    let out = args
        .next()
        .unwrap_or_else(|| "render_frame.png".to_string());
    let options = Options {
        scene: &scene,
        width: 640,
        height: 720,
        frames: 16,
        gaze: "sim:1",
    };
    let rendered = render(&options)?;
    write_side_by_side(
        Path::new(&out),
        options.width,
        options.height,
        &rendered.eyes,
    )?;
    println!(
        "wrote {out}: {scene}, both eyes {}×{} on {}",
        options.width, options.height, rendered.ctx.info.name
    );
    Ok(())
}
