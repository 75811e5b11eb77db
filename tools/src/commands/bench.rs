//! `fovea bench`: BVH build rate, memory and tree statistics per builder (`--bvh`); primary, shadow and indirect rays
//! per second on the current device; per-pass GPU milliseconds of whole frames. All figures
//! come from one run on one device (GPU timestamps for the GPU parts). The Visual-Polar vs
//! Cartesian comparison lives in `bench_vp.rs`, the real-time loop (frames in flight, stereo vs
//! two mono renders, host CPU time) in `bench_loop.rs`.

use super::bench_rays::{primary_rays, timed_trace};
use super::flags::{parse_traversals, DeviceArgs};
use anyhow::Context as _;
use anyhow::{bail, Result};
use fovea_renderer::frame::{CameraPose, FrameInput, RenderSettings};
use fovea_renderer::gpu_scene::GpuScene;
use fovea_renderer::layouts::{HitGpu, RayGpu};
use fovea_renderer::passes::raycast::RayCaster;
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::Cartesian;
use fovea_renderer::scene::bvh::compressed::Bvh8;
use fovea_renderer::scene::bvh::instanced::InstancingStats;
use fovea_renderer::scene::bvh::wide::Bvh4;
use fovea_renderer::scene::bvh::{Bvh, BvhBuilder, BvhStats};
use fovea_renderer::scene::lights::{build_light_table, sample_alias, LightKind};
use fovea_renderer::scene::{PunctualLight, Scene};
use fovea_renderer::traversal::{Traversal, TraversalChoice};
use glam::{UVec2, Vec3, Vec4};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// `BenchArgs::vp_gaze` by default: the screen's centre.
pub const CENTRED_GAZE: glam::Vec2 = glam::Vec2::splat(0.5);

pub struct BenchArgs<'a> {
    pub scenes: &'a [String],
    /// BVH builders to compare (the first also serves the frame and VP figures); with more than
    /// one, the ray figures are measured in the order A B … B A within one run.
    pub builders: &'a [BvhBuilder],
    /// Expand instances into world-space copies before measuring (`Scene::flattened`).
    pub flatten: bool,
    /// Sizes of the ray-throughput and Cartesian frame measurements (empty: skip them).
    pub sizes: &'a [(u32, u32)],
    /// Screen sizes of the VP vs Cartesian comparison (empty: skip it).
    pub vp_sizes: &'a [(u32, u32)],
    /// Where the gaze rests in the VP vs Cartesian frames, as a fraction of the screen per axis
    /// (`--vp-gaze`; `CENTRED_GAZE` by default, as the performance targets are stated).
    pub vp_gaze: glam::Vec2,
    pub frames: u32,
    /// Per-eye size of the real-time loop section (`None`: skip it); its scene is the Cornell box.
    pub loop_size: Option<(u32, u32)>,
    /// Timed frames of each loop run (after `bench_loop::WARMUP_FRAMES` warm-up frames).
    pub loop_frames: u32,
    /// Scenes and per-eye sizes of the headset loop (`--loop-scenes`, `--loop-headsets`; no
    /// scenes: skip it).
    pub loop_scenes: &'a [String],
    pub loop_headsets: &'a [super::bench_headsets::LoopHeadset],
    /// Keyframes the VP vs Cartesian frames follow and the ray rates are measured along
    /// (`--camera-path FILE`; none: the still camera).
    pub camera_path: Option<&'a fovea_stage::camera_keys::CameraKeys>,
    pub out: &'a Path,
    /// Also write each scene's world-space triangles and each size's primary and indirect rays
    /// into `out` (`--dump-rays`, files `rays_*.bin`), for a CPU tracer to time the very same rays
    /// (`scripts/embree-rays`).
    pub dump_rays: bool,
    /// `--traversal`: the ray figures and traversal counters are measured for each (after the
    /// builders, A B … B A over every pair); frames, VP and the loop run the first.
    pub traversals: &'a [TraversalChoice],
    pub device: Option<&'a str>,
    pub validation: bool,
}

