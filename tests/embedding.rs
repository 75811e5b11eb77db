//! A program embedding fovea with its libraries alone (`renderer/stage/examples/render_frame.rs`,
//! compiled in here as a module) renders what `fovea render` renders with the same settings: the
//! same scene, light, frusta, gaze, sampling, filters and exposure, byte for byte in both eyes.

#[path = "../renderer/stage/examples/render_frame.rs"]
mod render_frame;

use fovea_tools::commands::render::{run as render, RenderArgs};
use fovea_tools::commands::setup::Eyes;

#[test]
fn the_library_alone_renders_what_the_command_line_renders() {
    let (width, height, frames) = (128, 144, 4);
    let rendered = render_frame::render(&render_frame::Options {
        scene: "cornell-box",
        width,
        height,
        frames,
        gaze: "sim:1",
    })
    .unwrap();
    fovea_tests::assert_clean(&rendered.ctx);

    let out = fovea_tests::artifacts_dir().join(format!("embedding-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    render(&RenderArgs {
        method: "vp",
        width: Some(width),
        height: Some(height),
        scale: 1.0,
        gaze: "sim:1",
        frames,
        exr: false,
        camera_path: fovea_stage::camera_path::CameraMotion::Still,
        exposure: fovea_renderer::passes::exposure::Exposure::auto(),
        denoiser: "bmfr",
        taa: "vp",
        eyes: Eyes::Both,
        ..fovea_tests::small_render_args("cornell-box", &out)
    })
    .unwrap();

    for (view, eye) in ["left", "right"].iter().enumerate() {
        let file = out.join(format!("frame_{:04}_{eye}.png", frames - 1));
        let cli = image::open(&file).unwrap().to_rgba8().into_raw();
        let library = &rendered.eyes[view];
        assert_eq!(cli.len(), library.len(), "{eye} eye: image sizes");
        let differing = cli.iter().zip(library).filter(|(a, b)| a != b).count();
        assert_eq!(
            differing,
            0,
            "{eye} eye: {differing} of {} bytes differ from {}",
            cli.len(),
            file.display()
        );
        let mean = library.iter().map(|&v| v as f64).sum::<f64>() / library.len() as f64;
        assert!(
            (40.0..220.0).contains(&mean),
            "{eye} eye: the Cornell box is displayed (mean byte {mean:.1})"
        );
    }
    assert_ne!(
        rendered.eyes[0], rendered.eyes[1],
        "the eyes see the scene from their own places"
    );
}
