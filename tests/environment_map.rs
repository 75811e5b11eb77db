//! HDR environment maps: the GLSL mapping and sampler against their Rust twin (point by point on
//! the device), importance sampling against BRDF-only sampling of a peaked map (same mean, lower
//! variance, both on the analytic irradiance), and the loader's errors, each naming the file.

use fovea_renderer::environment::gpu_texels;
use fovea_renderer::frame::{CameraPose, EnvironmentSampling, RenderSettings};
use fovea_renderer::graph::{read_buffer, write_buffer, FrameRecorder};
use fovea_renderer::layouts::EnvProbePush;
use fovea_renderer::passes::tonemap::ToneCurve;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::Cartesian;
use fovea_renderer::vk::{Buffer, ComputePipeline};
use fovea_scene::environment::{direction_to_uv, pdf_solid_angle, texel_index, uv_to_direction};
use fovea_scene::{Camera, EnvironmentDistribution, EnvironmentMap, Material, Scene};
use fovea_tests::scenes::{add_floor, lambert};
use fovea_tests::{assert_clean, gpu};
use glam::{UVec2, UVec4, Vec2, Vec3, Vec4};
use std::f32::consts::PI;
use std::path::{Path, PathBuf};

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / 16777216.0
    }
}

/// Dim sky with a small bright "sun" of 2×2 texels at 40° from the zenith: a peaked map.
fn peaked_map(rotation_deg: f32) -> EnvironmentMap {
    let (w, h) = (64u32, 32u32);
    let texels = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            if (20..22).contains(&x) && (7..9).contains(&y) {
                Vec3::new(3000.0, 2800.0, 2500.0)
            } else {
                Vec3::new(0.05, 0.07, 0.1) * (1.0 + y as f32 / h as f32)
            }
        })
        .collect();
    let mut m = EnvironmentMap::new(w, h, texels).unwrap();
    m.rotation = rotation_deg.to_radians();
    m.intensity = 0.5;
    m
}

#[test]
fn rust_and_glsl_environment_mapping_and_sampling_agree() {
    let ctx = gpu();
    let map = peaked_map(123.0);
    let dist = EnvironmentDistribution::new(&map).unwrap();
    let n = 4096usize;
    let mut rng = Rng(5);
    let input: Vec<Vec4> = (0..n)
        .map(|_| Vec4::new(rng.next(), rng.next(), rng.next(), rng.next()))
        .collect();
    // The same four numbers serve as a direction (xyz − ½, normalised in the shader) and as the sampler's input.
    let dirs: Vec<Vec3> = input
        .iter()
        .map(|q| (q.truncate() - 0.5).normalize())
        .collect();
    let storage = ash::vk::BufferUsageFlags::STORAGE_BUFFER;
    let texels = Buffer::with_data(&ctx, "environment", &gpu_texels(&map, &dist), storage).unwrap();
    let points = Buffer::with_data(
        &ctx,
        "points",
        &input
            .iter()
            .map(|q| (q.truncate() - 0.5).extend(q.w))
            .collect::<Vec<_>>(),
        storage,
    )
    .unwrap();
    let sample_points = Buffer::with_data(&ctx, "sample_points", &input, storage).unwrap();
    let out = |name| {
        Buffer::new(
            &ctx,
            name,
            (n * 32) as u64,
            storage,
            gpu_allocator::MemoryLocation::GpuToCpu,
        )
        .unwrap()
    };
    let (mapped, sampled) = (out("mapped"), out("sampled"));
    let pipeline = ComputePipeline::new(
        &ctx,
        "passes/env_probe",
        std::mem::size_of::<EnvProbePush>() as u32,
    )
    .unwrap();
    let (s, c) = map.rotation.sin_cos();
    let push = EnvProbePush {
        environment: Vec4::new(c, s, map.intensity, 1.0),
        environment_map: UVec4::new(map.width, map.height, 1, 0),
        config: UVec4::new(n as u32, 0, 0, 0),
    };
    let mut rec = FrameRecorder::new(&ctx, 4).unwrap();
    rec.begin().unwrap();
    for (pts, o) in [(&points, &mapped), (&sample_points, &sampled)] {
        let binds = [
            read_buffer("environment", &texels),
            read_buffer("points", pts),
            write_buffer("mapped", o),
        ];
        rec.dispatch(
            "env_probe",
            &pipeline,
            &binds,
            bytemuck::bytes_of(&push),
            [n as u32, 1, 1],
        )
        .unwrap();
    }
    rec.submit_and_wait().unwrap();
    let (lookups, samples): (Vec<Vec4>, Vec<Vec4>) =
        (mapped.read().unwrap(), sampled.read().unwrap());
    // Direction → texel and pdf (out[2i]); a texel edge may round either way, so count those.
    let (mut edge, mut worst_pdf, mut worst_uv) = (0, 0f32, 0f32);
    for (i, d) in dirs.iter().enumerate() {
        let g = lookups[2 * i];
        let uv = direction_to_uv(map.to_local(*d));
        worst_uv = worst_uv.max(
            (Vec2::new(g.z, g.w) - uv)
                .abs()
                .max_element()
                .min(1.0 - (g.z - uv.x).abs()),
        );
        if g.x as u32 != texel_index(uv, map.width, map.height) {
            edge += 1;
            continue;
        }
        let want = dist.pdf(map.to_local(*d));
        worst_pdf = worst_pdf.max((g.y - want).abs() / want);
    }
    // Four numbers → direction and pdf (out[2i + 1]): the texel choice is exact arithmetic in both.
    let mut worst_dir = 0f32;
    for (i, q) in input.iter().enumerate() {
        let g = samples[2 * i + 1];
        let (texel, uv) = dist.sample_uv(q.to_array());
        let want_dir = map.to_world(uv_to_direction(uv));
        let want_pdf = pdf_solid_angle(dist.alias[texel as usize].pdf, uv.y, map.width, map.height);
        worst_dir = worst_dir.max((g.truncate() - want_dir).length());
        worst_pdf = worst_pdf.max((g.w - want_pdf).abs() / want_pdf);
    }
    println!("uv {worst_uv:.2e}, direction {worst_dir:.2e}, pdf (relative) {worst_pdf:.2e}, texel-edge roundings {edge}/{n}");
    // GLSL's atan/acos are not correctly rounded (lavapipe: ~5e-5 in v, measured), which moves a
    // few directions across a texel edge and the pdf's sin θ by as much near the poles.
    assert!(
        worst_uv < 2e-4 && worst_dir < 1e-5 && worst_pdf < 2e-3 && edge <= n / 500,
        "Rust and GLSL disagree"
    );
    assert_clean(&ctx);
}