#[derive(Serialize)]
struct BvhReport {
    scene: String,
    builder: String,
    triangles: usize,
    build_seconds: f64,
    triangles_per_second: f64,
    /// GPU bytes of the 4-wide tree the shaders traverse (128 B per node, 48 per leaf reference).
    memory_bytes: usize,
    /// Depth of the binary tree (`stats`) and of the 4-wide one collapsed from it.
    depth: u32,
    wide_depth: u32,
    wide_nodes: usize,
    /// The compressed 8-wide tree of the GPU traversal collapsed from the same binary tree.
    compressed: CompressedReport,
    stats: BvhStats,
    /// Instances and what instancing keeps off the GPU (the tree above is the world tree over
    /// the flattened triangles; `memory_bytes` counts it alone).
    instancing: InstancingStats,
}

#[derive(Serialize)]
struct CompressedReport {
    nodes: usize,
    depth: u32,
    /// Entries its traversal stack may need (`Bvh8::max_stack`; the shaders hold
    /// `gpu_scene::MAX_BVH8_STACK`).
    max_stack: u32,
    /// 80 B per node plus 48 per leaf entry.
    memory_bytes: usize,
}

#[derive(Serialize)]
struct RayReport {
    scene: String,
    builder: String,
    /// The traversal that traced these rays (cpu-driver or gpu).
    traversal: String,
    /// 1 on the way there, 2 on the way back (A B … B A); a single builder measures once.
    pass: u32,
    width: u32,
    height: u32,
    primary_mrays_per_s: f64,
    /// `null` when the scene has no point-like light to aim shadow rays at (only an environment;
    /// a scene its own lights do not light gets the default sun, as `fovea render` gives it).
    shadow_mrays_per_s: Option<f64>,
    indirect_mrays_per_s: f64,
    frame_passes_ms: BTreeMap<String, f64>,
    frame_rays: u64,
    /// Camera poses the primary rays come from: 1 (the scene's camera), or with `--camera-path`
    /// [`PATH_RAY_POSES`] frames spread over the keyframes (each a whole w×h frame of rays).
    ray_poses: usize,
    /// Primary rays whose hit (hit or miss, or distance beyond 1e-5 relative) differs from the
    /// first builder's and traversal's: every tree and traversal must find the same surfaces, so
    /// anything but 0 is a bug.
    primary_hits_differ: usize,
    /// What the traversal read per ray of each set, counted on the device by the counting kernel
    /// (on the way there only; `null` on the way back).
    counters: Option<super::bench_counters::RaySetCounters>,
}

#[derive(Serialize)]
struct BenchReport {
    device: String,
    bvh: Vec<BvhReport>,
    rays: Vec<RayReport>,
    visual_polar: Vec<super::bench_vp::VpFrameReport>,
    /// The real-time loop section (`null` when skipped).
    #[serde(rename = "loop")]
    real_time_loop: Option<super::bench_loop::LoopReport>,
    /// The headset loop: one entry per scene and size (empty when skipped).
    headset_loop: Vec<super::bench_headsets::HeadsetLoopReport>,
}

