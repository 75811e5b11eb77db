//! No host (heap) allocations in the render loop: after the first
//! frame has sized everything, `Renderer::render_frame` allocates nothing on the CPU side, for
//! Cartesian and Visual-Polar frames with a moving gaze, with and without a denoiser and TAA.
//! A counting global allocator (this test binary only) counts the allocations made by this
//! thread while a frame is recorded, submitted and read back.

use fovea_renderer::frame::{CameraPose, FrameInput, RenderSettings};
use fovea_renderer::passes::denoise::DenoiserSettings;
use fovea_renderer::passes::taa::TaaMode;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::{
    Cartesian, Eccentricity, FovTangents, SamplingSpace, VisualPolar, VisualPolarParams, VpLayout,
};
use fovea_tests::{assert_clean, gpu};
use glam::{UVec2, Vec2};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct CountingAllocator;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

fn note_allocation() {
    // try_with: the thread-local may already be gone while a thread shuts down.
    let _ = COUNTING.try_with(|on| {
        if on.get() {
            let _ = ALLOCATIONS.try_with(|n| n.set(n.get() + 1));
        }
    });
}

unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note_allocation();
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note_allocation();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note_allocation();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

/// Allocations made by this thread while `f` runs.
fn allocations_during(f: impl FnOnce()) -> u64 {
    ALLOCATIONS.with(|n| n.set(0));
    COUNTING.with(|on| on.set(true));
    f();
    COUNTING.with(|on| on.set(false));
    ALLOCATIONS.with(|n| n.get())
}

const SCREEN: UVec2 = UVec2::new(64, 72);
const WARM_UP_FRAMES: u32 = 1;
const COUNTED_FRAMES: u32 = 4;

#[test]
fn render_loop_makes_no_host_allocations() {
    let ctx = gpu();
    let scene = fovea_tests::owned_scene("cornell-box");
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], SCREEN.x, SCREEN.y);
    let vp_with = |params: VisualPolarParams| -> Box<dyn SamplingSpace> {
        Box::new(VisualPolar::new(SCREEN, SCREEN.as_vec2() * 0.5, params).unwrap())
    };
    let vp = || vp_with(VisualPolarParams::default());
    let clipped = VisualPolarParams {
        layout: VpLayout::ScreenClipped,
        ..Default::default()
    };
    let screen_aware = VisualPolarParams {
        layout: VpLayout::ScreenAware,
        ..Default::default()
    };
    let fove0 = FovTangents::from_angles_deg(-45.0, 45.0, -48.4, 48.4);
    let headset = VisualPolarParams {
        eccentricity: Eccentricity::Headset(fove0),
        ..Default::default()
    };
    let cases: [(&str, Box<dyn SamplingSpace>, &str, &str); 8] = [
        ("cartesian", Box::new(Cartesian::new(SCREEN)), "none", "off"),
        ("vp", vp(), "none", "off"),
        ("vp screen-clipped", vp_with(clipped), "none", "off"),
        (
            "vp screen-aware + svgf",
            vp_with(screen_aware),
            "svgf",
            "off",
        ),
        ("vp headset axis", vp_with(headset), "none", "off"),
        ("vp svgf + screen TAA", vp(), "svgf", "screen"),
        ("vp asvgf + grid TAA", vp(), "asvgf", "vp"),
        ("vp bmfr", vp(), "bmfr", "off"),
    ];
    let mut failures = Vec::new();
    for (name, space, denoiser, taa) in cases {
        let settings = RenderSettings {
            denoiser: DenoiserSettings::parse(denoiser).unwrap(),
            taa: TaaMode::parse(taa).unwrap(),
            ..Default::default()
        };
        let mut renderer = Renderer::new(&ctx, &scene, space, settings).unwrap();
        let mut ldr = Vec::new();
        let mut counts = Vec::new();
        for frame in 0..WARM_UP_FRAMES + COUNTED_FRAMES {
            // The gaze moves every frame, as it does on a headset.
            let gaze =
                SCREEN.as_vec2() * Vec2::new(0.3 + 0.1 * frame as f32, 0.6 - 0.05 * frame as f32);
            let input = FrameInput::mono(camera, frame, Some(gaze));
            let n = allocations_during(|| {
                renderer.render_frame(&input).unwrap();
                renderer.read_ldr(&mut ldr).unwrap();
            });
            counts.push(n);
        }
        println!("{name}: host allocations per frame {counts:?} (frame 0 sizes things)");
        if counts[WARM_UP_FRAMES as usize..].iter().any(|&n| n != 0) {
            failures.push(format!("{name}: {counts:?}"));
        }
    }
    assert!(
        failures.is_empty(),
        "the render loop allocates on the host:\n{}",
        failures.join("\n")
    );
    assert_clean(&ctx);
}