/// ∫ L cos θ dω over the upper hemisphere for a map whose every texel is piecewise constant
/// (nearest lookup): each row band's ∫ cos θ sin θ dθ in closed form. Rotation does not matter.
fn irradiance_from_above(map: &EnvironmentMap) -> f64 {
    let (w, h) = (map.width as usize, map.height as usize);
    let mut e = 0.0;
    for y in 0..h {
        let (t0, t1) = (
            PI as f64 * y as f64 / h as f64,
            (PI as f64 * (y + 1) as f64 / h as f64).min(PI as f64 / 2.0),
        );
        if t0 >= PI as f64 / 2.0 {
            break;
        }
        let band = 2.0 * PI as f64 / w as f64 * (t1.sin().powi(2) - t0.sin().powi(2)) / 2.0;
        e += map.texels[y * w..(y + 1) * w]
            .iter()
            .map(|t| t.y as f64)
            .sum::<f64>()
            * band;
    }
    e * map.intensity as f64
}

/// 1 spp of an upward white Lambertian plane lit only by `map`: every pixel is one independent
/// estimate of the same radiance (the environment is at infinity, nothing occludes).
fn plane_samples(
    ctx: &std::sync::Arc<fovea_renderer::vk::Context>,
    map: &EnvironmentMap,
    material: &Material,
    sampling: EnvironmentSampling,
    seed: u32,
) -> Vec<f64> {
    let mut scene = Scene {
        materials: vec![material.clone()],
        mesh_names: vec!["floor".into()],
        environment: Some(map.clone()),
        ..Default::default()
    };
    add_floor(&mut scene, 100.0, 0);
    // Looking down at 60° so that a glossy plane reflects part of the sky toward the camera.
    let camera = Camera::look_at(
        Vec3::new(0.0, 2.0, 0.0),
        Vec3::new(0.0, 0.0, -1.15),
        0.5,
        "down",
    );
    let size = UVec2::new(64, 72);
    let settings = RenderSettings {
        seed,
        tone_curve: ToneCurve::Clamp,
        environment_sampling: sampling,
        ..Default::default()
    };
    let mut r = Renderer::new(ctx, &scene, Box::new(Cartesian::new(size)), settings).unwrap();
    let img = r
        .render_reference(
            &CameraPose::from_scene_camera(&camera, size.x, size.y),
            1,
            2,
            |_| {},
        )
        .unwrap();
    img.iter().map(|p| p[1] as f64).collect()
}

fn mean_var(x: &[f64]) -> (f64, f64) {
    let m = x.iter().sum::<f64>() / x.len() as f64;
    (
        m,
        x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (x.len() - 1) as f64,
    )
}