pub fn run(args: &BenchArgs) -> Result<()> {
    if args.loop_size.is_some() || !args.loop_scenes.is_empty() {
        super::bench_loop::check_frames(args.loop_frames)?;
    }
    let _out_dir = crate::output::prepare_output_dir(args.out)?;
    let ctx = super::open_device(args.device, args.validation)?;
    let mut report = BenchReport {
        device: ctx.info.name.clone(),
        bvh: Vec::new(),
        rays: Vec::new(),
        visual_polar: Vec::new(),
        real_time_loop: None,
        headset_loop: Vec::new(),
    };
    for name in args.scenes {
        let mut scene = fovea_stage::scenes::load(name)?;
        // Lit as `fovea render` lights it: a scene its own emitters do not light (Sponza, the
        // Breakfast Room) gets the default sun and sky, so its shadow rays aim at the sun.
        if let Some(notice) = fovea_stage::look::apply_environment(
            &mut scene,
            &fovea_stage::look::EnvironmentOptions::default(),
        ) {
            println!("{notice}");
        }
        let scene = if args.flatten {
            scene.flattened()
        } else {
            scene
        };
        // The builders compared make the world tree over the flattened triangles; hits name placed
        // ids (instances expanded), which the secondary rays look up.
        let positions = scene.flat_positions();
        let placed = scene.triangle_positions();
        let Some(camera) = scene.default_camera() else {
            bail!("{name}: no camera")
        };
        // Each builder's tree, uploaded for each traversal: (builder, traversal, tree, upload).
        let traversals = resolve_traversals(args.traversals, &ctx);
        let mut variants = Vec::new();
        for &builder in args.builders {
            let started = Instant::now();
            let bvh = Bvh::build_with(&positions, builder);
            let seconds = started.elapsed().as_secs_f64();
            let stats = bvh.stats(&positions);
            let wide = Bvh4::from_binary(&bvh);
            let eight = Bvh8::from_binary(&bvh, &positions);
            let bvh = std::rc::Rc::new(bvh);
            let mut instancing = None;
            for &traversal in &traversals {
                let gpu = GpuScene::upload_for(&ctx, &scene, &positions, &bvh, traversal)?;
                instancing.get_or_insert_with(|| gpu.instancing_stats.clone());
                variants.push((builder, traversal, bvh.clone(), gpu));
            }
            let bvh_report = BvhReport {
                scene: name.clone(),
                builder: builder.name(),
                triangles: positions.len(),
                build_seconds: seconds,
                triangles_per_second: positions.len() as f64 / seconds,
                memory_bytes: wide.memory_bytes(),
                depth: bvh.depth(),
                wide_depth: wide.depth(),
                wide_nodes: wide.nodes.len(),
                compressed: CompressedReport {
                    nodes: eight.nodes.len(),
                    depth: eight.depth(),
                    max_stack: eight.max_stack(),
                    memory_bytes: eight.memory_bytes(),
                },
                stats,
                instancing: instancing.unwrap_or_default(),
            };
            let s = &bvh_report.stats;
            println!(
                "{name} [{}]: BVH of {} triangles in {:.3} s ({:.2} M triangles/s), {:.1} MiB on the GPU (4-wide: {} nodes, depth {}; compressed 8-wide: {:.1} MiB, {} nodes, depth {}), binary depth {}, {} nodes, {} references, \
                 mean leaf {:.2} at depth {:.1}, SAH {:.1} (nodes {:.1}), child overlap {:.3}, {} thin / {} large triangles",
                bvh_report.builder,
                bvh_report.triangles,
                seconds,
                bvh_report.triangles_per_second * 1e-6,
                bvh_report.memory_bytes as f64 / (1 << 20) as f64,
                bvh_report.wide_nodes,
                bvh_report.wide_depth,
                bvh_report.compressed.memory_bytes as f64 / (1 << 20) as f64,
                bvh_report.compressed.nodes,
                bvh_report.compressed.depth,
                bvh_report.depth,
                s.nodes,
                s.references,
                s.mean_leaf_size,
                s.mean_leaf_depth,
                s.sah_cost,
                s.sah_node_cost,
                s.mean_child_overlap,
                s.thin_triangles,
                s.large_triangles,
            );
            let inst = &bvh_report.instancing;
            println!(
                "{name} [{}]: {} instances of {} meshes: {} placed triangles, {} uploaded, {:.1} MiB saved against flattening",
                bvh_report.builder,
                inst.instances,
                inst.instanced_meshes,
                inst.placed_triangles,
                inst.uploaded_triangles,
                inst.bytes_saved as f64 / (1 << 20) as f64
            );
            report.bvh.push(bvh_report);
        }
        let mut caster = RayCaster::new(&ctx)?;
        // A B … B A: a drift of the machine's load over the run hits every builder alike.
        let order: Vec<(usize, u32)> = if variants.len() > 1 {
            (0..variants.len())
                .map(|i| (i, 1))
                .chain((0..variants.len()).rev().map(|i| (i, 2)))
                .collect()
        } else {
            vec![(0, 1)]
        };
        for &(w, h) in args.sizes {
            let pose = CameraPose::from_scene_camera(camera, w, h);
            let poses = ray_poses(args.camera_path, &pose);
            let primary: Vec<RayGpu> = poses.iter().flat_map(|p| primary_rays(p, w, h)).collect();
            // The secondary rays start from the first variant's hits so that every builder and
            // traversal traces the same rays (hits may differ in the last bit between trees).
            let (hits, _) = caster.trace(&variants[0].3, &primary, false)?;
            let (shadow, indirect) = secondary_rays(&scene, &placed, &primary, &hits);
            if args.dump_rays {
                dump_rays(args.out, name, (w, h), &placed, &primary, &indirect)?;
            }
            for &(v, pass) in &order {
                let (builder, traversal, bvh, gpu) = &variants[v];
                let (primary_hits, primary_ms) = timed_trace(&mut caster, gpu, &primary, false)?;
                let primary_hits_differ = hits
                    .iter()
                    .zip(&primary_hits)
                    .filter(|(a, b)| {
                        let (ta, tb) = (a.t_u_v.x, b.t_u_v.x);
                        (ta < 0.0) != (tb < 0.0) || (ta - tb).abs() > 1e-5 * ta.abs().max(1.0)
                    })
                    .count();
                let shadow_ms = if shadow.is_empty() {
                    None
                } else {
                    Some(timed_trace(&mut caster, gpu, &shadow, true)?.1)
                };
                let (_, indirect_ms) = timed_trace(&mut caster, gpu, &indirect, false)?;
                let rate = |n: usize, ms: f64| n as f64 / (ms * 1e-3) * 1e-6;
                // What each ray read, counted once per variant (untimed).
                let counters = if pass == 1 {
                    Some(super::bench_counters::count_sets(
                        &mut caster,
                        gpu,
                        &primary,
                        &shadow,
                        &indirect,
                    )?)
                } else {
                    None
                };
                // Whole frames once per builder (on the way there), with the context's traversal
                // (the renderer's kernels run it).
                let (sums, frame_rays) = if pass == 1 && *traversal == ctx.traversal {
                    let space = Box::new(Cartesian::new(UVec2::new(w, h)));
                    let upload = GpuScene::upload_with_bvh(&ctx, &scene, &positions, bvh)?;
                    let mut renderer =
                        Renderer::with_gpu_scene(&ctx, upload, space, RenderSettings::default())?;
                    // One untimed frame first: the first dispatch of a pipeline pays one-off costs
                    // (lavapipe's lazy set-up, first-touch page faults) that are not the kernel's speed.
                    let sums =
                        super::bench_vp::pass_medians(&mut renderer, pose, None, args.frames)?;
                    let input = FrameInput::mono(pose, 0, None);
                    (sums, renderer.render_frame(&input)?.rays_traced())
                } else {
                    (BTreeMap::new(), 0)
                };
                let r = RayReport {
                    scene: name.clone(),
                    builder: builder.name(),
                    traversal: traversal.name().to_string(),
                    pass,
                    width: w,
                    height: h,
                    primary_mrays_per_s: rate(primary.len(), primary_ms),
                    shadow_mrays_per_s: shadow_ms.map(|ms| rate(shadow.len(), ms)),
                    indirect_mrays_per_s: rate(indirect.len(), indirect_ms),
                    frame_passes_ms: sums,
                    frame_rays,
                    ray_poses: poses.len(),
                    primary_hits_differ,
                    counters,
                };
                println!(
                    "{name} {w}×{h} [{}, {} traversal, pass {pass}]: primary {:.2} Mrays/s, shadow {}, indirect {:.2} Mrays/s; frame passes (ms) {:?} (load {}); {} primary hits differ from the first builder's and traversal's",
                    r.builder,
                    r.traversal,
                    r.primary_mrays_per_s,
                    r.shadow_mrays_per_s.map_or("- (no light)".into(), |m| format!("{m:.2} Mrays/s")),
                    r.indirect_mrays_per_s,
                    r.frame_passes_ms,
                    load_average(),
                    r.primary_hits_differ
                );
                if let Some(c) = &r.counters {
                    super::bench_counters::print(name, (w, h), &r.builder, &r.traversal, c);
                }
                report.rays.push(r);
            }
        }
        let bvh = &variants[0].2;
        for &size in args.vp_sizes {
            let make_scene = || Ok(GpuScene::upload_with_bvh(&ctx, &scene, &positions, bvh)?);
            let scene = super::bench_vp::VpBenchScene {
                ctx: &ctx,
                name,
                make_scene: &make_scene,
                caster: &mut caster,
                camera,
                camera_path: args.camera_path,
            };
            report.visual_polar.push(super::bench_vp::measure(
                scene,
                size,
                args.vp_gaze,
                args.frames,
            )?);
        }
    }
    if let Some(size) = args.loop_size {
        report.real_time_loop = Some(super::bench_loop::measure(&ctx, size, args.loop_frames)?);
    }
    if !args.loop_scenes.is_empty() {
        report.headset_loop = super::bench_headsets::measure(
            &ctx,
            args.loop_scenes,
            args.loop_headsets,
            args.loop_frames,
        )?;
    }
    super::check_validation(&ctx)?;
    let path = args.out.join("report.json");
    crate::output::write_json(&path, &report)?;
    println!("wrote {}", path.display());
    Ok(())
}

