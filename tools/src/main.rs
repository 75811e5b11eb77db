//! `fovea`: the command line of the foveated path tracer. docs/cli.md is generated from these
//! definitions (the contract).

use anyhow::{bail, Context as _, Result};
use clap::{Parser, Subcommand};
use fovea_renderer::frame::StereoNoise;
use fovea_renderer::passes::denoise::DenoiserSettings;
use fovea_renderer::scene::bvh::BvhBuilder;
use fovea_tools::commands;
use fovea_tools::render_profile::{ProfileOverrides, RenderProfile};
use fovea_tools::replay::Tolerances;
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "fovea",
    version,
    about = "Foveated real-time path tracing in Visual-Polar space (Vulkan compute)"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(clap::Args)]
struct DeviceArgs {
    /// Vulkan device: index from `fovea info` or a name substring (default: best GPU, else CPU).
    #[arg(long, global = true)]
    device: Option<String>,
    /// Turn on Vulkan validation (always on in debug builds); any message fails the run.
    #[arg(long, global = true)]
    validation: bool,
    /// BVH traversal of the kernels that trace: auto (gpu on a discrete, integrated or virtual
    /// GPU, cpu-driver on a CPU driver such as lavapipe), cpu-driver (4-wide nodes in texel
    /// buffers, stack in shared memory) or gpu (compressed 8-wide nodes in storage buffers,
    /// children in order of distance, stack in private memory). `fovea bench` takes a comma list:
    /// ray figures and traversal counters for each, frames with the first.
    #[arg(long, global = true, default_value = "auto")]
    traversal: String,
}

impl DeviceArgs {
    /// `--traversal` of a command that renders: one traversal, the process's for every device it
    /// opens.
    fn choose_traversal(&self) -> Result<()> {
        let [choice] = parse_traversals(&self.traversal)?[..] else {
            bail!("--traversal: one of auto, cpu-driver, gpu (a list only for fovea bench)");
        };
        commands::choose_traversal(choice);
        Ok(())
    }
}

/// `--traversal` as a comma list.
fn parse_traversals(spec: &str) -> Result<Vec<fovea_renderer::traversal::TraversalChoice>> {
    spec.split(',')
        .map(|s| s.trim().parse().map_err(anyhow::Error::msg))
        .collect::<Result<Vec<_>>>()
        .context("--traversal")
}

/// The camera and the default environment (every command that renders the scene camera).
#[derive(clap::Args)]
struct SceneFlags {
    /// A camera of the scene file by index or name (default: its first; with none, a camera
    /// that frames the scene's bounds).
    #[arg(long)]
    camera: Option<String>,
    /// A free camera at X,Y,Z (with --camera-look) instead of the file's.
    #[arg(long, allow_hyphen_values = true)]
    camera_pos: Option<String>,
    /// The point X,Y,Z the free camera looks at (+Y up).
    #[arg(long, allow_hyphen_values = true)]
    camera_look: Option<String>,
    /// Vertical field of view in degrees, in (1, 170), with --projection scene-camera: of the free
    /// or framing camera (default 60), or replacing the chosen glTF camera's.
    #[arg(long)]
    fov: Option<f32>,
    /// How each eye sees the scene: headset (the default: through the headset profile's
    /// asymmetric per-eye FOV and eye offset, the camera being the head) or scene-camera (the
    /// camera's own symmetric FOV at the output's aspect ratio).
    #[arg(long, default_value = "headset")]
    projection: String,
    /// Metres per scene unit (default 1, glTF's metre; 0.01 for a scene authored in
    /// centimetres): the eyes' offsets and a headset's movements are metres.
    #[arg(long, default_value_t = 1.0)]
    world_scale: f32,
    /// The default sun's AZIMUTH,ELEVATION in degrees (azimuth from +Z toward +X; default 30,60);
    /// only for scenes without lights of their own.
    #[arg(long, allow_hyphen_values = true)]
    sun: Option<String>,
    /// The default sun's illuminance (default 3; 0 = no sun).
    #[arg(long)]
    sun_intensity: Option<f32>,
    /// The sky's radiance scale (default 0.5 for scenes without lights; 0 = no sky; a scene
    /// with lights gets a sky only when this is given and > 0).
    #[arg(long)]
    sky_intensity: Option<f32>,
    /// Texture filtering: cones (a mip level from each ray's cone, whose spread is the sample's
    /// footprint on the screen; the default) or off (every lookup reads level 0).
    #[arg(long)]
    texture_lod: Option<String>,
    /// Samples far off the screen: cull (the default: a sample farther off than the way back
    /// and the filters read, three footprints and three pixels, is not traced; the picture is the
    /// same) or trace (every sample, as in the paper; only the paper's Visual-Polar layout, the
    /// log-polar and composite buffers and random acuity place samples there).
    #[arg(long)]
    offscreen_samples: Option<String>,
    /// Light-sample reuse before the denoiser: off (the default: next-event estimation at every
    /// hit) or di (ReSTIR DI at the primary hit: light candidates resampled per sample, reused
    /// from the previous frame and from grid neighbours; spaces with temporal filters only, not
    /// with --denoiser asvgf); parameters from the profile's [resampling].
    #[arg(long)]
    resampling: Option<String>,
    /// How the two eyes' random numbers relate in a stereo run (docs/design/random-numbers.md):
    /// screen (the default: texel (x, y) of both eyes draws the same numbers), independent (each
    /// eye its own sequence) or surface (the path after the primary hit drawn from the hit's world position at
    /// the sample's footprint: the noise lies on the surfaces). `fovea quality` takes a
    /// comma-separated list and renders each.
    #[arg(long)]
    stereo_noise: Option<String>,
    /// Path regularisation strength in [0, 100] (default 1): after a low-density bounce, later
    /// vertices' glossy lobes are widened so sunlight focused through them stops making
    /// fireflies; biased, 0 = off (the unbiased estimator).
    #[arg(long)]
    path_regularisation: Option<f32>,
    /// An equirectangular HDR environment map (.exr or .hdr, at most 8192×4096) seen by escaping
    /// rays and sampled by next-event estimation; replaces the sky, and the default sun stays off
    /// unless --sun is given.
    #[arg(long)]
    env: Option<std::path::PathBuf>,
    /// The default sky's model: gradient (the default: a horizon-to-zenith gradient) or preetham
    /// (Preetham et al. 1999's daylight, turbidity 3, around the --sun position).
    #[arg(long)]
    sky: Option<String>,
    /// The environment map's rotation about +Y in degrees (counter-clockwise seen from above; default 0).
    #[arg(long, allow_hyphen_values = true)]
    env_rotation: Option<f32>,
    /// The environment map's radiance scale (default 1).
    #[arg(long)]
    env_intensity: Option<f32>,
    /// When the default sun and sky light the scene: auto (the default: when the scene's own
    /// emitters send out less than 2 % of the default sun's power through its bounds), on
    /// (always), off (never: the scene as authored).
    #[arg(long)]
    default_light: Option<String>,
}