#[test]
fn importance_sampling_agrees_with_brdf_sampling_and_has_lower_variance() {
    let ctx = gpu();
    let map = peaked_map(-70.0);
    let expected = irradiance_from_above(&map) / PI as f64;
    let mut is = Vec::new();
    let mut brdf = Vec::new();
    let white = lambert(1.0, 0.0);
    for seed in 1..=3 {
        is.extend(plane_samples(
            &ctx,
            &map,
            &white,
            EnvironmentSampling::ImportanceMis,
            seed,
        ));
        brdf.extend(plane_samples(
            &ctx,
            &map,
            &white,
            EnvironmentSampling::BrdfOnly,
            seed,
        ));
    }
    let ((m_is, v_is), (m_b, v_b)) = (mean_var(&is), mean_var(&brdf));
    let n = is.len() as f64;
    let z = (m_is - m_b) / (v_is / n + v_b / n).sqrt();
    let z_is = (m_is - expected) / (v_is / n).sqrt();
    let z_b = (m_b - expected) / (v_b / n).sqrt();
    println!(
        "analytic {expected:.4}; importance + MIS {m_is:.4} (variance {v_is:.4}); BRDF only {m_b:.4} (variance {v_b:.4}); \
         z = {z:.2} between them, {z_is:.2} / {z_b:.2} against the analytic value; variance ratio {:.1}× over {n} samples",
        v_b / v_is
    );
    assert!(
        z.abs() < 4.0 && z_is.abs() < 4.0 && z_b.abs() < 4.0,
        "means disagree"
    );
    assert!(
        v_is * 10.0 < v_b,
        "importance sampling should cut the variance of a peaked map at least tenfold"
    );
    assert_clean(&ctx);
}

/// The same comparison on a rough metal (GGX lobe, no closed form here): MIS weights that did
/// not match the BRDF sampler's density would bias one estimator against the other. Pixels see the
/// plane at different angles (different expected values), so each pixel's variance comes from its
/// own 8 seeds, and the image means are z-tested with those variances summed.
#[test]
fn importance_sampling_agrees_with_brdf_sampling_on_a_glossy_metal() {
    let ctx = gpu();
    let map = peaked_map(20.0);
    let metal = Material {
        base_color: Vec4::new(0.9, 0.8, 0.7, 1.0),
        metallic: 1.0,
        roughness: 0.4,
        ..Default::default()
    };
    let runs = |sampling| {
        (1..=8)
            .map(|seed| plane_samples(&ctx, &map, &metal, sampling, seed))
            .collect::<Vec<_>>()
    };
    let (is, brdf) = (
        runs(EnvironmentSampling::ImportanceMis),
        runs(EnvironmentSampling::BrdfOnly),
    );
    let pixels = is[0].len();
    let stats =
        |runs: &[Vec<f64>], i: usize| mean_var(&runs.iter().map(|r| r[i]).collect::<Vec<_>>());
    let (mut sum_is, mut sum_b, mut var_is, mut var_b) = (0.0, 0.0, 0.0, 0.0);
    for i in 0..pixels {
        let ((m_is, v_is), (m_b, v_b)) = (stats(&is, i), stats(&brdf, i));
        sum_is += m_is;
        sum_b += m_b;
        var_is += v_is;
        var_b += v_b;
    }
    // The image means: every sample is independent, so their variances add.
    let k = is.len() as f64;
    let n = pixels as f64;
    let z = (sum_is / n - sum_b / n) / ((var_is + var_b) / (k * n * n)).sqrt();
    println!(
        "glossy metal: importance + MIS {:.4}, BRDF only {:.4}, z = {z:.2}; mean per-sample variance {:.4} vs {:.4} ({:.1}× lower)",
        sum_is / n,
        sum_b / n,
        var_is / n,
        var_b / n,
        var_b / var_is
    );
    assert!(z.abs() < 4.0, "means disagree");
    assert!(var_is < var_b, "MIS should not add variance here");
    assert_clean(&ctx);
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = fovea_tests::artifacts_dir().join(format!("envmap-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write_exr(
    path: &Path,
    width: usize,
    height: usize,
    texel: impl Fn(usize, usize) -> [f32; 3] + Sync,
) {
    use exr::prelude::*;
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let t = texel(x, y);
        (t[0], t[1], t[2])
    });
    Image::from_channels((width, height), channels)
        .write()
        .to_file(path)
        .unwrap();
}

fn load_error(path: &Path) -> String {
    let err = fovea_stage::env_map::load(path, 0.0, 1.0).unwrap_err();
    let text = format!("{err:#}");
    assert!(
        text.contains(&path.display().to_string()),
        "the error does not name the file: {text}"
    );
    text
}