/// `--traversal`'s choices resolved for the device, each once, in the order given.
fn resolve_traversals(
    choices: &[TraversalChoice],
    ctx: &fovea_renderer::vk::Context,
) -> Vec<Traversal> {
    let mut out: Vec<Traversal> = Vec::new();
    for c in choices {
        let t = c.resolve(ctx.info.device_type);
        if !out.contains(&t) {
            out.push(t);
        }
    }
    if out.is_empty() {
        out.push(ctx.traversal);
    }
    out
}

/// The 1-minute load average (`/proc/loadavg`), printed beside each ray figure: on a shared
/// machine a figure taken at a load above the core count is disturbed.
fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_owned))
        .unwrap_or_else(|| "?".into())
}

/// Frames of primary rays the ray-rate figures take along a camera path: its start, its end and
/// evenly between (the rates then describe the path's views, not one of them).
pub const PATH_RAY_POSES: usize = 4;

/// The poses of the ray-rate figures: the still camera, or [`PATH_RAY_POSES`] along the keyframes.
fn ray_poses(
    path: Option<&fovea_stage::camera_keys::CameraKeys>,
    still: &CameraPose,
) -> Vec<CameraPose> {
    let Some(keys) = path else {
        return vec![*still];
    };
    let (first, last) = (keys.keys()[0].time, keys.keys()[keys.keys().len() - 1].time);
    (0..PATH_RAY_POSES)
        .map(|i| {
            keys.pose(
                first + (last - first) * i as f64 / (PATH_RAY_POSES - 1) as f64,
                still,
            )
        })
        .collect()
}

