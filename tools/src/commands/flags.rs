//! The flag groups several commands share: the Vulkan device and traversal, the scene's camera
//! and default environment, the gaze latency model.

use anyhow::{bail, Context as _, Result};

#[derive(clap::Args)]
pub struct DeviceArgs {
    /// Vulkan device: index from `fovea info` or a name substring (default: best GPU, else CPU).
    #[arg(long, global = true)]
    pub device: Option<String>,
    /// Turn on Vulkan validation (always on in debug builds); any message fails the run.
    #[arg(long, global = true)]
    pub validation: bool,
    /// BVH traversal of the kernels that trace: auto (gpu on a discrete, integrated or virtual
    /// GPU, cpu-driver on a CPU driver such as lavapipe), cpu-driver (4-wide nodes in texel
    /// buffers, stack in shared memory) or gpu (compressed 8-wide nodes in storage buffers,
    /// children in order of distance, stack in private memory). `fovea bench` takes a comma list:
    /// ray figures and traversal counters for each, frames with the first.
    #[arg(long, global = true, default_value = "auto")]
    pub traversal: String,
}

impl DeviceArgs {
    /// `--traversal` of a command that renders: one traversal, the process's for every device it
    /// opens.
    pub fn choose_traversal(&self) -> Result<()> {
        let [choice] = parse_traversals(&self.traversal)?[..] else {
            bail!("--traversal: one of auto, cpu-driver, gpu (a list only for fovea bench)");
        };
        super::choose_traversal(choice);
        Ok(())
    }
}

/// `--traversal` as a comma list.
pub fn parse_traversals(spec: &str) -> Result<Vec<fovea_renderer::traversal::TraversalChoice>> {
    spec.split(',')
        .map(|s| s.trim().parse().map_err(anyhow::Error::msg))
        .collect::<Result<Vec<_>>>()
        .context("--traversal")
}

