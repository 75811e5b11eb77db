//! Shared helpers for the integration tests: a validated Vulkan context, scenes built in code,
//! image statistics. Every test opens its own context with validation on and ends with
//! `assert_clean`, so any validation warning or error fails the test that caused it.

pub mod denoise;
pub mod scenes;

use ash::vk;
use fovea_renderer::graph::FrameRecorder;
use fovea_renderer::vk::{Buffer, Context, ContextOptions, Image};
use gpu_allocator::MemoryLocation;
use std::path::PathBuf;
use std::sync::Arc;

/// A context on the default device (lavapipe without a GPU) with validation on.
pub fn gpu() -> Arc<Context> {
    Context::new(&ContextOptions {
        validation: true,
        ..Default::default()
    })
    .expect("Vulkan device with validation layers")
}

/// Fails when the validation layer reported any warning or error.
pub fn assert_clean(ctx: &Context) {
    assert_eq!(
        ctx.validation.problems(),
        0,
        "validation messages: {:#?}",
        ctx.validation.messages()
    );
}

/// The repository root (tests may read `scenes/` and, when present, `../shared/`).
pub fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// One of the project's stored scenes (`scenes/<name>.gltf`).
pub fn owned_scene(name: &str) -> fovea_scene::Scene {
    let path = repo_root().join("scenes").join(format!("{name}.gltf"));
    fovea_scene::Scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// The Cornell box seen as the physical box's camera sees it: 1.44 m in front of the opening,
/// centred, 39.3° vertical field of view, fitted to `size`. The scene's own camera stands closer
/// (a viewer's place for a headset's wide view); tests whose thresholds were measured on this
/// framing, with the box inside a black surround, keep it.
pub fn cornell_box_far_camera(size: glam::UVec2) -> fovea_renderer::frame::CameraPose {
    let camera = fovea_scene::Camera::look_at(
        glam::Vec3::new(0.0, 0.5, 0.5 + 800.0 / 555.0),
        glam::Vec3::new(0.0, 0.5, 0.0),
        39.3f32.to_radians(),
        "far",
    );
    fovea_renderer::frame::CameraPose::from_scene_camera(&camera, size.x, size.y)
}

/// A file of the reference data under `../shared/data`: missing, it fails the test with its path
/// under `FOVEA_REQUIRE_DATA=1` and is reported as skipped otherwise (see `fovea_test_kit::data`).
pub use fovea_test_kit::data::shared_data;

/// Picture comparisons that leave actual, expected and FLIP pictures in
/// `target/test-failures/<test>/` when they fail (`fovea_test_kit::pictures`).
pub use fovea_test_kit::pictures::{
    assert_pictures, assert_pictures_equal, failure_message, Picture,
};

/// Where tests write images worth looking at when they fail.
pub fn artifacts_dir() -> PathBuf {
    let dir = repo_root().join("target/test-artifacts");
    std::fs::create_dir_all(&dir).expect("create target/test-artifacts");
    dir
}

/// Mean of the RGB channels over all pixels.
pub fn mean_rgb(pixels: &[[f32; 4]]) -> [f64; 3] {
    let mut sum = [0f64; 3];
    for p in pixels {
        for c in 0..3 {
            sum[c] += p[c] as f64;
        }
    }
    sum.map(|s| s / pixels.len() as f64)
}

/// Root-mean-square difference over RGB.
pub fn rmse(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    assert_eq!(a.len(), b.len());
    let sum: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| {
            (0..3)
                .map(|c| (x[c] as f64 - y[c] as f64).powi(2))
                .sum::<f64>()
        })
        .sum();
    (sum / (3 * a.len()) as f64).sqrt()
}

/// Writes a linear image as a PNG (clamped, sRGB-ish gamma) for a human to look at.
pub fn save_preview(name: &str, width: u32, height: u32, pixels: &[[f32; 4]]) -> PathBuf {
    let bytes: Vec<u8> = pixels
        .iter()
        .flat_map(|p| {
            let g = |v: f32| (v.clamp(0.0, 1.0).powf(1.0 / 2.2) * 255.0 + 0.5) as u8;
            [g(p[0]), g(p[1]), g(p[2]), 255]
        })
        .collect();
    let path = artifacts_dir().join(name);
    image::save_buffer(
        &path,
        &bytes,
        width,
        height,
        image::ExtendedColorType::Rgba8,
    )
    .expect("write preview");
    path
}