/// `DIR/rays_SCENE-WxH.{triangles,primary,indirect}.bin`: little-endian f32, 9 per triangle
/// (three world-space vertices), 8 per ray (origin, t_min, direction, t_max).
fn dump_rays(
    dir: &Path,
    scene: &str,
    (w, h): (u32, u32),
    tris: &[[Vec3; 3]],
    primary: &[RayGpu],
    indirect: &[RayGpu],
) -> Result<()> {
    let stem = Path::new(scene)
        .file_stem()
        .map_or(scene.into(), |s| s.to_string_lossy());
    let write = |kind: &str, floats: &[f32]| {
        let path = dir.join(format!("rays_{stem}-{w}x{h}.{kind}.bin"));
        crate::output::write_atomic(&path, |f| {
            Ok(std::io::Write::write_all(f, bytemuck::cast_slice(floats))?)
        })
    };
    let tri_floats: Vec<f32> = tris
        .iter()
        .flat_map(|t| t.iter().flat_map(|v| v.to_array()))
        .collect();
    write("triangles", &tri_floats)?;
    write("primary", bytemuck::cast_slice(primary))?;
    write("indirect", bytemuck::cast_slice(indirect))
}

/// A small deterministic hash → [0, 1) for the CPU-side ray generation.
fn hash01(i: u32, salt: u32) -> f32 {
    let mut x = i.wrapping_mul(0x9E37_79B9) ^ salt.wrapping_mul(0x85EB_CA6B);
    x ^= x >> 16;
    x = x.wrapping_mul(0x7FEB_352D);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846C_A68B);
    x ^= x >> 16;
    (x >> 8) as f32 / (1u32 << 24) as f32
}

