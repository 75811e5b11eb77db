//! The engine's plumbing on the device: the validation counter, struct layouts shared with GLSL,
//! resource lifetimes and binding errors.

use ash::vk;
use fovea_renderer::frame::RenderSettings;
use fovea_renderer::graph::{read_image, FrameRecorder};
use fovea_renderer::layouts::STRUCT_LAYOUTS;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::Cartesian;
use fovea_renderer::vk::{Buffer, ComputePipeline, Image};
use fovea_renderer::Error;
use fovea_tests::{assert_clean, gpu};

#[test]
fn validation_counter_catches_a_deliberate_misuse() {
    let ctx = gpu();
    assert_eq!(ctx.validation.problems(), 0);
    // A zero-sized buffer violates VUID-VkBufferCreateInfo-size-00912.
    let info = vk::BufferCreateInfo::default()
        .size(0)
        .usage(vk::BufferUsageFlags::STORAGE_BUFFER);
    if let Ok(buffer) = unsafe { ctx.device.create_buffer(&info, None) } {
        unsafe { ctx.device.destroy_buffer(buffer, None) };
    }
    assert!(ctx.validation.problems() >= 1, "the misuse went unnoticed");
    assert!(
        ctx.validation
            .messages()
            .iter()
            .any(|m| m.contains("00912")),
        "{:?}",
        ctx.validation.messages()
    );
}

/// Every field of every shared struct, read on the device through the GLSL layout, lands at the
/// offset Rust gives it (the wgpu-style layout proof).
#[test]
fn shared_struct_layouts_match_on_the_device() {
    let ctx = gpu();
    let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
    let pattern = |word: usize| 0x4000_0000u32 | word as u32; // normal floats: no denormal flushing
    let mut recorder = FrameRecorder::new(&ctx, 64).unwrap();
    for layout in STRUCT_LAYOUTS {
        let words: Vec<u32> = (0..layout.size / 4).map(pattern).collect();
        let total: usize = layout.fields.iter().map(|f| f.words).sum();
        let src = Buffer::with_data(&ctx, "probe_src", &words, storage).unwrap();
        let dst = Buffer::new(
            &ctx,
            "probe_dst",
            (total * 4) as u64,
            storage,
            gpu_allocator::MemoryLocation::GpuToCpu,
        )
        .unwrap();
        let pipeline =
            ComputePipeline::new(&ctx, &format!("layout_probe/{}", layout.name), 0).unwrap();
        recorder.begin().unwrap();
        let binds = [
            fovea_renderer::graph::read_buffer("src", &src),
            fovea_renderer::graph::write_buffer("dst", &dst),
        ];
        recorder
            .dispatch("layout_probe", &pipeline, &binds, &[], [1, 1, 1])
            .unwrap();
        recorder.submit_and_wait().unwrap();
        let got: Vec<u32> = dst.read().unwrap();
        let expected: Vec<u32> = layout
            .fields
            .iter()
            .flat_map(|f| (0..f.words).map(move |c| pattern(f.offset / 4 + c)))
            .collect();
        assert_eq!(
            got[..total],
            expected[..],
            "struct {} disagrees between Rust and GLSL",
            layout.name
        );
    }
    assert!(STRUCT_LAYOUTS.len() >= 10, "all shared structs are probed");
    assert_clean(&ctx);
}

#[test]
fn every_allocation_is_freed_when_resources_drop() {
    let ctx = gpu();
    let scene = fovea_tests::scenes::furnace(0.5, 1.0);
    {
        let space = Box::new(Cartesian::new(glam::UVec2::new(16, 16)));
        let _renderer = Renderer::new(&ctx, &scene, space, RenderSettings::default()).unwrap();
        assert!(ctx.live_allocations() > 10);
    }
    assert_eq!(ctx.live_allocations(), 0);
    assert_clean(&ctx);
}

#[test]
fn binding_mistakes_name_the_pass_and_the_binding() {
    let ctx = gpu();
    let pipeline = ComputePipeline::new(&ctx, "passes/accumulate", 16).unwrap();
    let image = Image::new(&ctx, "img", 4, 4, vk::Format::R32G32B32A32_SFLOAT).unwrap();
    let mut recorder = FrameRecorder::new(&ctx, 4).unwrap();
    recorder.begin().unwrap();
    let err = recorder
        .dispatch(
            "accumulate",
            &pipeline,
            &[read_image("sample_color", &image)],
            &[0; 16],
            [4, 4, 1],
        )
        .unwrap_err();
    let text = err.to_string();
    assert!(matches!(err, Error::Binding { .. }), "{text}");
    assert!(
        text.contains("accumulate") && text.contains("'accum'"),
        "{text}"
    );
    let wrong_push = recorder
        .dispatch("accumulate", &pipeline, &[], &[0; 4], [4, 4, 1])
        .unwrap_err()
        .to_string();
    assert!(wrong_push.contains("push-constant"), "{wrong_push}");
    recorder.submit_and_wait().unwrap();
    assert_clean(&ctx);
}

#[test]
fn pipeline_creation_checks_the_params_struct_size_and_shader_name() {
    let ctx = gpu();
    let err = ComputePipeline::new(&ctx, "passes/tonemap.own", 4)
        .err()
        .expect("size mismatch")
        .to_string();
    assert!(err.contains("16") && err.contains("4"), "{err}");
    let err = ComputePipeline::new(&ctx, "passes/no_such_pass", 0)
        .err()
        .expect("unknown shader")
        .to_string();
    assert!(err.contains("no_such_pass"), "{err}");
    assert_clean(&ctx);
}