/// Copies an image back (tightly packed texels of `T`, which must match the image format).
pub fn read_image<T: bytemuck::Pod + Default + Clone>(ctx: &Arc<Context>, image: &Image) -> Vec<T> {
    let texels = image.width as usize * image.height as usize;
    let bytes = (texels * std::mem::size_of::<T>()) as u64;
    let buffer = Buffer::new(
        ctx,
        "test_readback",
        bytes,
        vk::BufferUsageFlags::TRANSFER_DST,
        MemoryLocation::GpuToCpu,
    )
    .unwrap();
    let mut rec = FrameRecorder::new(ctx, 2).unwrap();
    rec.begin().unwrap();
    rec.copy_image_to_buffer("test_read_image", image, &buffer)
        .unwrap();
    rec.submit_and_wait().unwrap();
    let mut out = vec![T::default(); texels];
    buffer.read_into(&mut out).unwrap();
    out
}

/// Fills an RGBA32F image with `texels` (row-major, `width × height`).
pub fn write_image(ctx: &Arc<Context>, image: &Image, texels: &[[f32; 4]]) {
    assert_eq!(texels.len(), image.width as usize * image.height as usize);
    let buffer = Buffer::with_data(
        ctx,
        "test_upload",
        texels,
        vk::BufferUsageFlags::TRANSFER_SRC,
    )
    .unwrap();
    let mut rec = FrameRecorder::new(ctx, 2).unwrap();
    rec.begin().unwrap();
    rec.copy_buffer_to_image("test_write_image", &buffer, image)
        .unwrap();
    rec.submit_and_wait().unwrap();
}

/// `fovea render` arguments for a small, quick run (40×36, 2 frames, Cartesian, orbiting camera,
/// EXR on, validation on) into `out`; tests change the fields they exercise.
pub fn small_render_args<'a>(
    scene: &'a str,
    out: &'a std::path::Path,
) -> fovea_tools::commands::render::RenderArgs<'a> {
    fovea_tools::commands::render::RenderArgs {
        scene,
        method: "cartesian",
        width: Some(40),
        height: Some(36),
        scale: 0.25,
        headset: "fove0",
        gaze: "sim:3",
        frames: 2,
        out,
        exr: true,
        camera_path: fovea_stage::camera_path::CameraMotion::Orbit,
        seed: 1,
        max_depth: 3,
        exposure: fovea_renderer::passes::exposure::Exposure::Manual(1.0),
        tone: fovea_renderer::passes::tonemap::ToneCurve::Aces,
        overview: false,
        profile: Default::default(),
        debug_views: false,
        denoiser: "none",
        taa: "off",
        device: None,
        validation: true,
        eyes: fovea_tools::commands::setup::Eyes::Left,
        frames_in_flight: 2,
        camera: &fovea_stage::look::NO_CAMERA_FLAGS,
    }
}

/// Mean linear colour of the screen over `frames` real-time frames (independent noise each), with
/// the gaze at `gaze`; each frame's HDR screen goes to `check` first.
pub fn mean_over_frames(
    renderer: &mut fovea_renderer::pipeline::Renderer,
    camera: fovea_renderer::frame::CameraPose,
    gaze: Option<glam::Vec2>,
    frames: u32,
    mut check: impl FnMut(u32, &[[f32; 4]]),
) -> [f64; 3] {
    let mut sum = [0.0; 3];
    let mut hdr = Vec::new();
    for f in 0..frames {
        renderer
            .render_frame(&fovea_renderer::frame::FrameInput::mono(camera, f, gaze).with_hdr(true))
            .unwrap();
        renderer.read_hdr(&mut hdr).unwrap();
        check(f, &hdr);
        let m = mean_rgb(&hdr);
        (0..3).for_each(|c| sum[c] += m[c] / frames as f64);
    }
    sum
}

/// A hash of `v` in [0, 1] (PCG output permutation): deterministic picks in tests.
pub fn unit_hash(v: u32) -> f32 {
    fovea_renderer::sampling::random::pcg_hash(v) as f32 / u32::MAX as f32
}

/// The Cornell box's only emissive material (its ceiling light).
pub fn light_material(scene: &fovea_scene::Scene) -> usize {
    let lights: Vec<usize> = (0..scene.materials.len())
        .filter(|&m| scene.materials[m].emissive.max_element() > 0.0)
        .collect();
    assert_eq!(lights.len(), 1, "the Cornell box has one light material");
    lights[0]
}