impl SceneFlags {
    fn camera(&self) -> Result<fovea_stage::look::CameraOptions> {
        Ok(fovea_stage::look::CameraOptions {
            camera: self.camera.clone(),
            position: self.camera_pos.clone(),
            look: self.camera_look.clone(),
            fov: self.fov,
            projection: fovea_stage::look::Projection::parse(&self.projection)?,
            world_scale: self.world_scale,
        })
    }

    fn environment(&self) -> Result<fovea_stage::look::EnvironmentOptions> {
        Ok(fovea_stage::look::EnvironmentOptions {
            sun: self
                .sun
                .as_deref()
                .map(fovea_stage::look::parse_sun)
                .transpose()?,
            sun_intensity: self.sun_intensity,
            sky_intensity: self.sky_intensity,
            env: self.env.clone(),
            env_rotation: self.env_rotation,
            env_intensity: self.env_intensity,
            sky: self
                .sky
                .as_deref()
                .map(fovea_stage::sky_model::SkyModel::parse)
                .transpose()
                .context("--sky")?,
            default_light: self
                .default_light
                .as_deref()
                .map(fovea_stage::look::DefaultLight::parse)
                .transpose()?,
        })
    }
}

/// The latency model (hal): with any of these flags each frame is foveated with the gaze a
/// headset would have and judged also where the eye is when it is shown.
#[derive(clap::Args)]
struct LatencyFlags {
    /// Gaze-to-photon latency in ms: a frame displayed at T sees the tracker samples taken up to
    /// T − this (default: the headset profile's tracker + render + display latency). Any of
    /// --latency-ms, --tracker-hz, --gaze-predict turns this latency model on.
    #[arg(long, allow_hyphen_values = true)]
    latency_ms: Option<f64>,
    /// Tracker rate of the latency model in Hz (default: the headset profile's).
    #[arg(long, allow_hyphen_values = true)]
    tracker_hz: Option<f64>,
    /// Gaze prediction at the display time: off (the newest sample) | hold | linear | saccade
    /// (default saccade, chosen by `fovea gaze-eval`; see docs/guide/gaze-latency.md).
    #[arg(long)]
    gaze_predict: Option<String>,
}

impl LatencyFlags {
    fn timing(&self) -> Result<fovea_stage::gaze::GazeTiming> {
        fovea_stage::gaze::GazeTiming::from_flags(
            self.latency_ms,
            self.tracker_hz,
            self.gaze_predict.as_deref(),
        )
    }
}

#[derive(clap::Args)]
struct RenderOpts {
    #[command(flatten)]
    look: SceneFlags,
    #[command(flatten)]
    latency: LatencyFlags,
    /// Scene name (cornell-box, stress, large; sponza, breakfast-room, flight-helmet from the
    /// shared scene folder, $FOVEA_SCENES or ../shared/data/scenes) or a .gltf/.glb path.
    #[arg(long, default_value = fovea_stage::scenes::DEFAULT_SCENE)]
    scene: String,
    /// Sampling method: vp (Visual-Polar, Koskela et al. 2019) or cartesian (uniform, 1 spp).
    #[arg(long, default_value = "vp")]
    method: String,
    /// Headset profile: a name from `fovea headsets` or a TOML path.
    #[arg(long, default_value = "fove0")]
    headset: String,
    /// Gaze: center | X,Y (render pixels) | sim[:seed] (simulated FOVE 0 eye) | a trace file |
    /// degrees:FILE (t_s,x_deg,y_deg,valid) | gazebase:FILE (render: default sim:1; view: default
    /// the mouse).
    #[arg(long)]
    gaze: Option<String>,
    /// Render width (default: the headset's per-eye width × --scale).
    #[arg(long)]
    width: Option<u32>,
    /// Render height (default: the headset's per-eye height × --scale).
    #[arg(long)]
    height: Option<u32>,
    /// Fraction of the headset's per-eye resolution when --width/--height are not given
    /// (render, view: default 0.25, which keeps the default run near a minute on a CPU driver;
    /// xr: default 1, the runtime's recommended size).
    #[arg(long)]
    scale: Option<f32>,
    /// Frames to render (render: default 24; view: default until the window is closed).
    #[arg(long)]
    frames: Option<u32>,
    /// Eyes: left (default; files frame_NNNN.png), right, or both (one scene upload, both eyes
    /// in one submit per frame; files frame_NNNN_left.png and frame_NNNN_right.png).
    #[arg(long, default_value = "left")]
    eyes: String,
    /// Frames kept on the GPU at once (1 waits for every frame).
    #[arg(long, default_value_t = 2)]
    frames_in_flight: usize,
    /// Output folder (created; must hold only fovea's own outputs if it exists; default
    /// out/render, for fovea xr out/xr).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Also write linear EXR frames.
    #[arg(long)]
    exr: bool,
    /// Move the camera: without a value along the scene's default path (a slow orbit), with a TOML
    /// file along its keyframes (time, position, look, optional fov; see docs/guide/scenes.md).
    #[arg(long, num_args = 0..=1, default_missing_value = "orbit", value_name = "FILE")]
    camera_path: Option<String>,
    #[arg(long, default_value_t = 1)]
    seed: u32,
    /// Path vertices: 1 = emission seen directly, 2 = + direct light, 3 = + one indirect bounce.
    #[arg(long, default_value_t = 3)]
    max_depth: u32,
    /// Exposure: auto (metered from each frame's radiance with more weight around the gaze,
    /// adapted over time like an eye, one exposure for both eyes), auto+EV / auto-EV (metered,
    /// then compensated by EV stops), or EV (fixed, in stops: 0 displays radiance as it is).
    #[arg(long, default_value = "auto", allow_hyphen_values = true)]
    exposure: String,
    /// Display transform: neutral (Khronos PBR Neutral: base colours as authored, highlights
    /// compressed), aces (fitted ACES filmic) or clamp.
    #[arg(long, default_value = "neutral")]
    tone: String,
    /// Render profile TOML (Visual-Polar parameters, blur); see config/render/default.toml.
    #[arg(long)]
    profile: Option<PathBuf>,
    /// Visual-Polar grid size per axis relative to the screen (default 2/3).
    #[arg(long)]
    vp_scale: Option<f32>,
    /// Share of the VP grid removed by the fovea's triangular clip (default 0.12).
    #[arg(long)]
    vp_clip: Option<f32>,
    /// Fovea radius in the paper's normalised degrees (default 5.79).
    #[arg(long)]
    vp_fovea_deg: Option<f32>,
    /// Sample density ∝ acuity^k (default 1).
    #[arg(long)]
    vp_density_exponent: Option<f32>,
    /// Inverse CDF: polynomial (the paper's Eq. 3, default) or exact.
    #[arg(long)]
    vp_inverse_cdf: Option<String>,
    /// VP radius: corner (largest gaze-to-corner distance, default) or pixels.
    #[arg(long)]
    vp_radius: Option<String>,
    /// VP layout: screen-clipped (the default: each column's rows on its on-screen arcs, so the
    /// budget holds when the eye looks toward a corner), paper (every column's rows on its whole
    /// circle; samples far off the screen are culled) or screen-aware (screen-clipped rows,
    /// columns placed by the on-screen acuity mass).
    #[arg(long)]
    vp_layout: Option<String>,
    /// VP eccentricity axis: normalized (the paper's, 80 ↦ farthest corner; default) or headset
    /// (true degrees through the --headset eye's FOV).
    #[arg(long)]
    vp_eccentricity: Option<String>,
    /// --method log-polar: L from the farthest corner (Meng et al. 2018, default) or the screen
    /// diagonal (Andersson & Hansson 2020); σ and α from the profile's [log_polar].
    #[arg(long)]
    log_polar_extent: Option<String>,
    /// --method composite: Andersson & Hansson 2020's mode, fov|kernel|composite|composite-kernel
    /// (default composite).
    #[arg(long)]
    composite_mode: Option<String>,
    /// Foveated blur σ in pixels at 30° for a 1280×1440 eye (scaled with resolution; 0 = off).
    #[arg(long)]
    blur_sigma: Option<f32>,
    /// Where the foveated blur runs: screen (after the remap, the paper's) | grid (in the VP grid
    /// before the remap, no full-screen blur pass; the paper layout without screen-space TAA).
    #[arg(long)]
    blur_space: Option<String>,
    /// Also write per-frame grid images and density heat maps, and a density-vs-eccentricity plot.
    #[arg(long)]
    debug_views: bool,
    /// Denoiser in the sampling grid: auto (bmfr where the method's grid runs denoisers, none
    /// where it cannot: the method table's best for Visual-Polar, docs/quality.md) | none | svgf
    /// (Schied et al. 2017) | asvgf (Schied et al. 2018: SVGF with temporal gradients) | bmfr
    /// (Koskela et al. 2019); parameters from the profile's [svgf] / [asvgf] / [bmfr] sections.
    #[arg(long, default_value = "auto")]
    denoiser: String,
    /// TAA (Karis 2014) after the denoiser: auto (vp where the method's grid runs it, off where it
    /// cannot) | off | vp (in the sampling grid; the screen for Cartesian) | screen (after the
    /// remap to the screen, neighbourhood sized by the local VP texel footprint; for Cartesian the
    /// same as vp).
    #[arg(long, default_value = "auto")]
    taa: String,
}