/// The camera and the default environment (every command that renders the scene camera).
#[derive(clap::Args)]
pub struct SceneFlags {
    /// A camera of the scene file by index or name (default: its first; with none, a camera
    /// that frames the scene's bounds).
    #[arg(long)]
    pub camera: Option<String>,
    /// A free camera at X,Y,Z (with --camera-look) instead of the file's.
    #[arg(long, allow_hyphen_values = true)]
    pub camera_pos: Option<String>,
    /// The point X,Y,Z the free camera looks at (+Y up).
    #[arg(long, allow_hyphen_values = true)]
    pub camera_look: Option<String>,
    /// Vertical field of view in degrees, in (1, 170), with --projection scene-camera: of the free
    /// or framing camera (default 60), or replacing the chosen glTF camera's.
    #[arg(long)]
    pub fov: Option<f32>,
    /// How each eye sees the scene: headset (the default: through the headset profile's
    /// asymmetric per-eye FOV and eye offset, the camera being the head) or scene-camera (the
    /// camera's own symmetric FOV at the output's aspect ratio).
    #[arg(long, default_value = "headset")]
    pub projection: String,
    /// Metres per scene unit (default 1, glTF's metre; 0.01 for a scene authored in
    /// centimetres): the eyes' offsets and a headset's movements are metres.
    #[arg(long, default_value_t = 1.0)]
    pub world_scale: f32,
    /// The default sun's AZIMUTH,ELEVATION in degrees (azimuth from +Z toward +X; default 30,60);
    /// only for scenes without lights of their own.
    #[arg(long, allow_hyphen_values = true)]
    pub sun: Option<String>,
    /// The default sun's illuminance (default 3; 0 = no sun).
    #[arg(long)]
    pub sun_intensity: Option<f32>,
    /// The sky's radiance scale (default 0.5 for scenes without lights; 0 = no sky; a scene
    /// with lights gets a sky only when this is given and > 0).
    #[arg(long)]
    pub sky_intensity: Option<f32>,
    /// Texture filtering: cones (a mip level from each ray's cone, whose spread is the sample's
    /// footprint on the screen; the default) or off (every lookup reads level 0).
    #[arg(long)]
    pub texture_lod: Option<String>,
    /// Samples far off the screen: cull (the default: a sample farther off than the way back
    /// and the filters read, three footprints and three pixels, is not traced; the picture is the
    /// same) or trace (every sample, as in the paper; only the paper's Visual-Polar layout, the
    /// log-polar and composite buffers and random acuity place samples there).
    #[arg(long)]
    pub offscreen_samples: Option<String>,
    /// Light-sample reuse before the denoiser: off (the default: next-event estimation at every
    /// hit), di (ReSTIR DI at the primary hit: light candidates resampled per sample, reused
    /// from the previous frame and from grid neighbours) or di+gi (ReSTIR GI too: the primary
    /// hit's bounce reused the same way by reconnection); spaces with temporal filters only;
    /// parameters from the profile's [resampling].
    #[arg(long)]
    pub resampling: Option<String>,
    /// How the two eyes' random numbers relate in a stereo run (docs/design/random-numbers.md):
    /// screen (the default: texel (x, y) of both eyes draws the same numbers), independent (each
    /// eye its own sequence) or surface (the path after the primary hit drawn from the hit's world position at
    /// the sample's footprint: the noise lies on the surfaces). `fovea quality` takes a
    /// comma-separated list and renders each.
    #[arg(long)]
    pub stereo_noise: Option<String>,
    /// With both eyes, whether each eye's samples also take the other eye's samples of the same
    /// surface this frame, found through the depth, before the denoiser (where a glossy lobe is
    /// narrower than the angle between the eyes, less): auto (the default: where the method's
    /// space has temporal filters), on (refused where it cannot) or off.
    #[arg(long)]
    pub cross_eye_reuse: Option<String>,
    /// Path regularisation strength in [0, 100] (default 1): after a low-density bounce, later
    /// vertices' glossy lobes are widened so sunlight focused through them stops making
    /// fireflies; biased, 0 = off (the unbiased estimator).
    #[arg(long)]
    pub path_regularisation: Option<f32>,
    /// An equirectangular HDR environment map (.exr or .hdr, at most 8192×4096) seen by escaping
    /// rays and sampled by next-event estimation; replaces the sky, and the default sun stays off
    /// unless --sun is given.
    #[arg(long)]
    pub env: Option<std::path::PathBuf>,
    /// The default sky's model: gradient (the default: a horizon-to-zenith gradient) or preetham
    /// (Preetham et al. 1999's daylight, turbidity 3, around the --sun position).
    #[arg(long)]
    pub sky: Option<String>,
    /// The environment map's rotation about +Y in degrees (counter-clockwise seen from above; default 0).
    #[arg(long, allow_hyphen_values = true)]
    pub env_rotation: Option<f32>,
    /// The environment map's radiance scale (default 1).
    #[arg(long)]
    pub env_intensity: Option<f32>,
    /// When the default sun and sky light the scene: auto (the default: when the scene's own
    /// emitters send out less than 2 % of the default sun's power through its bounds), on
    /// (always), off (never: the scene as authored).
    #[arg(long)]
    pub default_light: Option<String>,
}

impl SceneFlags {
    pub fn camera(&self) -> Result<fovea_stage::look::CameraOptions> {
        Ok(fovea_stage::look::CameraOptions {
            camera: self.camera.clone(),
            position: self.camera_pos.clone(),
            look: self.camera_look.clone(),
            fov: self.fov,
            projection: fovea_stage::look::Projection::parse(&self.projection)?,
            world_scale: self.world_scale,
        })
    }

    pub fn environment(&self) -> Result<fovea_stage::look::EnvironmentOptions> {
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
pub struct LatencyFlags {
    /// Gaze-to-photon latency in ms: a frame displayed at T sees the tracker samples taken up to
    /// T − this (default: the headset profile's tracker + render + display latency). Any of
    /// --latency-ms, --tracker-hz, --gaze-predict turns this latency model on.
    #[arg(long, allow_hyphen_values = true)]
    pub latency_ms: Option<f64>,
    /// Tracker rate of the latency model in Hz (default: the headset profile's).
    #[arg(long, allow_hyphen_values = true)]
    pub tracker_hz: Option<f64>,
    /// Gaze prediction at the display time: off (the newest sample) | hold | linear | saccade
    /// (default saccade, chosen by `fovea gaze-eval`; see docs/guide/gaze-latency.md).
    #[arg(long)]
    pub gaze_predict: Option<String>,
}

impl LatencyFlags {
    pub fn timing(&self) -> Result<fovea_stage::gaze::GazeTiming> {
        fovea_stage::gaze::GazeTiming::from_flags(
            self.latency_ms,
            self.tracker_hz,
            self.gaze_predict.as_deref(),
        )
    }
}
