//! What a frame is made of, as the engine's callers and its views see it: the camera, each
//! view's input, the engine settings and the counts a frame reports. `pipeline` (the engine) and
//! `view` (one eye) both read these.

use crate::error::{Error, Result};
use crate::graph::{ExternalImage, SubmitSync};
use crate::passes::denoise::DenoiserSettings;
use crate::passes::exposure::Exposure;
use crate::passes::resampling::ResamplingSettings;
use crate::passes::taa::TaaMode;
use crate::passes::tonemap::ToneCurve;
use crate::scene::Camera;
use crate::vk::Buffer;
use crate::way_back::blur::BlurSettings;
use glam::{Mat4, UVec2, Vec2, Vec4};

/// The real-time path: primary ray, one indirect bounce, next-event estimation at both hits.
pub const REALTIME_MAX_DEPTH: u32 = 3;

/// A pinhole camera: rigid pose and the tangents of its four half-angles (left/down negative).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraPose {
    pub world_from_view: Mat4,
    pub fov_tan: Vec4,
}

impl CameraPose {
    /// A glTF camera fitted to an output size: `yfov` is kept and the horizontal extent follows
    /// the output's aspect ratio, so pixels stay square.
    pub fn from_scene_camera(camera: &Camera, width: u32, height: u32) -> CameraPose {
        let ty = (camera.yfov * 0.5).tan();
        let tx = ty * width as f32 / height as f32;
        CameraPose {
            world_from_view: camera.world_from_view,
            fov_tan: Vec4::new(-tx, tx, -ty, ty),
        }
    }
}

#[derive(Clone, Copy, Debug)]
pub struct RenderSettings {
    pub max_depth: u32,
    pub seed: u32,
    pub exposure: Exposure,
    pub tone_curve: ToneCurve,
    /// Foveated blur after the remap (Visual-Polar only).
    pub blur: BlurSettings,
    /// Denoiser between the tracer and the screen (fixed for the renderer's life: it owns state).
    pub denoiser: DenoiserSettings,
    /// TAA after the denoiser (fixed for the renderer's life, like the denoiser); when on, the
    /// tracer jitters by its Halton sequence instead of the RNG.
    pub taa: TaaMode,
    /// How the views' (eyes') random sequences relate.
    pub stereo_noise: StereoNoise,
    /// `StereoNoise::Surface`: the cells' edge in sample footprints (rounded down to a power of
    /// two in world units). Larger cells share more samples between the eyes and make coarser
    /// noise within each.
    pub surface_cell: f32,
    /// With two views (the eyes): whether each eye's samples also take the other eye's sample
    /// of the same surface this frame before the filters (passes/cross_eye.rs). Ignored with
    /// one view.
    pub cross_eye_reuse: CrossEyeReuse,
    /// Texture filtering of frames (references always read level 0: point samples converge to
    /// the box-filtered pixel).
    pub texture_lod: TextureLod,
    /// How the environment map is found: next-event estimation with MIS (the default), or by
    /// BRDF-sampled rays alone (the comparison the importance-sampling tests measure against).
    pub environment_sampling: EnvironmentSampling,
    /// Path regularisation strength (shaders/common/path.glsl, `regularise`): after a scattering
    /// bounce of low pdf, later vertices are roughened so that light a near-specular lobe would
    /// focus (sunlight through a diffuse-then-glossy path: fireflies) is spread out. Biased, like
    /// every such filter; 0 turns it off (the unbiased estimator), 1 is the default.
    pub path_regularisation: f32,
    /// Whether samples far off the screen are traced (only the paper's Visual-Polar layout, the
    /// log-polar and composite buffers and random acuity place any there).
    pub offscreen_samples: OffscreenSamples,
    /// Reuse of light samples between the sampling grid's texels and frames (ReSTIR DI) before
    /// the denoiser; off by default. Fixed for the renderer's life (it owns reservoirs).
    pub resampling: ResamplingSettings,
}

/// `RenderSettings::environment_sampling`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum EnvironmentSampling {
    /// Light selection picks the environment like any light, and BRDF rays that escape to it
    /// are weighed against that sample (power heuristic).
    #[default]
    ImportanceMis,
    /// Only escaping BRDF rays count it (a selected environment sample contributes nothing).
    BrdfOnly,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            max_depth: REALTIME_MAX_DEPTH,
            seed: 1,
            exposure: Exposure::default(),
            tone_curve: ToneCurve::Aces,
            blur: BlurSettings::default(),
            denoiser: DenoiserSettings::None,
            taa: TaaMode::Off,
            stereo_noise: StereoNoise::default(),
            surface_cell: DEFAULT_SURFACE_CELL,
            cross_eye_reuse: CrossEyeReuse::Off,
            environment_sampling: EnvironmentSampling::default(),
            texture_lod: TextureLod::default(),
            path_regularisation: DEFAULT_PATH_REGULARISATION,
            offscreen_samples: OffscreenSamples::default(),
            resampling: ResamplingSettings::default(),
        }
    }
}