impl RenderOpts {
    /// The profile file (or the built-in defaults) with the flags applied.
    fn profile(&self) -> Result<RenderProfile> {
        let base = match &self.profile {
            Some(path) => RenderProfile::load(path)?,
            None => RenderProfile::default(),
        };
        base.override_with(&ProfileOverrides {
            axis_scale: self.vp_scale,
            clip_fraction: self.vp_clip,
            fovea_deg: self.vp_fovea_deg,
            density_exponent: self.vp_density_exponent,
            inverse_cdf: self.vp_inverse_cdf.clone(),
            radius: self.vp_radius.clone(),
            layout: self.vp_layout.clone(),
            eccentricity: self.vp_eccentricity.clone(),
            log_polar_extent: self.log_polar_extent.clone(),
            composite_mode: self.composite_mode.clone(),
            blur_sigma: self.blur_sigma,
            blur_space: self.blur_space.clone(),
            environment: self.look.environment()?,
            texture_lod: self.look.texture_lod.clone(),
            path_regularisation: self.look.path_regularisation,
            offscreen_samples: self.look.offscreen_samples.clone(),
            resampling: self.look.resampling.clone(),
            stereo_noise: self.look.stereo_noise.clone(),
            gaze_timing: self.latency.timing()?,
        })
    }
}

/// `fovea quality`'s flags (also the command a quality sweep splits).
#[derive(clap::Args)]
struct QualityFlags {
    #[arg(long, default_value = fovea_stage::scenes::DEFAULT_SCENE)]
    scene: String,
    #[arg(long, default_value_t = 160)]
    width: u32,
    #[arg(long, default_value_t = 180)]
    height: u32,
    #[arg(long, default_value = "fove0")]
    headset: String,
    /// Gaze source of every run (as for `render`); rings follow each frame's gaze.
    #[arg(long, default_value = "sim:1")]
    gaze: String,
    #[arg(long, default_value_t = 16)]
    frames: u32,
    /// The last this many frames are evaluated and averaged.
    #[arg(long, default_value_t = 4)]
    eval_frames: u32,
    /// Sampling methods (`all`: every `--method` of `fovea render`).
    #[arg(long, value_delimiter = ',', default_value = "vp,cartesian")]
    methods: Vec<String>,
    /// Denoisers to compare (default: every one built in).
    #[arg(long, value_delimiter = ',')]
    denoisers: Vec<String>,
    #[arg(long, value_delimiter = ',', default_value = "off")]
    taa: Vec<String>,
    /// still and/or moving (the scene's default camera path).
    #[arg(long, value_delimiter = ',', default_value = "still,moving")]
    cameras: Vec<String>,
    /// left, or both: every run renders both eyes (the headset's eye offsets), each eye is
    /// judged against its own reference, and the binocular consistency measure is added
    /// (the right eye warped into the left through the converged depth).
    #[arg(long, default_value = "left")]
    eyes: String,
    #[arg(long, default_value_t = 256)]
    reference_spp: u32,
    /// Take the converged references from an earlier `fovea quality` folder instead of rendering
    /// them: its quality.json must record the same reference settings for each camera (scene,
    /// size, headset, eyes, samples, seed, camera and light flags; the frames for the moving
    /// camera); they are copied into --out. E.g. the same scene at several sample budgets
    /// (profiles) or gaze sources with one set of references
    #[arg(long)]
    references: Option<PathBuf>,
    /// Equal-width rings from the gaze out to the farthest corner.
    #[arg(long, default_value_t = 10)]
    rings: usize,
    #[arg(long, default_value_t = 1)]
    seed: u32,
    /// Render profile (TOML) for every run; flags below override it.
    #[arg(long)]
    profile: Option<PathBuf>,
    /// Foveated blur σ at 30° (0 turns it off).
    #[arg(long)]
    blur_sigma: Option<f32>,
    /// Where the foveated blur runs: screen | grid (see `fovea render --blur-space`).
    #[arg(long)]
    blur_space: Option<String>,
    #[arg(long, default_value = "out/quality")]
    out: PathBuf,
    #[command(flatten)]
    look: SceneFlags,
    #[command(flatten)]
    latency: LatencyFlags,
}