/// From each primary hit: one shadow ray to a random point on a random light and one
/// cosine-distributed indirect ray, like the path tracer's first vertex.
fn secondary_rays(
    scene: &Scene,
    tris: &[[Vec3; 3]],
    primary: &[RayGpu],
    hits: &[HitGpu],
) -> (Vec<RayGpu>, Vec<RayGpu>) {
    let table = build_light_table(scene);
    let (mut shadow, mut indirect) = (Vec::new(), Vec::new());
    for (i, (ray, hit)) in primary.iter().zip(hits).enumerate() {
        if hit.t_u_v.x < 0.0 {
            continue;
        }
        let i = i as u32;
        let [a, b, c] = tris[hit.triangle.x as usize];
        let mut n = (b - a).cross(c - a).normalize();
        let dir = ray.direction_tmax.truncate();
        if n.dot(dir) > 0.0 {
            n = -n;
        }
        let p = ray.origin_tmin.truncate() + dir * hit.t_u_v.x + n * 1e-4;
        if !table.entries.is_empty() {
            let entry = &table.entries[sample_alias(&table.alias, hash01(i, 1))];
            let target = match entry.kind {
                LightKind::EmissiveTriangle => {
                    let [la, lb, lc] = tris[entry.index as usize];
                    let (u, v) = (hash01(i, 2).sqrt(), hash01(i, 3));
                    Some(la * (1.0 - u) + lb * (u * (1.0 - v)) + lc * (u * v))
                }
                // The bench's shadow rays go to points; an environment has none.
                LightKind::Environment => None,
                _ => match &scene.punctual_lights[entry.index as usize] {
                    PunctualLight::Point { position, .. }
                    | PunctualLight::Spot { position, .. } => Some(*position),
                    PunctualLight::Directional { direction, .. } => Some(p - *direction * 1e4),
                },
            };
            if let Some(q) = target {
                let to = q - p;
                let d = to.length();
                shadow.push(RayGpu {
                    origin_tmin: p.extend(0.0),
                    direction_tmax: (to / d).extend(d * (1.0 - 1e-4)),
                });
            }
        }
        let (u1, u2) = (hash01(i, 4), hash01(i, 5));
        let (r, phi) = (u1.sqrt(), std::f32::consts::TAU * u2);
        let local = Vec4::new(
            r * phi.cos(),
            r * phi.sin(),
            (1.0 - u1).max(0.0).sqrt(),
            0.0,
        );
        let t = if n.x.abs() > 0.5 { Vec3::Y } else { Vec3::X }
            .cross(n)
            .normalize();
        let bt = n.cross(t);
        let d = (t * local.x + bt * local.y + n * local.z).normalize();
        indirect.push(RayGpu {
            origin_tmin: p.extend(0.0),
            direction_tmax: d.extend(1e30),
        });
    }
    (shadow, indirect)
}

// `fovea bench` (its help is the variant's in `crate::cli::Command`).
#[derive(clap::Args)]
pub struct BenchCommand {
    /// Scenes of the BVH, ray and frame figures, names or paths as --scene ("" skips them).
    #[arg(long, value_delimiter = ',', default_value = "cornell-box,large")]
    pub scenes: Vec<String>,
    /// BVH builders to compare: binned, sbvh, sbvh:BUDGET (extra references per triangle).
    /// The first also serves the frame and VP figures; several are measured A B … B A.
    #[arg(long, value_delimiter = ',', default_value = "sbvh")]
    pub bvh: Vec<String>,
    /// Copy every instance into world space (meshes placed by several nodes copied per
    /// node, no instancing): the comparison of the two in one build.
    #[arg(long)]
    pub flatten: bool,
    /// Frame sizes WxH of the ray-throughput and Cartesian frame figures ("" skips them).
    #[arg(long, value_delimiter = ',', default_value = "320x360,1280x1440")]
    pub sizes: Vec<String>,
    /// Screen sizes WxH of the Visual-Polar vs Cartesian comparison ("" skips it).
    #[arg(long, value_delimiter = ',', default_value = "640x720,1280x1440")]
    pub vp_sizes: Vec<String>,
    /// Gaze of the Visual-Polar vs Cartesian frames as FX,FY, fractions of the screen in
    /// [0, 1] (0,0: the top-left corner; default 0.5,0.5: the centre).
    #[arg(long, default_value = "0.5,0.5")]
    pub vp_gaze: String,
    /// Whole frames rendered per size for the per-pass timings.
    #[arg(long, default_value_t = 2)]
    pub frames: u32,
    /// Per-eye size WxH of the real-time loop figures: Cornell box, both eyes, VP + SVGF, 1 vs 2
    /// frames in flight, stereo vs two mono renders, stereo with cross-eye reuse ("" skips them).
    #[arg(long, default_value = "320x360")]
    pub loop_size: String,
    /// Timed frames of each run of the real-time loop and of the headset loop (after 2 warm-up
    /// frames; at least 2). Each run is made twice (real-time loop: order A B C D D C B A; headset
    /// loop: A B C C B A).
    #[arg(long, default_value_t = 5)]
    pub loop_frames: u32,
    /// Scenes of the headset loop: both eyes at each --loop-headsets size, the head on the
    /// default orbit and the simulated gaze, VP + SVGF, VP + A-SVGF and Cartesian + SVGF (2
    /// frames in flight, --loop-frames timed frames each, order A B C C B A): frames/s,
    /// per-pass GPU ms and VP / Cartesian per size ("" skips it; names as --scenes, e.g.
    /// sponza, breakfast-room from the shared scene folder).
    #[arg(long, default_value = "")]
    pub loop_scenes: String,
    /// Headsets of the headset loop, each at its recommended per-eye size (names from `fovea
    /// headsets` or profile paths), or per-eye sizes WxH (through the FOVE 0's frusta). The
    /// frames run the first --traversal.
    #[arg(long, default_value = super::bench_headsets::DEFAULT_HEADSETS)]
    pub loop_headsets: String,
    /// A keyframe file (as `fovea render --camera-path FILE`) the VP vs Cartesian frames
    /// follow, frame i at i / 70 Hz (default: the scene camera, still).
    #[arg(long)]
    pub camera_path: Option<PathBuf>,
    #[arg(long, default_value = "out/bench")]
    pub out: PathBuf,
    /// Also write each scene's triangles and each `--sizes` size's primary and indirect rays
    /// into OUT as rays_*.bin (for `scripts/embree-rays`: Embree timing the same rays).
    #[arg(long)]
    pub dump_rays: bool,
    #[command(flatten)]
    pub device: DeviceArgs,
}