/// `RenderSettings::surface_cell` unless the user sets it.
pub const DEFAULT_SURFACE_CELL: f32 = 1.0;
/// The range of `RenderSettings::surface_cell` (footprints).
pub const SURFACE_CELL_RANGE: (f32, f32) = (0.25, 16.0);

/// `RenderSettings::path_regularisation` unless the user sets it.
pub const DEFAULT_PATH_REGULARISATION: f32 = 1.0;

/// What the tracer does with a sample whose screen position lies off the screen
/// (`RenderSettings::offscreen_samples`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum OffscreenSamples {
    /// Samples farther off the screen than the way back and the filters read (three footprints
    /// and three pixels, trace.comp) hold no sample, like clipped texels: the picture is the
    /// same, the paper layout's off-screen work is not done (`FrameStats::samples_culled`).
    #[default]
    Cull,
    /// Every sample is traced, as in the paper (Koskela et al. 2019).
    Trace,
}

impl OffscreenSamples {
    pub const NAMES: &'static str = "cull, trace";

    pub fn parse(name: &str) -> Result<OffscreenSamples> {
        match name {
            "cull" => Ok(OffscreenSamples::Cull),
            "trace" => Ok(OffscreenSamples::Trace),
            other => Err(Error::Invalid(format!(
                "off-screen samples '{other}' is not one of {}",
                Self::NAMES
            ))),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            OffscreenSamples::Cull => "cull",
            OffscreenSamples::Trace => "trace",
        }
    }
}

/// How texture lookups choose a mip level (`RenderSettings::texture_lod`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum TextureLod {
    /// Ray cones (Akenine-Möller et al. 2019): each sample's footprint on the screen sets the
    /// primary spread, so sparse periphery samples read coarser mips instead of aliasing.
    #[default]
    RayCones,
    /// Every lookup reads level 0 (bilinear point sampling).
    Off,
}

impl TextureLod {
    pub const NAMES: &'static str = "cones, off";

    pub fn parse(name: &str) -> Result<TextureLod> {
        match name {
            "cones" => Ok(TextureLod::RayCones),
            "off" => Ok(TextureLod::Off),
            other => Err(Error::Invalid(format!(
                "texture LOD '{other}' is not one of {}",
                Self::NAMES
            ))),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            TextureLod::RayCones => "cones",
            TextureLod::Off => "off",
        }
    }
}

/// How the two eyes' 1-spp noise relates (`RenderSettings::stereo_noise`; the seeds' design is
/// docs/design/random-numbers.md).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum StereoNoise {
    /// Each view gets its own random sequence (the view index salts the seed).
    Independent,
    /// Every view uses the same seed: texel (x, y) of both eyes draws the same random numbers.
    /// The default: after SVGF it gave the smallest binocular difference at an unchanged
    /// single-eye FLIP (docs/quality.md, "Binocular consistency"). In Visual-Polar space texel
    /// (ρ, φ) of both eyes looks at nearly one point near the fixation, where both gazes meet.
    #[default]
    Screen,
    /// The jitter as `Screen`; every number after the primary hit from the hit's world position
    /// quantised at the sample's footprint (`surface_rng_seed`, shaders/common/random.glsl):
    /// samples of both eyes that land on one surface neighbourhood draw the same path, so the
    /// noise lies on the surfaces.
    Surface,
}

impl StereoNoise {
    pub const NAMES: &'static str = "independent, screen, surface";

    pub fn parse(name: &str) -> Result<StereoNoise> {
        match name {
            "independent" => Ok(StereoNoise::Independent),
            "screen" => Ok(StereoNoise::Screen),
            "surface" => Ok(StereoNoise::Surface),
            other => Err(Error::Invalid(format!(
                "stereo noise '{other}' is not one of {}",
                Self::NAMES
            ))),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            StereoNoise::Independent => "independent",
            StereoNoise::Screen => "screen",
            StereoNoise::Surface => "surface",
        }
    }
}

/// `RenderSettings::cross_eye_reuse`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum CrossEyeReuse {
    #[default]
    Off,
    /// Always; a renderer whose eyes cannot share (a space without temporal filters, two eyes
    /// of different spaces) is refused with the reason.
    On,
    /// Where the eyes can share (see `On`), off elsewhere.
    Auto,
}