/// `fovea replay`'s flags (also the command a replay sweep splits).
#[derive(clap::Args)]
struct ReplayFlags {
    /// Gaze traces (files) or gaze sources (sim:SEED, center, X,Y), one baseline each.
    traces: Vec<String>,
    /// Baseline folder (one subfolder per trace).
    #[arg(long)]
    baseline: PathBuf,
    /// Write the baselines from this run instead of comparing (overwrites them).
    #[arg(long)]
    update_baseline: bool,
    /// Samples per pixel of the converged reference made with a new baseline.
    #[arg(long, default_value_t = 256)]
    reference_spp: u32,
    /// Rings of distance from the gaze for every per-ring figure.
    #[arg(long, default_value_t = 4)]
    rings: usize,
    /// Largest mean FLIP per ring against the baseline's frame.
    #[arg(long, default_value_t = Tolerances::default().change_flip)]
    change_flip: f64,
    /// Largest sRGB RMSE (0…1) per ring against the baseline's frame.
    #[arg(long, default_value_t = Tolerances::default().change_rmse)]
    change_rmse: f64,
    /// A ring's error against the reference may grow to baseline × (1 + this) + --quality-abs.
    #[arg(long, default_value_t = Tolerances::default().quality_rel)]
    quality_rel: f64,
    #[arg(long, default_value_t = Tolerances::default().quality_abs)]
    quality_abs: f64,
    #[command(flatten)]
    opts: Box<RenderOpts>,
}

/// `fovea reference`'s flags (also the command a reference sweep splits).
#[derive(clap::Args)]
struct ReferenceFlags {
    #[arg(long, default_value = fovea_stage::scenes::DEFAULT_SCENE)]
    scene: String,
    #[arg(long, default_value_t = 256)]
    width: u32,
    #[arg(long, default_value_t = 256)]
    height: u32,
    #[arg(long, default_value_t = 1024)]
    spp: u32,
    #[arg(long, default_value_t = 3)]
    max_depth: u32,
    #[arg(long, default_value_t = 1)]
    seed: u32,
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    look: SceneFlags,
    /// Headset profile whose eye is rendered (with --projection headset, the default).
    #[arg(long, default_value = "fove0")]
    headset: String,
    /// The eye: left (as `fovea render` writes by default) or right.
    #[arg(long, default_value = "left")]
    eye: String,
    /// Replace FILE if it exists.
    #[arg(long)]
    force: bool,
    /// Also write a tonemapped PNG preview (FILE with .png).
    #[arg(long)]
    preview: bool,
}

/// `fovea` with no arguments renders with every default.
#[derive(Parser)]
struct DefaultRender {
    #[command(flatten)]
    opts: RenderOpts,
}