impl BenchCommand {
    pub fn run(self) -> Result<()> {
        let camera_path = self
            .camera_path
            .map(|f| fovea_stage::camera_keys::CameraKeys::load(&f))
            .transpose()
            .context("--camera-path")?;
        let builders = self
            .bvh
            .iter()
            .map(|b| BvhBuilder::parse(b).map_err(anyhow::Error::msg))
            .collect::<Result<Vec<_>>>()
            .context("--bvh")?;
        if builders.is_empty() {
            bail!("--bvh: name at least one builder");
        }
        let parse = |v: &[String]| {
            v.iter()
                .filter(|s| !s.is_empty())
                .map(|s| parse_size(s))
                .collect::<Result<Vec<_>>>()
        };
        let (sizes, vp_sizes) = (
            parse(&self.sizes).context("--sizes")?,
            parse(&self.vp_sizes).context("--vp-sizes")?,
        );
        let loop_size = (!self.loop_size.is_empty())
            .then(|| parse_size(&self.loop_size))
            .transpose()
            .context("--loop-size")?;
        let scenes: Vec<String> = self.scenes.into_iter().filter(|s| !s.is_empty()).collect();
        let loop_scenes: Vec<String> = self
            .loop_scenes
            .split(',')
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .map(String::from)
            .collect();
        let loop_headsets = if loop_scenes.is_empty() {
            Vec::new()
        } else {
            super::bench_headsets::LoopHeadset::parse_list(&self.loop_headsets)?
        };
        let traversals = parse_traversals(&self.device.traversal)?;
        super::choose_traversal(traversals[0]);
        run(&BenchArgs {
            scenes: &scenes,
            builders: &builders,
            flatten: self.flatten,
            sizes: &sizes,
            vp_sizes: &vp_sizes,
            vp_gaze: parse_gaze_fraction(&self.vp_gaze).context("--vp-gaze")?,
            frames: self.frames,
            loop_size,
            loop_frames: self.loop_frames,
            loop_scenes: &loop_scenes,
            loop_headsets: &loop_headsets,
            camera_path: camera_path.as_ref(),
            out: &self.out,
            dump_rays: self.dump_rays,
            traversals: &traversals,
            device: self.device.device.as_deref(),
            validation: self.device.validation,
        })
    }
}

/// `WxH`, each at least 1.
pub fn parse_size(s: &str) -> Result<(u32, u32)> {
    let parsed = s
        .split_once('x')
        .and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?)));
    match parsed {
        Some((w, h)) if w > 0 && h > 0 => Ok((w, h)),
        _ => bail!("size '{s}' is not WIDTHxHEIGHT (e.g. 320x360)"),
    }
}

/// `--vp-gaze FX,FY`: two fractions of the screen, each in [0, 1].
pub fn parse_gaze_fraction(spec: &str) -> Result<glam::Vec2> {
    let parts: Vec<&str> = spec.split(',').map(str::trim).collect();
    let [x, y] = parts[..] else {
        bail!("'{spec}' is not FX,FY (two fractions of the screen)")
    };
    let fraction = |s: &str| -> Result<f32> {
        let v: f32 = s
            .parse()
            .with_context(|| format!("'{s}' is not a number"))?;
        if !(0.0..=1.0).contains(&v) {
            bail!("{v} is not a fraction of the screen in [0, 1]");
        }
        Ok(v)
    };
    Ok(glam::Vec2::new(fraction(x)?, fraction(y)?))
}