impl CrossEyeReuse {
    pub const NAMES: &'static str = "off, on, auto";

    pub fn parse(name: &str) -> Result<CrossEyeReuse> {
        match name {
            "off" => Ok(CrossEyeReuse::Off),
            "on" => Ok(CrossEyeReuse::On),
            "auto" => Ok(CrossEyeReuse::Auto),
            other => Err(Error::Invalid(format!(
                "cross-eye reuse '{other}' is not one of {}",
                Self::NAMES
            ))),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            CrossEyeReuse::Off => "off",
            CrossEyeReuse::On => "on",
            CrossEyeReuse::Auto => "auto",
        }
    }
}

/// The most views one frame renders (two eyes).
pub const MAX_VIEWS: usize = 2;

/// One view's input: its camera (pose and asymmetric FOV tangents) and gaze.
#[derive(Clone, Copy, Debug)]
pub struct ViewInput {
    pub camera: CameraPose,
    /// Gaze point in the view's screen pixels; `None` keeps the space's current gaze.
    pub gaze: Option<Vec2>,
}

/// `FrameInput::frame_seconds` by default: one refresh of a 90 Hz headset.
pub const DEFAULT_FRAME_SECONDS: f32 = 1.0 / 90.0;

/// One frame of every view (fixed capacity: building it allocates nothing).
#[derive(Clone, Copy, Debug)]
pub struct FrameInput {
    views: [ViewInput; MAX_VIEWS],
    view_count: usize,
    pub frame_index: u32,
    /// Seconds from the previous frame to this one on the display (automatic exposure adapts
    /// over it); `DEFAULT_FRAME_SECONDS` unless the caller knows better.
    pub frame_seconds: f32,
    /// Also copy the linear screen image back (EXR output).
    pub read_hdr: bool,
    /// Also tonemap the sampling-grid image and copy it back (`read_grid_ldr`; debug views).
    pub read_grid: bool,
}

impl FrameInput {
    /// A frame of one view.
    pub fn mono(camera: CameraPose, frame_index: u32, gaze: Option<Vec2>) -> FrameInput {
        FrameInput::views(&[ViewInput { camera, gaze }], frame_index).expect("one view fits")
    }

    /// A frame of `views.len()` ≤ MAX_VIEWS views, in the renderer's view order.
    pub fn views(views: &[ViewInput], frame_index: u32) -> Result<FrameInput> {
        if views.is_empty() || views.len() > MAX_VIEWS {
            return Err(Error::Invalid(format!(
                "a frame has 1 to {MAX_VIEWS} views, not {}",
                views.len()
            )));
        }
        let mut all = [views[0]; MAX_VIEWS];
        all[..views.len()].copy_from_slice(views);
        Ok(FrameInput {
            views: all,
            view_count: views.len(),
            frame_index,
            frame_seconds: DEFAULT_FRAME_SECONDS,
            read_hdr: false,
            read_grid: false,
        })
    }

    pub fn with_hdr(mut self, read_hdr: bool) -> FrameInput {
        self.read_hdr = read_hdr;
        self
    }

    pub fn with_grid(mut self, read_grid: bool) -> FrameInput {
        self.read_grid = read_grid;
        self
    }

    pub fn view_inputs(&self) -> &[ViewInput] {
        &self.views[..self.view_count]
    }
}

/// An image the engine does not own that the frame's final pass writes (a swapchain image), with
/// the semaphores the submission waits on and signals.
#[derive(Clone, Copy)]
pub struct FrameTarget<'a> {
    pub image: &'a ExternalImage,
    /// Top-left pixel of each view in the image (stereo side by side).
    pub offsets: [UVec2; MAX_VIEWS],
    pub sync: SubmitSync<'a>,
    /// Copy the finished image here before it is released (screenshots).
    pub copy_to: Option<&'a Buffer>,
}

/// Exact counts for one frame (from the GPU's own counters).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameStats {
    pub samples_traced: u64,
    pub primary_rays: u64,
    pub shadow_rays: u64,
    pub continuation_rays: u64,
    /// Traced samples whose screen position lies off the screen (Visual-Polar covers the r_max
    /// circle; always 0 for Cartesian).
    pub samples_offscreen: u64,
    /// Samples not traced because they lay far off the screen (`OffscreenSamples::Cull`).
    pub samples_culled: u64,
}

impl FrameStats {
    pub fn rays_traced(&self) -> u64 {
        self.primary_rays + self.shadow_rays + self.continuation_rays
    }
}