// Parsed once per run: the variants' sizes do not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand)]
enum Command {
    /// Render frames to PNG (and EXR) with a timing report.
    Render {
        // Boxed: the render options dwarf every other command's.
        #[command(flatten)]
        opts: Box<RenderOpts>,
        /// Skip overview.png (the last frame beside the same frame at full cost, every pixel
        /// traced, and the sample density with the gaze; the full-cost frame renders the last
        /// 8 frames again without foveation).
        #[arg(long)]
        no_overview: bool,
        #[command(flatten)]
        device: DeviceArgs,
    },
    /// Real-time rendering in a window: one eye or both side by side, gaze from the mouse (or
    /// --gaze), keys m / n / t cycle method, denoiser and TAA, f freezes the gaze, q or Esc quits.
    View {
        #[command(flatten)]
        opts: Box<RenderOpts>,
        /// Save the last presented image (both eyes side by side) as PNG; needs --frames N. An
        /// existing file is replaced only with --force.
        #[arg(long)]
        screenshot: Option<PathBuf>,
        /// Let --screenshot replace an existing file.
        #[arg(long)]
        force: bool,
        /// fifo (vsync, default), mailbox or immediate (fifo when the surface lacks it).
        #[arg(long, default_value = "fifo")]
        present_mode: String,
        /// The debug view shown first: off, grid (the sampling grid as traced), density (samples
        /// per pixel), rings (eccentricity rings at 5, 10, 20, 30, 40°) or stereo-diff (with
        /// --eyes both: each eye's binocular difference as a heat map, the other eye warped into
        /// it through the scene's depth); key v cycles them.
        #[arg(long, default_value = "off")]
        debug_view: String,
        #[command(flatten)]
        device: DeviceArgs,
    },
    /// Both eyes on a headset through an OpenXR runtime (Vulkan): views and gaze at each frame's
    /// predicted display time; writes DIR/frames.jsonl (one row per frame) and DIR/report.json.
    Xr {
        #[command(flatten)]
        opts: Box<RenderOpts>,
        /// Write the gaze that drove the session as a trace (a new file), replayable with
        /// `fovea render --headset <same> --gaze TRACE.csv`.
        #[arg(long)]
        record: Option<PathBuf>,
        /// Save the last rendered frame as submitted (both eyes side by side) as PNG; needs
        /// --frames. An existing file is replaced only with --force.
        #[arg(long)]
        screenshot: Option<PathBuf>,
        /// Let --screenshot replace an existing file.
        #[arg(long)]
        force: bool,
        /// The runtime space the scene camera stands in: local (the default: where the head was
        /// when the session started) or stage (the play area's floor is the scene's y = 0).
        #[arg(long, default_value = "local")]
        reference_space: String,
        #[command(flatten)]
        device: DeviceArgs,
    },
    /// Regression replay: render gaze traces and compare every frame with a stored baseline
    /// (change: FLIP/RMSE per ring; quality against the converged reference; the gaze used;
    /// cost, reported). Exit 0 within tolerance, 1 on a regression, 2 on bad input.
    Replay {
        #[command(flatten)]
        flags: ReplayFlags,
        #[command(flatten)]
        device: DeviceArgs,
    },
    /// Render a converged linear-radiance reference EXR.
    Reference {
        #[command(flatten)]
        flags: ReferenceFlags,
        #[command(flatten)]
        device: DeviceArgs,
    },
    /// Benchmark: BVH build, rays per second, per-pass GPU milliseconds, the real-time loop (one
    /// run, one device).
    Bench {
        /// Scenes of the BVH, ray and frame figures, names or paths as --scene ("" skips them).
        #[arg(long, value_delimiter = ',', default_value = "cornell-box,large")]
        scenes: Vec<String>,
        /// BVH builders to compare: binned, sbvh, sbvh:BUDGET (extra references per triangle).
        /// The first also serves the frame and VP figures; several are measured A B … B A.
        #[arg(long, value_delimiter = ',', default_value = "sbvh")]
        bvh: Vec<String>,
        /// Copy every instance into world space (meshes placed by several nodes copied per
        /// node, no instancing): the comparison of the two in one build.
        #[arg(long)]
        flatten: bool,
        /// Frame sizes WxH of the ray-throughput and Cartesian frame figures ("" skips them).
        #[arg(long, value_delimiter = ',', default_value = "320x360,1280x1440")]
        sizes: Vec<String>,
        /// Screen sizes WxH of the Visual-Polar vs Cartesian comparison ("" skips it).
        #[arg(long, value_delimiter = ',', default_value = "640x720,1280x1440")]
        vp_sizes: Vec<String>,
        /// Gaze of the Visual-Polar vs Cartesian frames as FX,FY, fractions of the screen in
        /// [0, 1] (0,0: the top-left corner; default 0.5,0.5: the centre).
        #[arg(long, default_value = "0.5,0.5")]
        vp_gaze: String,
        /// Whole frames rendered per size for the per-pass timings.
        #[arg(long, default_value_t = 2)]
        frames: u32,
        /// Per-eye size WxH of the real-time loop figures: Cornell box, both eyes, VP + SVGF, 1 vs 2
        /// frames in flight, stereo vs two mono renders ("" skips them).
        #[arg(long, default_value = "320x360")]
        loop_size: String,
        /// Timed frames of each run of the real-time loop and of the headset loop (after 2 warm-up
        /// frames; at least 2). Each run is made twice (order A B C C B A).
        #[arg(long, default_value_t = 5)]
        loop_frames: u32,
        /// Scenes of the headset loop: both eyes at each --loop-headsets size, the head on the
        /// default orbit and the simulated gaze, VP + SVGF, VP + A-SVGF and Cartesian + SVGF (2
        /// frames in flight, --loop-frames timed frames each, order A B C C B A): frames/s,
        /// per-pass GPU ms and VP / Cartesian per size ("" skips it; names as --scenes, e.g.
        /// sponza, breakfast-room from the shared scene folder).
        #[arg(long, default_value = "")]
        loop_scenes: String,
        /// Headsets of the headset loop, each at its recommended per-eye size (names from `fovea
        /// headsets` or profile paths), or per-eye sizes WxH (through the FOVE 0's frusta). The
        /// frames run the first --traversal.
        #[arg(long, default_value = fovea_tools::commands::bench_headsets::DEFAULT_HEADSETS)]
        loop_headsets: String,
        /// A keyframe file (as `fovea render --camera-path FILE`) the VP vs Cartesian frames
        /// follow, frame i at i / 70 Hz (default: the scene camera, still).
        #[arg(long)]
        camera_path: Option<PathBuf>,
        #[arg(long, default_value = "out/bench")]
        out: PathBuf,
        /// Also write each scene's triangles and each `--sizes` size's primary and indirect rays
        /// into OUT as rays_*.bin (for `scripts/embree-rays`: Embree timing the same rays).
        #[arg(long)]
        dump_rays: bool,
        #[command(flatten)]
        device: DeviceArgs,
    },
    /// List Vulkan devices, the chosen one and its limits.
    Info {
        #[command(flatten)]
        device: DeviceArgs,
    },
    /// List the headset profiles built in (config/headsets/*.toml).
    Headsets,
    /// Write one of the project's procedural scenes as glTF.
    GenScene {
        /// cornell-box, stress or large.
        kind: String,
        #[arg(long)]
        out: PathBuf,
        /// Minimum triangle count of the large scene.
        #[arg(long)]
        min_triangles: Option<usize>,
        #[arg(long)]
        force: bool,
    },
    /// Quality over a gaze sequence for each method × denoiser × TAA, still and moving camera:
    /// per-ring RMSE/SSIM against converged references → DIR/quality.json + quality.md.
    Quality {
        #[command(flatten)]
        flags: QualityFlags,
        #[command(flatten)]
        device: DeviceArgs,
    },
    /// Gaze error at display time without rendering: recordings through the latency model and
    /// each predictor, every frame against where the eye is when it is shown (median, p95, p99,
    /// share above 2.5° and 5°, per-saccade landing error) → DIR/gaze_eval.json + a table.
    GazeEval {
        /// Recordings: degrees CSVs (t_s,x_deg,y_deg,valid), fovea gaze traces, degrees:FILE or
        /// gazebase:FILE.
        #[arg(required = true)]
        traces: Vec<String>,
        /// Headset profile (its left eye's view, tracker and latency).
        #[arg(long, default_value = "fove0")]
        headset: String,
        /// Sample-to-photon latency in ms (default: the profile's tracker + render + display).
        #[arg(long, allow_hyphen_values = true)]
        latency_ms: Option<f64>,
        /// Tracker rate in Hz (default: the profile's).
        #[arg(long, allow_hyphen_values = true)]
        tracker_hz: Option<f64>,
        /// Display rate in Hz (default: the profile's refresh).
        #[arg(long, allow_hyphen_values = true)]
        display_hz: Option<f64>,
        /// Predictors, comma-separated: off, hold, linear, saccade (default: all).
        #[arg(long, value_delimiter = ',')]
        gaze_predict: Vec<String>,
        #[arg(long, default_value = "out/gaze-eval")]
        out: PathBuf,
    },
    /// Write the method table into a Markdown file (between its method-table markers) from a
    /// `fovea quality` folder and a `fovea bench` report, with a picture row and the papers' claims.
    MethodTable {
        /// A `fovea quality` output folder (e.g. run with `--methods all`).
        #[arg(long)]
        quality: PathBuf,
        /// `fovea bench` report.json files, comma-separated: the first one's first `--vp-sizes`
        /// screen gives the table's costs; every screen of every one a figure in the claims.
        #[arg(long, value_delimiter = ',', required = true)]
        bench: Vec<PathBuf>,
        /// The Markdown document to write the table into, between its method-table markers.
        #[arg(long, alias = "readme", default_value = "docs/quality.md")]
        doc: PathBuf,
        /// Folder for the picture row's images.
        #[arg(long, default_value = "docs/methods")]
        pictures: PathBuf,
        /// `fovea quality` reports (quality.json), comma-separated, each of `vp` and one other
        /// method at VP's sample count (a profile's budget knob): one claim line each.
        #[arg(long, value_delimiter = ',')]
        equal_samples: Vec<PathBuf>,
    },
    /// Perceived quality against cost: `fovea quality` folders scored by FovVideoVDP
    /// (scripts/perceptual) → per scene, size, gaze and camera a table and plots of JOD against
    /// samples and GPU time per frame, one line per method + filters → DIR/perceptual.md + jod_*.png
    PerceptualReport {
        /// `fovea quality` folders, each with the perceptual.json of scripts/perceptual.
        #[arg(required = true)]
        folders: Vec<PathBuf>,
        #[arg(long, default_value = "out/perceptual")]
        out: PathBuf,
    },
    /// Compare a frame with a reference (RMSE, PSNR, SSIM), whole-frame and per eccentricity ring.
    Eval {
        /// Reference: a linear EXR (e.g. from `fovea reference`) or a PNG (taken as displayed).
        #[arg(long)]
        reference: PathBuf,
        /// Frame to evaluate, of the reference's size and kind (e.g. `fovea render --exr`, or its PNG).
        #[arg(long)]
        test: PathBuf,
        /// Gaze point X,Y in image pixels (y down), or center; rings are centred on it.
        #[arg(long)]
        gaze: String,
        /// Equal-width rings from the gaze out to the farthest image corner.
        #[arg(long, default_value_t = 20)]
        rings: usize,
        /// Output folder for eval.json and eval.png (must hold only fovea's own outputs).
        #[arg(long, default_value = "out/eval")]
        out: PathBuf,
        /// Also report rings of true eccentricity (degrees) through this headset's left-eye FOV
        /// (eval.json `true_eccentricity`).
        #[arg(long)]
        headset: Option<String>,
        /// FLIP's pixels per degree (default: the image width over the --headset eye's
        /// horizontal FOV, the FOVE 0's without --headset); eval.json `flip_ppd`.
        #[arg(long)]
        ppd: Option<f32>,
    },
    /// Split `fovea quality`, `fovea reference` or `fovea replay` into independent jobs for a batch
    /// scheduler
    /// (Slurm job arrays: scripts/sweep-slurm) or a shell loop, and merge their results into
    /// the files the one-process command writes (docs/guide/sweeps.md).
    Sweep {
        #[command(subcommand)]
        command: SweepCommand,
    },
}