#[test]
fn valid_exr_and_hdr_maps_load_with_their_texels() {
    let dir = temp_dir("valid");
    let exr = dir.join("grad.exr");
    write_exr(&exr, 8, 4, |x, y| [x as f32, y as f32, 0.5]);
    let m = fovea_stage::env_map::load(&exr, 90.0, 2.0).unwrap();
    assert_eq!(
        (m.width, m.height, m.texels[3 * 8 + 5]),
        (8, 4, Vec3::new(5.0, 3.0, 0.5))
    );
    assert_eq!((m.rotation, m.intensity), (90f32.to_radians(), 2.0));
    let hdr = dir.join("grad.HDR");
    let pixels: Vec<image::Rgb<f32>> = (0..8 * 4)
        .map(|i| image::Rgb([(i % 8) as f32, 1.0, 0.25]))
        .collect();
    image::codecs::hdr::HdrEncoder::new(std::fs::File::create(&hdr).unwrap())
        .encode(&pixels, 8, 4)
        .unwrap();
    let m = fovea_stage::env_map::load(&hdr, 0.0, 1.0).unwrap();
    // RGBE keeps 8 mantissa bits: 5 and 0.25 are exact.
    assert_eq!(
        (m.width, m.height, m.texels[8 + 5]),
        (8, 4, Vec3::new(5.0, 1.0, 0.25))
    );
}

#[test]
fn a_missing_map_is_named() {
    let e = load_error(&temp_dir("missing").join("nowhere.exr"));
    assert!(e.contains("No such file"), "{e}");
}

#[test]
fn a_folder_is_not_a_map() {
    let dir = temp_dir("folder");
    let e = load_error(&dir);
    assert!(e.contains("not a regular file"), "{e}");
}

#[test]
fn other_formats_are_refused() {
    let path = temp_dir("format").join("sky.png");
    std::fs::write(&path, b"\x89PNG\r\n\x1a\n").unwrap();
    let e = load_error(&path);
    assert!(
        e.contains("unsupported format") && e.contains(".exr") && e.contains(".hdr"),
        "{e}"
    );
}

#[test]
fn files_that_do_not_decode_are_refused() {
    let dir = temp_dir("corrupt");
    for (name, what) in [("junk.exr", "OpenEXR"), ("junk.hdr", "Radiance HDR")] {
        std::fs::write(dir.join(name), b"not an image at all").unwrap();
        let e = load_error(&dir.join(name));
        assert!(e.contains(&format!("not a readable {what} file")), "{e}");
    }
}

#[test]
fn non_finite_texels_are_refused_with_their_position() {
    let path = temp_dir("nan").join("nan.exr");
    write_exr(&path, 4, 2, |x, y| {
        if (x, y) == (3, 1) {
            [1.0, f32::NAN, 0.0]
        } else {
            [1.0; 3]
        }
    });
    let e = load_error(&path);
    assert!(e.contains("texel (3, 1)") && e.contains("finite"), "{e}");
}

/// Lossy OpenEXR compression leaves small negative channels around dark texels (CC0 maps
/// compressed with DWAA carry them): they load, read as 0, the other channels and texels kept.
#[test]
fn negative_channels_are_read_as_zero() {
    let path = temp_dir("negative").join("negative.exr");
    write_exr(&path, 4, 2, |x, y| {
        if (x, y) == (1, 0) {
            [-0.5, 0.25, -0.01]
        } else {
            [1.0; 3]
        }
    });
    let map = fovea_stage::env_map::load(&path, 0.0, 1.0).unwrap();
    assert_eq!(map.texels[1], Vec3::new(0.0, 0.25, 0.0));
    assert!(map
        .texels
        .iter()
        .enumerate()
        .all(|(i, t)| i == 1 || *t == Vec3::ONE));
}

#[test]
fn maps_above_the_size_bound_are_refused_before_decoding() {
    let dir = temp_dir("large");
    for (name, w, h) in [("wide.exr", 8193, 1), ("tall.exr", 1, 4097)] {
        write_exr(&dir.join(name), w, h, |_, _| [1.0; 3]);
        let e = load_error(&dir.join(name));
        assert!(
            e.contains(&format!("{w}×{h}")) && e.contains("8192×4096"),
            "{e}"
        );
    }
    // A Radiance header claiming 100000 columns: refused from the header alone.
    let hdr = dir.join("huge.hdr");
    std::fs::write(
        &hdr,
        b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 100000\n",
    )
    .unwrap();
    let e = load_error(&hdr);
    assert!(e.contains("100000×2") && e.contains("8192×4096"), "{e}");
}

#[test]
fn maps_of_zero_width_or_height_are_refused() {
    let hdr = temp_dir("zero").join("empty.hdr");
    std::fs::write(&hdr, b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 0 +X 16\n").unwrap();
    let e = load_error(&hdr);
    assert!(e.contains("16×0") && e.contains("at least 1"), "{e}");
}