/// Overwrites four traced texels of `image` (frame `f` picks which) with a huge, an infinite, a
/// NaN and a negative colour.
pub fn inject_fireflies(ctx: &Arc<Context>, image: &Image, f: u32) {
    let mut texels: Vec<[f32; 4]> = read_image(ctx, image);
    let kept: Vec<usize> = (0..texels.len()).filter(|&i| texels[i][3] > 0.0).collect();
    let pick = |k: u32| kept[(unit_hash(k + 97 * f) * (kept.len() - 1) as f32) as usize];
    texels[pick(1)] = [1e30, 1e30, 1e30, 1.0];
    texels[pick(2)] = [f32::INFINITY, 0.0, 1.0, 1.0];
    texels[pick(3)] = [f32::NAN, 1.0, 1.0, 1.0];
    texels[pick(4)] = [-5.0, 1.0, 1.0, 1.0];
    write_image(ctx, image, &texels);
}

/// The buffers a space's kernels read (`frame`, `sampling`, `sampling_table`) for frame `frame`.
pub struct SpaceBuffers {
    pub frame: Buffer,
    pub sampling: Buffer,
    pub table: Buffer,
    /// Every tile holding a sample (`grid_tiles`).
    pub tiles: fovea_renderer::passes::grid::OwnedTileList,
}

impl SpaceBuffers {
    pub fn new(
        ctx: &Arc<Context>,
        space: &dyn fovea_renderer::sampling::SamplingSpace,
        frame: u32,
        seed: u32,
    ) -> SpaceBuffers {
        let uniform = vk::BufferUsageFlags::UNIFORM_BUFFER;
        let data = fovea_renderer::layouts::FrameData {
            frame: glam::UVec4::new(frame, seed, 3, 0),
            ..Default::default()
        };
        SpaceBuffers {
            frame: Buffer::with_data(ctx, "frame", &[data], uniform).unwrap(),
            sampling: Buffer::with_data(ctx, "sampling", &[space.params()], uniform).unwrap(),
            table: grid_table(ctx, space, None),
            tiles: grid_tiles(ctx, space),
        }
    }
}

impl SpaceBuffers {
    /// These buffers' grid frame over `gbuffer`: `current` this frame's space (as `sampling`
    /// holds it), `previous` the previous frame's (`None`: no history), the camera at the
    /// origin, the scene's `materials`.
    pub fn grid_frame<'a>(
        &'a self,
        gbuffer: &'a fovea_renderer::passes::grid::GBuffer,
        (current, previous): (
            fovea_renderer::layouts::SamplingParams,
            Option<fovea_renderer::layouts::SamplingParams>,
        ),
        materials: &'a Buffer,
    ) -> fovea_renderer::passes::grid::GridFrame<'a> {
        fovea_renderer::passes::grid::GridFrame {
            gbuffer,
            frame_data: &self.frame,
            sampling: &self.sampling,
            current,
            previous,
            sampling_table: &self.table,
            tiles: self.tiles.list(),
            camera_origin: glam::Vec3::ZERO,
            materials,
        }
    }
}

/// A view's sampling table as the renderer keeps it: `current`'s, then `previous`'s (`current`'s
/// again without one) — what the trace and `DenoiseFrame::sampling_table` read.
pub fn grid_table(
    ctx: &Arc<Context>,
    current: &dyn fovea_renderer::sampling::SamplingSpace,
    previous: Option<&dyn fovea_renderer::sampling::SamplingSpace>,
) -> Buffer {
    let mut rows = current.sampling_table();
    rows.extend(previous.unwrap_or(current).sampling_table());
    Buffer::texels(ctx, "sampling_table", &rows).unwrap()
}

/// `space`'s tile list without culling: every tile where a texel holds a sample is live, as a
/// synthetic G-buffer may place a sample in any of them (`DenoiseFrame::tiles`).
pub fn grid_tiles(
    ctx: &Arc<Context>,
    space: &dyn fovea_renderer::sampling::SamplingSpace,
) -> fovea_renderer::passes::grid::OwnedTileList {
    fovea_renderer::passes::grid::OwnedTileList::new(ctx, space, false).unwrap()
}

/// One texel as the GPU's space sees it (passes/space_probe): its sample's screen position at
/// jitter (½, ½), and the samples it traces per frame.
pub struct ProbedTexel {
    pub position: Option<glam::Vec2>,
    pub samples: u32,
}