#[derive(Subcommand)]
enum SweepCommand {
    /// Write DIR/sweep.json and DIR/jobs.jsonl: the jobs of a `fovea quality …`,
    /// `fovea reference …` or `fovea replay …` command, given after the sweep's own flags
    /// (references split into sample batches whose merge is exact, then one job per combination
    /// or trace).
    Plan {
        /// The sweep folder (new or empty).
        #[arg(long)]
        out: PathBuf,
        /// Scenes, one study (one merged output) each; default the command's --scene (quality and
        /// reference sweeps).
        #[arg(long, value_delimiter = ',')]
        scenes: Vec<String>,
        /// Headset profiles, one study each; default the command's --headset (quality and
        /// reference sweeps).
        #[arg(long, value_delimiter = ',')]
        headsets: Vec<String>,
        /// Gaze sources of a quality sweep, one study each; default the command's --gaze.
        #[arg(long, value_delimiter = ',')]
        gazes: Vec<String>,
        /// Reference batches (16 samples each) per reference job: a power of two.
        #[arg(long, default_value_t = 4)]
        batches_per_job: u32,
        /// The one-process command: `quality …`, `reference …` or `replay …` (comparing with
        /// existing baselines) with that command's flags (without --out).
        #[arg(
            required = true,
            trailing_var_arg = true,
            allow_hyphen_values = true,
            value_name = "COMMAND"
        )]
        command: Vec<String>,
    },
    /// Run job K of the sweep in DIR (K from --index, else the Slurm array task's
    /// SLURM_ARRAY_TASK_ID; plus --offset): its result appears whole in its folder or not at all;
    /// a finished job is left as it is; a failure is recorded and exits non-zero.
    Run {
        /// The sweep folder (`fovea sweep plan --out`).
        dir: PathBuf,
        /// The job: its line in jobs.jsonl, counted from 0.
        #[arg(long)]
        index: Option<u32>,
        /// Added to the index (Slurm arrays whose task ids start at 0).
        #[arg(long, default_value_t = 0)]
        offset: u32,
    },
    /// Every job's state: done, running, failed or missing, with the reason.
    Status {
        /// The sweep folder.
        dir: PathBuf,
        /// As JSON.
        #[arg(long)]
        json: bool,
    },
    /// Job indices, one per line, for a shell loop, GNU parallel or Slurm.
    List {
        /// The sweep folder.
        dir: PathBuf,
        /// Only the jobs of this stage (reference, run).
        #[arg(long)]
        stage: Option<String>,
        /// Only jobs not done.
        #[arg(long)]
        pending: bool,
        /// Print the stages in the order they run instead.
        #[arg(long)]
        stages: bool,
        /// Print Slurm array chunks "OFFSET SPEC" whose task ids stay below this (MaxArraySize).
        #[arg(long)]
        arrays: Option<u32>,
    },
    /// Gather every job's result into DIR/merged/<study>/: the files the one-process command
    /// writes (refused while a job is not done or the jobs ran on different devices).
    Merge {
        /// The sweep folder.
        dir: PathBuf,
    },
}

/// `fovea replay`'s length for a new baseline without `--frames`.
const DEFAULT_REPLAY_FRAMES: u32 = commands::replay::DEFAULT_FRAMES;

/// `fovea render`'s length without `--frames`.
const DEFAULT_RENDER_FRAMES: u32 = 24;

/// What a command takes when a render flag is not given.
struct RenderDefaults {
    frames: u32,
    gaze: &'static str,
    out: &'static str,
    scale: f32,
}

/// `--scale` of `fovea render`, `view` and `replay` without the flag.
const DEFAULT_SCALE: f32 = 0.25;

/// The flags `fovea render` and `fovea view` share, checked.
fn render_args<'a>(
    opts: &'a RenderOpts,
    camera: &'a fovea_stage::look::CameraOptions,
    device: &'a DeviceArgs,
    profile: &RenderProfile,
    defaults: RenderDefaults,
) -> Result<commands::render::RenderArgs<'a>> {
    Ok(commands::render::RenderArgs {
        scene: &opts.scene,
        method: &opts.method,
        width: opts.width,
        height: opts.height,
        scale: opts.scale.unwrap_or(defaults.scale),
        headset: &opts.headset,
        gaze: opts.gaze.as_deref().unwrap_or(defaults.gaze),
        frames: opts.frames.unwrap_or(defaults.frames),
        out: opts
            .out
            .as_deref()
            .unwrap_or(std::path::Path::new(defaults.out)),
        exr: opts.exr,
        camera_path: fovea_stage::camera_path::CameraMotion::from_flag(
            opts.camera_path.as_deref(),
        )?,
        seed: opts.seed,
        max_depth: opts.max_depth,
        exposure: commands::setup::parse_exposure(&opts.exposure)?,
        tone: commands::setup::parse_tone(&opts.tone)?,
        overview: false,
        profile: profile.clone(),
        debug_views: opts.debug_views,
        denoiser: &opts.denoiser,
        taa: &opts.taa,
        device: device.device.as_deref(),
        validation: device.validation,
        eyes: commands::setup::Eyes::parse(&opts.eyes)?,
        frames_in_flight: opts.frames_in_flight,
        camera,
    })
}

/// Exit status 1 for errors, 128 + the signal for a run stopped by SIGINT/SIGTERM.
fn main() -> std::process::ExitCode {
    match run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("Error: {e:?}");
            if let Some(interrupted) = e.downcast_ref::<fovea_tools::interrupt::Interrupted>() {
                return std::process::ExitCode::from(interrupted.exit_code());
            }
            // fovea replay: 1 = a regression, 2 = bad input (everything else: 1).
            if e.downcast_ref::<commands::replay::BadInput>().is_some() {
                return std::process::ExitCode::from(2);
            }
            std::process::ExitCode::FAILURE
        }
    }
}

