//! A 1,000-frame soak of the real-time loop as `fovea render` drives it (tools/src/commands/
//! render.rs: `Setup`'s frame inputs with the simulated gaze and the camera path, two frames in
//! flight, each retired frame's counts, timings and LDR image read back), at 64×72, Visual-Polar +
//! SVGF, validation on. Nothing may grow in the steady state: GPU bytes and live allocations are
//! the same at frame 1,000 as at frame 100, and the process' resident memory within a few MiB.

use fovea_renderer::gpu_scene::GpuScene;
use fovea_renderer::pipeline::Renderer;
use fovea_tests::{assert_clean, gpu};
use fovea_tools::commands::setup::Setup;
use std::time::Instant;

const FRAMES: u32 = 1000;
/// The steady state starts well before this (histories full, every pool warm).
const CHECKPOINT: u32 = 100;
/// Resident memory may move by this much (allocator and driver caches settle, the loader's
/// buffers); a per-frame leak of even 4 KiB would add 3.5 MiB over the 900 frames.
const RSS_SLACK_BYTES: i64 = 2 << 20;

/// This process' resident set (`VmRSS` of /proc/self/status, in bytes).
fn rss_bytes() -> i64 {
    let status = std::fs::read_to_string("/proc/self/status").expect("/proc/self/status");
    let kb = status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .expect("VmRSS line");
    kb.trim()
        .trim_end_matches("kB")
        .trim()
        .parse::<i64>()
        .expect("VmRSS in kB")
        * 1024
}

#[derive(Debug, PartialEq)]
struct Memory {
    gpu_bytes: i64,
    allocations: i64,
    rss: i64,
}

#[test]
fn a_thousand_frames_hold_gpu_and_host_memory_flat_without_validation_messages() {
    let ctx = gpu();
    let out = fovea_tests::artifacts_dir().join("soak-unused");
    let mut args = fovea_tests::small_render_args("cornell-box", &out);
    (
        args.method,
        args.denoiser,
        args.width,
        args.height,
        args.gaze,
    ) = ("vp", "svgf", Some(64), Some(72), "sim:1");
    (args.frames, args.exr, args.camera_path) =
        (FRAMES, false, fovea_stage::camera_path::CameraMotion::Orbit);
    let mut setup = Setup::new(&args, FRAMES).unwrap();
    let spaces = setup.spaces(args.method, &args.profile).unwrap();
    let scene = GpuScene::upload(&ctx, &setup.scene).unwrap();
    let mut renderer =
        Renderer::with_views(&ctx, scene, spaces, setup.settings, args.frames_in_flight).unwrap();

    let memory = || Memory {
        gpu_bytes: ctx.allocated_bytes(),
        allocations: ctx.live_allocations(),
        rss: rss_bytes(),
    };
    let (mut ldr, mut retired, mut samples, mut lit) = (Vec::new(), 0u64, 0u64, 0u64);
    let mut at_checkpoint = None;
    let started = Instant::now();
    for frame in 0..FRAMES {
        let (input, _) = setup.frame_input(frame).unwrap();
        if let Some(done) = renderer.retire_next().unwrap() {
            assert!(!renderer.frame_timings(done).unwrap().is_empty());
            samples += renderer.frame_stats(done, 0).unwrap().samples_traced;
            renderer.read_view_ldr(done, 0, &mut ldr).unwrap();
            lit += u64::from(ldr.chunks(4).any(|p| p[..3].iter().any(|&c| c > 16)));
            retired += 1;
        }
        renderer.submit(&input, None).unwrap();
        if frame + 1 == CHECKPOINT {
            at_checkpoint = Some(memory());
        }
    }
    let at_end = memory();
    renderer.finish().unwrap();
    let seconds = started.elapsed().as_secs_f64();
    let before = at_checkpoint.unwrap();
    println!(
        "soak: {FRAMES} frames of 64×72 VP + SVGF in {seconds:.1} s ({:.1} ms per frame); frame {CHECKPOINT}: {before:?}, frame {FRAMES}: {at_end:?}",
        seconds * 1e3 / FRAMES as f64
    );
    assert_clean(&ctx);
    assert_eq!(
        retired,
        (FRAMES - 2) as u64,
        "every frame but the two in flight was retired in the loop"
    );
    assert_eq!(lit, retired, "every frame shows the lit Cornell box");
    assert!(
        samples > 1000 * retired,
        "{samples} samples over {retired} frames"
    );
    assert_eq!(
        (at_end.gpu_bytes, at_end.allocations),
        (before.gpu_bytes, before.allocations),
        "GPU memory grew between frame {CHECKPOINT} and {FRAMES}"
    );
    let grown = at_end.rss - before.rss;
    assert!(
        grown <= RSS_SLACK_BYTES,
        "resident memory grew by {} KiB between frame {CHECKPOINT} and {FRAMES}",
        grown / 1024
    );
}