/// Every texel of `space`'s grid through its kernel variant of passes/space_probe (row-major).
pub fn probe(
    ctx: &Arc<Context>,
    space: &dyn fovea_renderer::sampling::SamplingSpace,
    frame: u32,
    seed: u32,
) -> Vec<ProbedTexel> {
    use fovea_renderer::graph::{read_buffer, read_texels, write_buffer};
    let grid = space.grid_size();
    let pipeline = fovea_renderer::vk::ComputePipeline::new(
        ctx,
        &format!("passes/space_probe.{}", space.trace_variant()),
        0,
    )
    .unwrap();
    let buffers = SpaceBuffers::new(ctx, space, frame, seed);
    let out = Buffer::new(
        ctx,
        "probe_out",
        grid.x as u64 * grid.y as u64 * 16,
        vk::BufferUsageFlags::STORAGE_BUFFER,
        MemoryLocation::GpuToCpu,
    )
    .unwrap();
    let mut rec = FrameRecorder::new(ctx, 2).unwrap();
    rec.begin().unwrap();
    let binds = [
        read_buffer("frame", &buffers.frame),
        read_buffer("sampling", &buffers.sampling),
        read_texels("sampling_table", &buffers.table),
        write_buffer("mapped", &out),
    ];
    rec.dispatch("space_probe", &pipeline, &binds, &[], [grid.x, grid.y, 1])
        .unwrap();
    rec.submit_and_wait().unwrap();
    let got: Vec<[f32; 4]> = out.read().unwrap();
    got.iter()
        .map(|o| ProbedTexel {
            position: (o[2] > 0.0).then(|| glam::Vec2::new(o[0], o[1])),
            samples: o[3] as u32,
        })
        .collect()
}

/// `fovea render --method METHOD` of the Cornell box at 64×72 (`small_render_args` otherwise,
/// The default render profile with the paper's foveated blur on (σ 6.8 px at 30° for the FOVE 0
/// eye; the product default is off), for tests of the way back's blur passes.
pub fn profile_with_blur() -> fovea_tools::render_profile::RenderProfile {
    let mut profile = fovea_tools::render_profile::RenderProfile::default();
    profile.blur.sigma_at_30 = fovea_renderer::way_back::blur::FOVE_SIGMA_AT_30;
    profile
}

/// with `profile`): its report.json (the output folder is removed).
pub fn render_report(
    method: &str,
    profile: fovea_tools::render_profile::RenderProfile,
) -> serde_json::Value {
    let out = artifacts_dir().join(format!("{method}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let args = fovea_tools::commands::render::RenderArgs {
        method,
        width: Some(64),
        height: Some(72),
        profile,
        ..small_render_args("cornell-box", &out)
    };
    fovea_tools::commands::render::run(&args).unwrap();
    let report =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let _ = std::fs::remove_dir_all(&out);
    report
}

/// `Renderer::new` refuses SVGF on `space`, naming both.
pub fn assert_refuses_svgf(
    ctx: &Arc<Context>,
    scene: &fovea_scene::Scene,
    space: Box<dyn fovea_renderer::sampling::SamplingSpace>,
) {
    use fovea_renderer::passes::denoise::{svgf::SvgfSettings, DenoiserSettings};
    let name = space.name();
    let svgf = fovea_renderer::frame::RenderSettings {
        denoiser: DenoiserSettings::Svgf(SvgfSettings::default()),
        ..Default::default()
    };
    let err = fovea_renderer::pipeline::Renderer::new(ctx, scene, space, svgf)
        .err()
        .expect("refused")
        .to_string();
    assert!(err.contains("svgf") && err.contains(name), "{err}");
}

/// The mean colour of `renderer`'s frames (`frames` of them, gaze `gaze`, each through `check`)
/// within 8 % per channel of one sample per pixel's on the same screen and camera.
pub fn assert_mean_like_cartesian(
    ctx: &Arc<Context>,
    scene: &fovea_scene::Scene,
    renderer: &mut fovea_renderer::pipeline::Renderer,
    camera: fovea_renderer::frame::CameraPose,
    gaze: glam::Vec2,
    frames: u32,
    mut check: impl FnMut(u32, &[[f32; 4]]),
) {
    use fovea_renderer::frame::RenderSettings;
    use fovea_renderer::pipeline::Renderer;
    let name = renderer.space().name();
    let screen = renderer.space().screen_size();
    let a = mean_over_frames(renderer, camera, Some(gaze), frames, &mut check);
    let mut cartesian = Renderer::new(
        ctx,
        scene,
        Box::new(fovea_renderer::sampling::Cartesian::new(screen)),
        RenderSettings::default(),
    )
    .unwrap();
    let b = mean_over_frames(&mut cartesian, camera, Some(gaze), frames, &mut check);
    for c in 0..3 {
        assert!(
            (a[c] / b[c] - 1.0).abs() < 0.08,
            "channel {c}: {name} {} vs one per pixel {}",
            a[c],
            b[c]
        );
    }
}