fn run() -> Result<()> {
    let cli = Cli::parse();
    let command = cli.command.unwrap_or_else(|| Command::Render {
        opts: Box::new(DefaultRender::parse_from(["fovea"]).opts),
        no_overview: false,
        device: DeviceArgs {
            device: None,
            validation: false,
            traversal: "auto".into(),
        },
    });
    if matches!(
        command,
        Command::Render { .. }
            | Command::Xr { .. }
            | Command::Sweep {
                command: SweepCommand::Run { .. }
            }
    ) {
        // Only `render`, `xr` and a sweep's job check for it (a clean end); other commands stop
        // at once.
        fovea_tools::interrupt::install()?;
    }
    match command {
        Command::Render {
            opts,
            no_overview,
            device,
        } => {
            device.choose_traversal()?;
            let profile = opts.profile()?;
            let camera = opts.look.camera()?;
            let mut args = render_args(
                &opts,
                &camera,
                &device,
                &profile,
                RenderDefaults {
                    frames: DEFAULT_RENDER_FRAMES,
                    gaze: "sim:1",
                    out: "out/render",
                    scale: DEFAULT_SCALE,
                },
            )?;
            args.overview = !no_overview;
            commands::render::run(&args)
        }
        Command::View {
            opts,
            screenshot,
            force,
            present_mode,
            debug_view,
            device,
        } => {
            device.choose_traversal()?;
            let profile = opts.profile()?;
            let camera = opts.look.camera()?;
            // Without --frames the run has no length: the camera path's period is a long one.
            let render = render_args(
                &opts,
                &camera,
                &device,
                &profile,
                RenderDefaults {
                    frames: u32::MAX,
                    gaze: "center",
                    out: "out/render",
                    scale: DEFAULT_SCALE,
                },
            )?;
            commands::view::run(&commands::view::ViewArgs {
                frames: opts.frames,
                screenshot: screenshot.as_deref(),
                force,
                present_mode: &present_mode,
                mouse_gaze: opts.gaze.is_none(),
                debug_view: fovea_tools::viewer::debug::DebugView::parse(&debug_view)?,
                render,
            })
        }
        Command::Xr {
            opts,
            record,
            screenshot,
            force,
            reference_space,
            device,
        } => {
            device.choose_traversal()?;
            let profile = opts.profile()?;
            let camera = opts.look.camera()?;
            // The `frames` of RenderArgs is unused: xr ends on --frames rendered frames or the session.
            let render = render_args(
                &opts,
                &camera,
                &device,
                &profile,
                RenderDefaults {
                    frames: u32::MAX,
                    gaze: "center",
                    out: "out/xr",
                    scale: 1.0,
                },
            )?;
            if opts.eyes != "left" && opts.eyes != "both" {
                anyhow::bail!(
                    "fovea xr renders both eyes; --eyes {} does not apply",
                    opts.eyes
                );
            }
            commands::xr::run(&commands::xr::XrArgs {
                render,
                frames: opts.frames,
                gaze: opts.gaze.as_deref(),
                record: record.as_deref(),
                screenshot: screenshot.as_deref(),
                force,
                reference_space: commands::xr::ReferenceSpace::parse(&reference_space)?,
            })
        }
        Command::Replay { flags, device } => {
            with_replay_args(flags, &device, &mut commands::replay::run)
        }
        Command::Reference { flags, device } => {
            with_reference_args(flags, &device, &mut commands::reference::run)
        }
        Command::Bench {
            scenes,
            bvh,
            flatten,
            sizes,
            vp_sizes,
            vp_gaze,
            frames,
            loop_size,
            loop_frames,
            loop_scenes,
            loop_headsets,
            camera_path,
            out,
            dump_rays,
            device,
        } => {
            let camera_path = camera_path
                .map(|f| fovea_stage::camera_keys::CameraKeys::load(&f))
                .transpose()
                .context("--camera-path")?;
            let builders = bvh
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
                parse(&sizes).context("--sizes")?,
                parse(&vp_sizes).context("--vp-sizes")?,
            );
            let loop_size = (!loop_size.is_empty())
                .then(|| parse_size(&loop_size))
                .transpose()
                .context("--loop-size")?;
            let scenes: Vec<String> = scenes.into_iter().filter(|s| !s.is_empty()).collect();
            let loop_scenes: Vec<String> = loop_scenes
                .split(',')
                .map(str::trim)
                .filter(|s| !s.is_empty())
                .map(String::from)
                .collect();
            let loop_headsets = if loop_scenes.is_empty() {
                Vec::new()
            } else {
                commands::bench_headsets::LoopHeadset::parse_list(&loop_headsets)?
            };
            let traversals = parse_traversals(&device.traversal)?;
            commands::choose_traversal(traversals[0]);
            commands::bench::run(&commands::bench::BenchArgs {
                scenes: &scenes,
                builders: &builders,
                flatten,
                sizes: &sizes,
                vp_sizes: &vp_sizes,
                vp_gaze: parse_gaze_fraction(&vp_gaze).context("--vp-gaze")?,
                frames,
                loop_size,
                loop_frames,
                loop_scenes: &loop_scenes,
                loop_headsets: &loop_headsets,
                camera_path: camera_path.as_ref(),
                out: &out,
                dump_rays,
                traversals: &traversals,
                device: device.device.as_deref(),
                validation: device.validation,
            })
        }
        Command::Headsets => commands::headsets::run(),
        Command::Info { device } => {
            device.choose_traversal()?;
            commands::info::run(device.device.as_deref())
        }
        Command::GenScene {
            kind,
            out,
            min_triangles,
            force,
        } => commands::gen_scene::run(&kind, &out, min_triangles, force),
        Command::Quality { flags, device } => {
            with_quality_args(flags, &device, &mut commands::quality::run)
        }
        Command::Sweep { command } => sweep(command),
        Command::GazeEval {
            traces,
            headset,
            latency_ms,
            tracker_hz,
            display_hz,
            gaze_predict,
            out,
        } => commands::gaze_eval::run(&commands::gaze_eval::GazeEvalArgs {
            traces: &traces,
            headset: &headset,
            latency_ms,
            tracker_hz,
            display_hz,
            predict: &gaze_predict,
            out: &out,
        }),
        Command::PerceptualReport { folders, out } => {
            commands::perceptual_report::run(&commands::perceptual_report::PerceptualReportArgs {
                folders: &folders,
                out: &out,
            })
        }
        Command::MethodTable {
            quality,
            bench,
            doc,
            pictures,
            equal_samples,
        } => commands::method_table::run(&commands::method_table::MethodTableArgs {
            quality: &quality,
            bench: &bench,
            doc: &doc,
            pictures: &pictures,
            equal_samples: &equal_samples,
        }),
        Command::Eval {
            reference,
            test,
            gaze,
            rings,
            out,
            headset,
            ppd,
        } => commands::eval::run(&commands::eval::EvalArgs {
            reference: &reference,
            test: &test,
            gaze: &gaze,
            rings,
            out: &out,
            headset: headset.as_deref(),
            ppd,
        }),
    }
}

/// `fovea quality`'s flags as its arguments, handed to `run`.
fn with_quality_args(
    flags: QualityFlags,
    device: &DeviceArgs,
    run: &mut dyn FnMut(&commands::quality::QualityArgs) -> Result<()>,
) -> Result<()> {
    device.choose_traversal()?;
    let QualityFlags {
        scene,
        width,
        height,
        headset,
        gaze,
        frames,
        eval_frames,
        methods,
        denoisers,
        taa,
        cameras,
        eyes,
        reference_spp,
        references,
        rings,
        seed,
        profile,
        blur_sigma,
        blur_space,
        out,
        look,
        latency,
    } = flags;
    let base = match &profile {
        Some(path) => RenderProfile::load(path)?,
        None => RenderProfile::default(),
    };
    let profile = base.override_with(&ProfileOverrides {
        blur_sigma,
        blur_space,
        environment: look.environment()?,
        texture_lod: look.texture_lod.clone(),
        path_regularisation: look.path_regularisation,
        offscreen_samples: look.offscreen_samples.clone(),
        resampling: look.resampling.clone(),
        gaze_timing: latency.timing()?,
        ..Default::default()
    })?;
    let all: Vec<String> = DenoiserSettings::NAMES
        .iter()
        .map(|s| s.to_string())
        .collect();
    let stereo_noises = match &look.stereo_noise {
        Some(list) => list
            .split(',')
            .map(|n| StereoNoise::parse(n.trim()).context("--stereo-noise"))
            .collect::<Result<Vec<_>>>()?,
        None => Vec::new(),
    };
    run(&commands::quality::QualityArgs {
        scene: &scene,
        width,
        height,
        headset: &headset,
        gaze: &gaze,
        frames,
        eval_frames,
        methods: &commands::quality::expand_methods(methods),
        denoisers: if denoisers.is_empty() {
            &all
        } else {
            &denoisers
        },
        taa: &taa,
        cameras: &cameras,
        reference_spp,
        rings,
        seed,
        profile,
        eyes: commands::setup::Eyes::parse(&eyes)?,
        stereo_noises: &stereo_noises,
        camera: &look.camera()?,
        references: references.as_deref(),
        out: &out,
        device: device.device.as_deref(),
        validation: device.validation,
    })
}

/// `fovea replay`'s flags as its arguments, handed to `run`.
fn with_replay_args(
    flags: ReplayFlags,
    device: &DeviceArgs,
    run: &mut dyn FnMut(&commands::replay::ReplayArgs) -> Result<()>,
) -> Result<()> {
    device.choose_traversal()?;
    let ReplayFlags {
        traces,
        baseline,
        update_baseline,
        reference_spp,
        rings,
        change_flip,
        change_rmse,
        quality_rel,
        quality_abs,
        opts,
    } = flags;
    let profile = opts.profile()?;
    let camera = opts.look.camera()?;
    let mut render = render_args(
        &opts,
        &camera,
        device,
        &profile,
        RenderDefaults {
            frames: DEFAULT_REPLAY_FRAMES,
            gaze: "center",
            out: "out/replay",
            scale: DEFAULT_SCALE,
        },
    )?;
    // Small by default: replays run in the test suite.
    render.width = Some(opts.width.unwrap_or(64));
    render.height = Some(opts.height.unwrap_or(72));
    let tolerances = Tolerances {
        change_flip,
        change_rmse,
        quality_rel,
        quality_abs,
        ..Tolerances::default()
    };
    run(&commands::replay::ReplayArgs {
        traces: &traces,
        baseline: &baseline,
        frames: opts.frames,
        out: render.out,
        render,
        update: update_baseline,
        reference_spp,
        rings,
        tolerances,
    })
}

/// `fovea reference`'s flags as its arguments, handed to `run`.
fn with_reference_args(
    flags: ReferenceFlags,
    device: &DeviceArgs,
    run: &mut dyn FnMut(&commands::reference::ReferenceArgs) -> Result<()>,
) -> Result<()> {
    device.choose_traversal()?;
    let ReferenceFlags {
        scene,
        width,
        height,
        spp,
        max_depth,
        seed,
        out,
        look,
        headset,
        eye,
        force,
        preview,
    } = flags;
    run(&commands::reference::ReferenceArgs {
        camera: &look.camera()?,
        headset: &headset,
        eye: match commands::setup::Eyes::parse(&eye)? {
            commands::setup::Eyes::Left => fovea_hal::Eye::Left,
            commands::setup::Eyes::Right => fovea_hal::Eye::Right,
            commands::setup::Eyes::Both => {
                anyhow::bail!("--eye both: a reference is one eye (left or right)")
            }
        },
        environment: look.environment()?,
        path_regularisation: fovea_tools::render_profile::check_path_regularisation(
            look.path_regularisation,
            "--path-regularisation",
        )?,
        scene: &scene,
        width,
        height,
        spp,
        max_depth,
        seed,
        out: &out,
        force,
        preview,
        device: device.device.as_deref(),
        validation: device.validation,
    })
}

/// A sweep's command (`fovea ARGS…`) parsed as the command line parses it.
fn parse_study(
    argv: &[String],
    f: &mut dyn FnMut(fovea_tools::sweep::Study<'_>) -> Result<()>,
) -> Result<()> {
    use fovea_tools::sweep::Study;
    let words = std::iter::once("fovea").chain(argv.iter().map(String::as_str));
    let cli = Cli::try_parse_from(words).map_err(|e| {
        let message = e.to_string();
        let first = message
            .lines()
            .next()
            .unwrap_or("")
            .trim_start_matches("error: ");
        anyhow::anyhow!("`fovea {}`: {first}", argv.join(" "))
    })?;
    match cli.command {
        Some(Command::Quality { flags, device }) => {
            with_quality_args(flags, &device, &mut |q| f(Study::Quality(q)))
        }
        Some(Command::Reference { flags, device }) => {
            with_reference_args(flags, &device, &mut |r| f(Study::Reference(r)))
        }
        Some(Command::Replay { flags, device }) => {
            with_replay_args(flags, &device, &mut |r| f(Study::Replay(r)))
        }
        _ => bail!(
            "fovea sweep splits `fovea quality …`, `fovea reference …` or `fovea replay …`, not \
             `fovea {}`",
            argv.join(" ")
        ),
    }
}

fn sweep(command: SweepCommand) -> Result<()> {
    use fovea_tools::sweep;
    match command {
        SweepCommand::Plan {
            out,
            scenes,
            headsets,
            gazes,
            batches_per_job,
            command,
        } => sweep::plan(
            &sweep::PlanArgs {
                out: &out,
                command: &command,
                axes: sweep::Axes {
                    scenes,
                    headsets,
                    gazes,
                },
                batches_per_job,
            },
            &parse_study,
        ),
        SweepCommand::Run { dir, index, offset } => sweep::run(&dir, index, offset, &parse_study),
        SweepCommand::Status { dir, json } => sweep::status(&dir, json, &parse_study),
        SweepCommand::List {
            dir,
            stage,
            pending,
            stages,
            arrays,
        } => sweep::list(
            &dir,
            &sweep::ListArgs {
                stage: stage.as_deref(),
                pending,
                stages,
                arrays,
            },
            &parse_study,
        ),
        SweepCommand::Merge { dir } => sweep::merge(&dir, &parse_study),
    }
}

fn parse_size(s: &str) -> Result<(u32, u32)> {
    let parsed = s
        .split_once('x')
        .and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?)));
    match parsed {
        Some((w, h)) if w > 0 && h > 0 => Ok((w, h)),
        _ => anyhow::bail!("size '{s}' is not WIDTHxHEIGHT (e.g. 320x360)"),
    }
}

/// `--vp-gaze FX,FY`: two fractions of the screen, each in [0, 1].
fn parse_gaze_fraction(spec: &str) -> Result<glam::Vec2> {
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

#[cfg(test)]
mod docs_tests;
