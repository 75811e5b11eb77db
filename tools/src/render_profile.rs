//! Render profiles (`config/render/*.toml`): the Visual-Polar parameters, the foveated blur, each
//! registered denoiser's parameters (one section each, named as `--denoiser` names it: `[svgf]`,
//! `[asvgf]`, `[bmfr]`; the registry is `fovea_renderer::passes::denoise`) and the TAA parameters
//! (used with `--taa vp` or `--taa screen`); those sections read straight into the engine's
//! settings, every key defaulting to the engine's value.
//! Parsing is strict: unknown keys and out-of-range values are errors naming the file and key.
//! Command-line flags override single values (`RenderProfile::override_with`).
//! `eccentricity = "headset"` only names the axis: the command glues in the headset's FOV
//! (`RenderProfile::visual_polar_for`).

use anyhow::{bail, Context, Result};
use fovea_renderer::frame::{
    CrossEyeReuse, OffscreenSamples, StereoNoise, TextureLod, DEFAULT_PATH_REGULARISATION,
    DEFAULT_SURFACE_CELL, SURFACE_CELL_RANGE,
};
use fovea_renderer::passes::denoise::{DenoiserProfile, DenoiserSettings};
use fovea_renderer::passes::resampling::{ResamplingMode, ResamplingSettings};
use fovea_renderer::passes::taa::TaaSettings;
use fovea_renderer::sampling::{
    CompositeMode, CompositeParams, Eccentricity, FovTangents, InverseCdf, LogPolarExtent,
    LogPolarParams, RadialLaw, RadiusMode, VisualPolarParams, VpLayout,
};
use fovea_renderer::way_back::blur::{BlurSettings, BlurSpace};
use fovea_stage::look::{EnvironmentNames, EnvironmentOptions};
use serde::de::{self, DeserializeSeed, MapAccess, Visitor};
use serde::{Deserialize, Deserializer};
use std::path::Path;

#[derive(Clone, Debug, PartialEq)]
pub struct RenderProfile {
    pub visual_polar: VisualPolarParams,
    /// `[log_polar]`: `--method log-polar` (Meng et al. 2018; σ, α, the extent L comes from).
    pub log_polar: LogPolarParams,
    /// `--composite-mode` / `[composite] mode`: `--method composite`'s mode (Andersson & Hansson 2020).
    pub composite_mode: CompositeMode,
    /// `[composite] sigma`: the log-polar buffer's σ instead of the mode's (its budget knob: the
    /// buffer holds ≈ W·H/σ² samples), e.g. to compare at another method's sample count.
    pub composite_sigma: Option<f32>,
    /// The ρ axis (`[visual_polar] eccentricity`); `visual_polar.eccentricity` stays Normalized
    /// until `visual_polar_for` adds the headset's FOV.
    pub eccentricity: EccentricityMode,
    pub blur: BlurSettings,
    /// Every registered denoiser's parameters (`--denoiser` picks one: `denoisers.get`).
    pub denoisers: DenoiserProfile,
    pub taa: TaaSettings,
    /// `[environment]`: the default sun and sky (`fovea_stage::look`), flags applied on top.
    pub environment: EnvironmentOptions,
    /// `[textures] lod`: mip-level selection (`cones` or `off`).
    pub texture_lod: TextureLod,
    /// `[path] regularisation` (`RenderSettings::path_regularisation`); `None`: the engine's default.
    pub path_regularisation: Option<f32>,
    /// `[trace] offscreen`: samples far off the screen culled (the default) or traced.
    pub offscreen_samples: OffscreenSamples,
    /// `[resampling]` and `--resampling`: ReSTIR DI's mode and parameters (off by default).
    pub resampling: ResamplingSettings,
    /// `[trace] stereo_noise`: how the two eyes' random numbers relate (`--stereo-noise`).
    pub stereo_noise: StereoNoise,
    /// `[trace] surface_cell`: the surface noise's cell edge in sample footprints
    /// (`RenderSettings::surface_cell`); `None`: the engine's default.
    pub surface_cell: Option<f32>,
    /// `[trace] cross_eye_reuse`: with both eyes, whether each eye's samples also take the other
    /// eye's sample of the same surface before the filters (`--cross-eye-reuse`); `auto` by
    /// default (docs/quality.md#cross-eye-reuse).
    pub cross_eye_reuse: CrossEyeReuse,
    /// `--latency-ms`, `--tracker-hz`, `--gaze-predict` (flags only): which gaze each frame sees.
    pub gaze_timing: fovea_stage::gaze::GazeTiming,
}

/// The Visual-Polar layout of the product's default profile: the paper's grid with each column's
/// rows on its on-screen arcs, so the sample budget does not fall when the eye looks toward a
/// corner (the paper layout loses up to 54 % there), at the paper layout's perceived quality
/// (docs/perceptual.md). The renderer's own default stays the paper's.
pub const DEFAULT_VP_LAYOUT: VpLayout = VpLayout::ScreenClipped;

/// The foveated blur's σ at 30° in the product's default profile: off. Koskela et al.'s 6.8 px
/// (the renderer's own default) lowered the perceived quality of every foveated method in every
/// run scored (FovVideoVDP at the FOVE 0's resolution, still camera: 0.7–1.0 JOD; moving camera:
/// 0.7 JOD), and the blurred periphery flickered more, not less, under a moving camera
/// (docs/perceptual.md). `--blur-sigma` / `[blur] sigma_at_30` turn it on.
pub const DEFAULT_BLUR_SIGMA_AT_30: f32 = 0.0;

impl Default for RenderProfile {
    fn default() -> Self {
        RenderProfile {
            visual_polar: VisualPolarParams {
                layout: DEFAULT_VP_LAYOUT,
                ..VisualPolarParams::default()
            },
            log_polar: Default::default(),
            composite_mode: Default::default(),
            composite_sigma: None,
            eccentricity: Default::default(),
            blur: BlurSettings {
                sigma_at_30: DEFAULT_BLUR_SIGMA_AT_30,
                ..Default::default()
            },
            denoisers: Default::default(),
            taa: Default::default(),
            environment: Default::default(),
            texture_lod: Default::default(),
            path_regularisation: None,
            offscreen_samples: Default::default(),
            resampling: Default::default(),
            stereo_noise: Default::default(),
            surface_cell: None,
            cross_eye_reuse: CrossEyeReuse::Auto,
            gaze_timing: Default::default(),
        }
    }
}

/// A render profile as written: the fixed sections, and the registered denoisers' sections
/// (`DenoiserSettings::deserialize_section`), each read onto its defaults.
#[derive(Default)]
struct ProfileFile {
    visual_polar: Option<VpSection>,
    log_polar: Option<LogPolarSection>,
    composite: Option<CompositeSection>,
    blur: Option<BlurSection>,
    taa: Option<TaaSettings>,
    environment: Option<EnvironmentSection>,
    textures: Option<TexturesSection>,
    path: Option<PathSection>,
    trace: Option<TraceSection>,
    resampling: Option<ResamplingSettings>,
    /// The denoiser sections present.
    denoisers: Vec<DenoiserSettings>,
}

/// The sections besides the denoisers'.
const FIXED_SECTIONS: &[&str] = &[
    "visual_polar",
    "log_polar",
    "composite",
    "blur",
    "taa",
    "environment",
    "textures",
    "path",
    "trace",
    "resampling",
];

impl<'de> Deserialize<'de> for ProfileFile {
    fn deserialize<D: Deserializer<'de>>(de: D) -> std::result::Result<Self, D::Error> {
        de.deserialize_map(ProfileVisitor)
    }
}

struct ProfileVisitor;

impl<'de> Visitor<'de> for ProfileVisitor {
    type Value = ProfileFile;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("render profile sections")
    }

    fn visit_map<A: MapAccess<'de>>(
        self,
        mut map: A,
    ) -> std::result::Result<ProfileFile, A::Error> {
        let mut file = ProfileFile::default();
        while let Some(key) = map.next_key::<String>()? {
            match key.as_str() {
                "visual_polar" => file.visual_polar = Some(map.next_value()?),
                "log_polar" => file.log_polar = Some(map.next_value()?),
                "composite" => file.composite = Some(map.next_value()?),
                "blur" => file.blur = Some(map.next_value()?),
                "taa" => file.taa = Some(map.next_value()?),
                "environment" => file.environment = Some(map.next_value()?),
                "textures" => file.textures = Some(map.next_value()?),
                "path" => file.path = Some(map.next_value()?),
                "trace" => file.trace = Some(map.next_value()?),
                "resampling" => file.resampling = Some(map.next_value()?),
                section if DenoiserSettings::NAMES[1..].contains(&section) => {
                    if let Some(d) = map.next_value_seed(DenoiserSection(section))? {
                        file.denoisers.push(d);
                    }
                }
                other => {
                    let expected: Vec<&str> = FIXED_SECTIONS
                        .iter()
                        .chain(&DenoiserSettings::NAMES[1..])
                        .copied()
                        .collect();
                    return Err(de::Error::custom(format!(
                        "unknown section `{other}`, expected one of {}",
                        expected.join(", ")
                    )));
                }
            }
        }
        Ok(file)
    }
}

/// A registered denoiser's section, read into its parameters.
struct DenoiserSection<'a>(&'a str);

impl<'de> DeserializeSeed<'de> for DenoiserSection<'_> {
    type Value = Option<DenoiserSettings>;

    fn deserialize<D: Deserializer<'de>>(
        self,
        de: D,
    ) -> std::result::Result<Self::Value, D::Error> {
        DenoiserSettings::deserialize_section(self.0, de)
    }
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct TraceSection {
    offscreen: Option<String>,
    stereo_noise: Option<String>,
    surface_cell: Option<f32>,
    cross_eye_reuse: Option<String>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct PathSection {
    regularisation: Option<f32>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct TexturesSection {
    lod: Option<String>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct EnvironmentSection {
    /// [azimuth, elevation] in degrees.
    sun: Option<[f32; 2]>,
    sun_intensity: Option<f32>,
    sky_intensity: Option<f32>,
    /// An HDR environment map, relative to the profile's folder.
    env: Option<std::path::PathBuf>,
    env_rotation: Option<f32>,
    env_intensity: Option<f32>,
    /// "gradient" or "preetham".
    sky: Option<String>,
    /// "auto", "on" or "off" (`--default-light`).
    default_light: Option<String>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct VpSection {
    axis_scale: Option<f32>,
    clip_fraction: Option<f32>,
    fovea_deg: Option<f32>,
    density_exponent: Option<f32>,
    inverse_cdf: Option<String>,
    radius: Option<toml::Value>,
    layout: Option<String>,
    eccentricity: Option<String>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct LogPolarSection {
    sigma: Option<f32>,
    alpha: Option<f32>,
    extent: Option<String>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct CompositeSection {
    mode: Option<String>,
    sigma: Option<f32>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct BlurSection {
    sigma_at_30: Option<f32>,
    space: Option<String>,
}

/// Optional single-value overrides (the `fovea render` flags).
#[derive(Clone, Debug, Default)]
pub struct ProfileOverrides {
    pub axis_scale: Option<f32>,
    pub clip_fraction: Option<f32>,
    pub fovea_deg: Option<f32>,
    pub density_exponent: Option<f32>,
    pub inverse_cdf: Option<String>,
    pub radius: Option<String>,
    pub layout: Option<String>,
    pub eccentricity: Option<String>,
    /// `--log-polar-extent`.
    pub log_polar_extent: Option<String>,
    /// `--composite-mode`.
    pub composite_mode: Option<String>,
    pub blur_sigma: Option<f32>,
    pub blur_space: Option<String>,
    /// `--sun`, `--sun-intensity`, `--sky-intensity`.
    pub environment: EnvironmentOptions,
    /// `--texture-lod`.
    pub texture_lod: Option<String>,
    /// `--path-regularisation`.
    pub path_regularisation: Option<f32>,
    /// `--offscreen-samples`.
    pub offscreen_samples: Option<String>,
    /// `--resampling`.
    pub resampling: Option<String>,
    /// `--stereo-noise`.
    pub stereo_noise: Option<String>,
    /// `--cross-eye-reuse`.
    pub cross_eye_reuse: Option<String>,
    /// `--latency-ms`, `--tracker-hz`, `--gaze-predict` (all absent: no latency model).
    pub gaze_timing: fovea_stage::gaze::GazeTiming,
}

/// What the Visual-Polar ρ axis measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum EccentricityMode {
    /// The paper's normalised screen distance (80 ↦ the farthest corner).
    #[default]
    Normalized,
    /// True degrees from the gaze direction through the headset eye's FOV.
    Headset,
}

pub fn parse_eccentricity(s: &str) -> Result<EccentricityMode> {
    match s {
        "normalized" => Ok(EccentricityMode::Normalized),
        "headset" => Ok(EccentricityMode::Headset),
        other => bail!("'{other}' is not an eccentricity axis (normalized | headset)"),
    }
}

/// The name `parse_eccentricity` reads (report.json, messages).
pub fn eccentricity_name(mode: EccentricityMode) -> &'static str {
    match mode {
        EccentricityMode::Normalized => "normalized",
        EccentricityMode::Headset => "headset",
    }
}

/// `--log-polar-extent` / `[log_polar] extent`: where L comes from.
pub fn parse_log_polar_extent(s: &str) -> Result<LogPolarExtent> {
    match s {
        "corner" => Ok(LogPolarExtent::FarthestCorner),
        "diagonal" => Ok(LogPolarExtent::Diagonal),
        other => bail!("'{other}' is not a log-polar extent (corner: Meng's farthest corner | diagonal: Andersson & Hansson's screen diagonal)"),
    }
}

/// The name `parse_log_polar_extent` reads.
pub fn log_polar_extent_name(e: LogPolarExtent) -> &'static str {
    match e {
        LogPolarExtent::FarthestCorner => "corner",
        LogPolarExtent::Diagonal => "diagonal",
    }
}

pub fn parse_inverse_cdf(s: &str) -> Result<InverseCdf> {
    match s {
        "polynomial" | "poly" => Ok(InverseCdf::Polynomial),
        "exact" => Ok(InverseCdf::Exact),
        other => bail!("'{other}' is not an inverse-CDF mode (polynomial | exact)"),
    }
}

pub fn parse_layout(s: &str) -> Result<VpLayout> {
    match s {
        "paper" => Ok(VpLayout::Paper),
        "screen-clipped" => Ok(VpLayout::ScreenClipped),
        "screen-aware" => Ok(VpLayout::ScreenAware),
        other => {
            bail!("'{other}' is not a Visual-Polar layout (paper | screen-clipped | screen-aware)")
        }
    }
}

/// The name `parse_layout` reads (report.json, messages).
pub fn layout_name(layout: VpLayout) -> &'static str {
    match layout {
        VpLayout::Paper => "paper",
        VpLayout::ScreenClipped => "screen-clipped",
        VpLayout::ScreenAware => "screen-aware",
    }
}

/// The range of a fixed Visual-Polar radius in pixels. Below one pixel every screen pixel but the
/// gaze's own lies beyond r_max (the outermost column, clamped); above 10⁶ no screen fovea renders
/// has a use for it. The command also bounds it by the screen it renders
/// (`commands::setup::check_space`: at most 10 diagonals).
pub const VP_RADIUS_RANGE: (f32, f32) = (1.0, 1e6);

pub fn parse_radius(s: &str) -> Result<RadiusMode> {
    if s == "corner" {
        return Ok(RadiusMode::FarthestCorner);
    }
    let (lo, hi) = VP_RADIUS_RANGE;
    match s.parse::<f32>() {
        Ok(r) if r.is_finite() && (lo..=hi).contains(&r) => Ok(RadiusMode::Fixed(r)),
        Ok(r) if r.is_finite() && r > 0.0 => bail!("radius {s} px: must be corner or in [{lo}, {hi:e}] pixels (below one pixel the whole screen lies beyond it)"),
        _ => bail!("'{s}' is not a radius mode (corner | a radius in pixels in [{lo}, {hi:e}])"),
    }
}

impl RenderProfile {
    pub fn load(path: &Path) -> Result<RenderProfile> {
        let text = fovea_hal::file::read_text(
            path,
            fovea_hal::file::MAX_PROFILE_BYTES,
            "a render profile",
        )
        .with_context(|| format!("reading render profile {}", path.display()))?;
        let file: ProfileFile = toml::from_str(&text)
            .with_context(|| format!("{}: invalid render profile", path.display()))?;
        let mut profile = RenderProfile::default();
        let at = |key: &str| format!("{}: [{}]", path.display(), key);
        if let Some(vp) = file.visual_polar {
            let p = &mut profile.visual_polar;
            p.axis_scale = vp.axis_scale.unwrap_or(p.axis_scale);
            p.clip_fraction = vp.clip_fraction.unwrap_or(p.clip_fraction);
            p.fovea_deg = vp.fovea_deg.unwrap_or(p.fovea_deg);
            p.density_exponent = vp.density_exponent.unwrap_or(p.density_exponent);
            if let Some(mode) = vp.inverse_cdf {
                p.inverse_cdf = parse_inverse_cdf(&mode)
                    .with_context(|| format!("{}.inverse_cdf", at("visual_polar")))?;
            }
            if let Some(radius) = vp.radius {
                let text = match radius {
                    toml::Value::String(s) => s,
                    toml::Value::Integer(i) => i.to_string(),
                    // Debug keeps 1e30 short in the message (Display writes every digit).
                    toml::Value::Float(f) => format!("{f:?}"),
                    other => bail!(
                        "{}.radius: expected \"corner\" or pixels, got {other}",
                        at("visual_polar")
                    ),
                };
                p.radius_mode = parse_radius(&text)
                    .with_context(|| format!("{}.radius", at("visual_polar")))?;
            }
            if let Some(layout) = &vp.layout {
                p.layout = parse_layout(layout)
                    .with_context(|| format!("{}.layout", at("visual_polar")))?;
            }
            if let Some(mode) = vp.eccentricity {
                profile.eccentricity = parse_eccentricity(&mode)
                    .with_context(|| format!("{}.eccentricity", at("visual_polar")))?;
                // The headset axis exists for the paper layout only: asking for it without a
                // layout asks for that one.
                if profile.eccentricity == EccentricityMode::Headset && vp.layout.is_none() {
                    p.layout = VpLayout::Paper;
                }
            }
            p.validate().with_context(|| at("visual_polar"))?;
            profile
                .check_eccentricity()
                .with_context(|| format!("{}.eccentricity", at("visual_polar")))?;
        }
        if let Some(lp) = file.log_polar {
            let p = &mut profile.log_polar;
            p.sigma = lp.sigma.unwrap_or(p.sigma);
            p.alpha = lp.alpha.unwrap_or(p.alpha);
            if let Some(extent) = lp.extent {
                p.extent = parse_log_polar_extent(&extent)
                    .with_context(|| format!("{}.extent", at("log_polar")))?;
            }
            p.validate().with_context(|| at("log_polar"))?;
        }
        if let Some(c) = file.composite {
            if let Some(mode) = c.mode {
                profile.composite_mode = CompositeMode::parse(&mode).with_context(|| {
                    format!(
                        "{}.mode: '{mode}', expected one of {}",
                        at("composite"),
                        CompositeMode::NAMES.join(", ")
                    )
                })?;
            }
            profile.composite_sigma = c.sigma;
            // A stand-in viewing distance: σ's range does not depend on it.
            profile
                .composite_params(1000.0)
                .validate()
                .with_context(|| format!("{}.sigma", at("composite")))?;
        }
        if let Some(blur) = file.blur {
            profile.blur.sigma_at_30 = blur.sigma_at_30.unwrap_or(profile.blur.sigma_at_30);
            if let Some(space) = &blur.space {
                profile.blur.space =
                    parse_blur_space(space).with_context(|| format!("{}.space", at("blur")))?;
            }
        }
        check_blur(&profile.blur).with_context(|| format!("{}.sigma_at_30", at("blur")))?;
        for denoiser in file.denoisers {
            profile.denoisers.set(denoiser);
        }
        profile.denoisers.complete();
        for denoiser in profile.denoisers.iter() {
            denoiser.validate().with_context(|| at(denoiser.name()))?;
        }
        if let Some(taa) = file.taa {
            taa.validate().with_context(|| at("taa"))?;
            profile.taa = taa;
        }
        if let Some(f) = file.environment {
            let env = f.env.map(|e| confined_env_path(path, &e)).transpose()?;
            profile.environment = EnvironmentOptions {
                sun: f.sun,
                sun_intensity: f.sun_intensity,
                sky_intensity: f.sky_intensity,
                env,
                env_rotation: f.env_rotation,
                env_intensity: f.env_intensity,
                sky: f
                    .sky
                    .as_deref()
                    .map(fovea_stage::sky_model::SkyModel::parse)
                    .transpose()
                    .with_context(|| format!("{}.sky", at("environment")))?,
                default_light: f
                    .default_light
                    .as_deref()
                    .map(fovea_stage::look::DefaultLight::parse)
                    .transpose()
                    .with_context(|| format!("{}.default_light", at("environment")))?,
            };
            profile
                .environment
                .validate(&EnvironmentNames::profile(&path.display().to_string()))?;
            if let Some(env) = &profile.environment.env {
                fovea_stage::env_map::check_path(env)
                    .with_context(|| format!("{}: [environment].env", path.display()))?;
            }
        }
        if let Some(lod) = file.textures.and_then(|t| t.lod) {
            profile.texture_lod =
                TextureLod::parse(&lod).with_context(|| format!("{}.lod", at("textures")))?;
        }
        let trace = file.trace.unwrap_or_default();
        if let Some(mode) = trace.offscreen {
            profile.offscreen_samples = OffscreenSamples::parse(&mode)
                .with_context(|| format!("{}.offscreen", at("trace")))?;
        }
        if let Some(mode) = trace.stereo_noise {
            profile.stereo_noise = StereoNoise::parse(&mode)
                .with_context(|| format!("{}.stereo_noise", at("trace")))?;
        }
        if let Some(cell) = trace.surface_cell {
            let (lo, hi) = SURFACE_CELL_RANGE;
            if !(lo..=hi).contains(&cell) {
                bail!(
                    "{}.surface_cell = {cell}: must be in [{lo}, {hi}] sample footprints",
                    at("trace")
                );
            }
            profile.surface_cell = Some(cell);
        }
        if let Some(reuse) = trace.cross_eye_reuse {
            profile.cross_eye_reuse = CrossEyeReuse::parse(&reuse)
                .with_context(|| format!("{}.cross_eye_reuse", at("trace")))?;
        }
        if let Some(resampling) = file.resampling {
            resampling.validate().with_context(|| at("resampling"))?;
            profile.resampling = resampling;
        }
        if let Some(strength) = file.path.and_then(|p| p.regularisation) {
            profile.path_regularisation = Some(check_path_regularisation(
                Some(strength),
                &format!("{}.regularisation", at("path")),
            )?);
        }
        Ok(profile)
    }

    /// Applies command-line values on top of the profile and re-checks the result.
    pub fn override_with(mut self, o: &ProfileOverrides) -> Result<RenderProfile> {
        let p = &mut self.visual_polar;
        p.axis_scale = o.axis_scale.unwrap_or(p.axis_scale);
        p.clip_fraction = o.clip_fraction.unwrap_or(p.clip_fraction);
        p.fovea_deg = o.fovea_deg.unwrap_or(p.fovea_deg);
        p.density_exponent = o.density_exponent.unwrap_or(p.density_exponent);
        if let Some(mode) = &o.inverse_cdf {
            p.inverse_cdf = parse_inverse_cdf(mode).context("--vp-inverse-cdf")?;
        }
        if let Some(radius) = &o.radius {
            p.radius_mode = parse_radius(radius).context("--vp-radius")?;
        }
        if let Some(layout) = &o.layout {
            p.layout = parse_layout(layout).context("--vp-layout")?;
        }
        if let Some(mode) = &o.eccentricity {
            self.eccentricity = parse_eccentricity(mode).context("--vp-eccentricity")?;
            // As in a profile: the headset axis without a layout takes the paper's, its only one.
            if self.eccentricity == EccentricityMode::Headset && o.layout.is_none() {
                self.visual_polar.layout = VpLayout::Paper;
            }
        }
        self.visual_polar.validate().context("Visual-Polar flags")?;
        self.check_eccentricity().context("--vp-eccentricity")?;
        if let Some(extent) = &o.log_polar_extent {
            self.log_polar.extent = parse_log_polar_extent(extent).context("--log-polar-extent")?;
        }
        if let Some(mode) = &o.composite_mode {
            self.composite_mode = CompositeMode::parse(mode).with_context(|| {
                format!(
                    "--composite-mode {mode}: expected one of {}",
                    CompositeMode::NAMES.join(", ")
                )
            })?;
        }
        self.blur.sigma_at_30 = o.blur_sigma.unwrap_or(self.blur.sigma_at_30);
        if let Some(space) = &o.blur_space {
            self.blur.space = parse_blur_space(space).context("--blur-space")?;
        }
        check_blur(&self.blur).context("--blur-sigma")?;
        o.environment.validate(&EnvironmentNames::flags())?;
        self.environment = self.environment.overridden(&o.environment);
        if let Some(lod) = &o.texture_lod {
            self.texture_lod = TextureLod::parse(lod).context("--texture-lod")?;
        }
        if let Some(strength) = o.path_regularisation {
            self.path_regularisation = Some(check_path_regularisation(
                Some(strength),
                "--path-regularisation",
            )?);
        }
        if let Some(mode) = &o.offscreen_samples {
            self.offscreen_samples =
                OffscreenSamples::parse(mode).context("--offscreen-samples")?;
        }
        if let Some(mode) = &o.stereo_noise {
            self.stereo_noise = StereoNoise::parse(mode).context("--stereo-noise")?;
        }
        if let Some(reuse) = &o.cross_eye_reuse {
            self.cross_eye_reuse = CrossEyeReuse::parse(reuse).context("--cross-eye-reuse")?;
        }
        if let Some(mode) = &o.resampling {
            let mode = ResamplingMode::parse(mode).context("--resampling")?;
            self.resampling = self.resampling.with_mode(mode);
        }
        if o.gaze_timing.enabled() {
            self.gaze_timing = o.gaze_timing;
        }
        Ok(self)
    }

    /// The surface noise's cell the engine runs with (footprints).
    pub fn surface_cell(&self) -> f32 {
        self.surface_cell.unwrap_or(DEFAULT_SURFACE_CELL)
    }

    /// The strength the engine runs with.
    pub fn path_regularisation(&self) -> f32 {
        self.path_regularisation
            .unwrap_or(DEFAULT_PATH_REGULARISATION)
    }
}

/// The largest path regularisation strength: k·pdf ≥ 1 switches it off for a bounce, so beyond
/// this only bounces of density below 0.01 are still roughened (nothing meaningful changes).
pub const MAX_PATH_REGULARISATION: f32 = 100.0;

/// `value` (or the default when `None`) when it is a meaningful strength; `name` is the flag or key.
pub fn check_path_regularisation(value: Option<f32>, name: &str) -> Result<f32> {
    let v = value.unwrap_or(DEFAULT_PATH_REGULARISATION);
    if !(0.0..=MAX_PATH_REGULARISATION).contains(&v) {
        bail!("{name} {v} must be in [0, {MAX_PATH_REGULARISATION}] (0 = off, 1 = the default)");
    }
    Ok(v)
}

/// An HMD eye's FOV as the plain tangents the renderer takes.
pub fn fov_tangents(fov: &fovea_hal::Fov) -> FovTangents {
    FovTangents {
        left: -fov.angle_left.tan(),
        right: fov.angle_right.tan(),
        up: fov.angle_up.tan(),
        down: -fov.angle_down.tan(),
    }
}

impl RenderProfile {
    /// The Visual-Polar parameters for an eye with this FOV (the headset axis needs it).
    pub fn visual_polar_for(&self, fov: FovTangents) -> Result<VisualPolarParams> {
        let mut p = self.visual_polar;
        if self.eccentricity == EccentricityMode::Headset {
            p.eccentricity = Eccentricity::Headset(fov);
        }
        p.validate().context("Visual-Polar parameters")?;
        Ok(p)
    }

    /// The polar-space parameters of `--method log-polar`: Visual-Polar's defaults (fovea° for the
    /// blur's slope) with the profile's log-polar law.
    pub fn log_polar_space(&self) -> VisualPolarParams {
        VisualPolarParams {
            radial: RadialLaw::LogPolar(self.log_polar),
            ..Default::default()
        }
    }

    /// The polar-space parameters of `--method composite` for an eye `viewing_distance_px` from
    /// the image (its gaze disc is d · tan a_G).
    pub fn composite_space(&self, viewing_distance_px: f32) -> VisualPolarParams {
        VisualPolarParams {
            radial: RadialLaw::Composite(self.composite_params(viewing_distance_px)),
            ..Default::default()
        }
    }

    /// The mode's parameters with the profile's σ, if it sets one.
    fn composite_params(&self, viewing_distance_px: f32) -> CompositeParams {
        let mode = self.composite_mode.params(viewing_distance_px);
        CompositeParams {
            sigma: self.composite_sigma.unwrap_or(mode.sigma),
            ..mode
        }
    }

    /// The combinations the headset axis refuses, checked with a stand-in FOV (the real one is
    /// only known to the command).
    fn check_eccentricity(&self) -> Result<()> {
        self.visual_polar_for(FovTangents {
            left: 1.0,
            right: 1.0,
            up: 1.0,
            down: 1.0,
        })
        .map(|_| ())
    }
}

fn parse_blur_space(name: &str) -> Result<BlurSpace> {
    match name {
        "screen" => Ok(BlurSpace::Screen),
        "grid" => Ok(BlurSpace::Grid),
        _ => bail!("'{name}', expected screen or grid"),
    }
}

fn check_blur(b: &BlurSettings) -> Result<()> {
    if !(b.sigma_at_30.is_finite() && (0.0..=64.0).contains(&b.sigma_at_30)) {
        bail!("σ at 30° must be in [0, 64] pixels, got {}", b.sigma_at_30);
    }
    Ok(())
}

/// A profile's `[environment].env`: a relative path inside the profile's folder (no `..`, not
/// absolute, no symbolic link leading out), so a profile from elsewhere cannot make fovea read
/// (and show) a file outside its folder. A map anywhere else is given with `--env FILE`.
fn confined_env_path(profile: &Path, env: &Path) -> Result<std::path::PathBuf> {
    use std::path::Component;
    let key = || {
        format!(
            "{}: [environment].env = {:?}",
            profile.display(),
            env.display().to_string()
        )
    };
    if env.as_os_str().is_empty()
        || env
            .components()
            .any(|c| !matches!(c, Component::Normal(_) | Component::CurDir))
    {
        bail!(
            "{}: a profile names an environment map inside its own folder (a relative path without `..`); give a map elsewhere on the command line with --env FILE",
            key()
        );
    }
    let dir = profile.parent().unwrap_or(Path::new("."));
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let joined = dir.join(env);
    fovea_stage::env_map::check_path(&joined).with_context(key)?;
    let (inside, folder) = (
        joined.canonicalize().with_context(key)?,
        dir.canonicalize().with_context(key)?,
    );
    if !inside.starts_with(&folder) {
        bail!(
            "{}: it leads out of the profile's folder through a symbolic link (to {}); give a map elsewhere with --env FILE",
            key(),
            inside.display()
        );
    }
    Ok(joined)
}

#[cfg(test)]
mod tests {
    use super::*;
    use fovea_renderer::passes::denoise::bmfr::BmfrSettings;

    fn load_str(name: &str, text: &str) -> Result<RenderProfile> {
        let dir = std::env::temp_dir().join(format!("fovea-profile-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        RenderProfile::load(&path)
    }

    /// `[composite]`: the mode and σ (the buffer's budget knob) reach `--method composite`'s space.
    #[test]
    fn composite_section_sets_mode_and_sigma() {
        let p = load_str(
            "composite.toml",
            "[composite]\nmode = \"kernel\"\nsigma = 1.66\n",
        )
        .unwrap();
        assert_eq!(p.composite_mode, CompositeMode::Kernel);
        let RadialLaw::Composite(c) = p.composite_space(160.0).radial else {
            panic!("not composite")
        };
        assert_eq!(
            (c.mode, c.sigma, c.alpha),
            (
                CompositeMode::Kernel,
                1.66,
                CompositeMode::Kernel.params(160.0).alpha
            )
        );
        let RadialLaw::Composite(c) = RenderProfile::default().composite_space(160.0).radial else {
            panic!("not composite")
        };
        assert_eq!(
            c,
            CompositeMode::Composite.params(160.0),
            "without the section: the mode's own σ"
        );
    }

    #[test]
    fn shipped_default_profile_is_the_built_in_default() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/render/default.toml");
        let p = RenderProfile::load(&path).unwrap();
        let d = VisualPolarParams::default();
        assert!((p.visual_polar.axis_scale - d.axis_scale).abs() < 1e-3);
        assert_eq!(p.visual_polar.clip_fraction, d.clip_fraction);
        assert_eq!(p.visual_polar.inverse_cdf, InverseCdf::Polynomial);
        assert_eq!(p.visual_polar.radius_mode, RadiusMode::FarthestCorner);
        assert_eq!(p.visual_polar.layout, DEFAULT_VP_LAYOUT);
        assert_eq!(p.eccentricity, EccentricityMode::Normalized);
        assert_eq!(p.blur.sigma_at_30, DEFAULT_BLUR_SIGMA_AT_30);
        assert_eq!(p.denoisers, DenoiserProfile::default());
        assert_eq!(p.taa, TaaSettings::default());
        assert_eq!(p.texture_lod, TextureLod::RayCones);
        assert_eq!(p.path_regularisation(), DEFAULT_PATH_REGULARISATION);
        assert_eq!(p.stereo_noise, StereoNoise::default());
        assert_eq!(p.surface_cell(), DEFAULT_SURFACE_CELL);
        assert_eq!(p.offscreen_samples, OffscreenSamples::Cull);
        // The shipped values are the built-in defaults of the sun (no sky key: see the file).
        let sun = Some(fovea_stage::look::DEFAULT_SUN);
        assert_eq!(
            p.environment,
            EnvironmentOptions {
                sun,
                sun_intensity: Some(fovea_stage::look::DEFAULT_SUN_INTENSITY),
                sky_intensity: None,
                ..Default::default()
            }
        );
    }

    #[test]
    fn values_are_read() {
        let p = load_str(
            "a.toml",
            "[visual_polar]\nclip_fraction = 0.088\ninverse_cdf = \"exact\"\nradius = 900\nlayout = \"screen-clipped\"\n[blur]\nsigma_at_30 = 0\n",
        )
        .unwrap();
        assert_eq!(p.visual_polar.layout, VpLayout::ScreenClipped);
        assert_eq!(p.visual_polar.clip_fraction, 0.088);
        assert_eq!(p.visual_polar.inverse_cdf, InverseCdf::Exact);
        assert_eq!(p.visual_polar.radius_mode, RadiusMode::Fixed(900.0));
        assert_eq!(p.blur.sigma_at_30, 0.0);
        let p = load_str(
            "taa_ok.toml",
            "[taa]\ncurrent_weight = 0.05\njitter_points = 8\n",
        )
        .unwrap();
        assert_eq!(
            p.taa,
            TaaSettings {
                current_weight: 0.05,
                jitter_points: 8
            }
        );
        let p = load_str(
            "ecc_ok.toml",
            "[visual_polar]\neccentricity = \"headset\"\n",
        )
        .unwrap();
        assert_eq!(p.eccentricity, EccentricityMode::Headset);
        let fov = FovTangents::from_angles_deg(-45.0, 45.0, -48.4, 48.4);
        assert_eq!(
            p.visual_polar_for(fov).unwrap().eccentricity,
            Eccentricity::Headset(fov)
        );
        assert_eq!(
            RenderProfile::default()
                .visual_polar_for(fov)
                .unwrap()
                .eccentricity,
            Eccentricity::Normalized
        );
        let p = load_str("bmfr_ok.toml", "[bmfr]\nalpha_noisy = 0.25\nnoise = 0\n").unwrap();
        assert_eq!(
            p.denoisers.get("bmfr").unwrap(),
            DenoiserSettings::Bmfr(BmfrSettings {
                alpha_noisy: 0.25,
                noise: 0.0,
                ..Default::default()
            })
        );
        let p = load_str(
            "asvgf_ok.toml",
            "[svgf]
alpha_color = 0.1
[asvgf]
gradient_iterations = 2
gradient_sigma_normal = 64
",
        )
        .unwrap();
        let DenoiserSettings::Asvgf(asvgf) = p.denoisers.get("asvgf").unwrap() else {
            panic!("asvgf is registered");
        };
        assert_eq!(asvgf.gradient_iterations, 2);
        assert_eq!(asvgf.gradient_sigma_normal, 64.0);
        assert_eq!(
            asvgf.svgf.alpha_color, 0.1,
            "A-SVGF's SVGF stages take the [svgf] section"
        );
    }

    #[test]
    fn bad_profiles_name_file_and_key() {
        let cases = [
            ("unknown.toml", "[visual_polar]\nclip = 0.1\n", "clip"),
            ("section.toml", "[vp]\n", "vp"),
            (
                "range.toml",
                "[visual_polar]\nclip_fraction = 0.7\n",
                "clip_fraction",
            ),
            (
                "mode.toml",
                "[visual_polar]\ninverse_cdf = \"cubic\"\n",
                "inverse_cdf",
            ),
            ("radius.toml", "[visual_polar]\nradius = -3\n", "radius"),
            (
                "radius_huge.toml",
                "[visual_polar]\nradius = 1e30\n",
                "radius",
            ),
            (
                "radius_tiny.toml",
                "[visual_polar]\nradius = 1e-30\n",
                "radius",
            ),
            (
                "radius_text.toml",
                "[visual_polar]\nradius = \"inf\"\n",
                "radius",
            ),
            (
                "layout.toml",
                "[visual_polar]\nlayout = \"clipped\"\n",
                "layout",
            ),
            ("layout_type.toml", "[visual_polar]\nlayout = 1\n", "layout"),
            (
                "ecc.toml",
                "[visual_polar]\neccentricity = \"true\"\n",
                "eccentricity",
            ),
            (
                "ecc_type.toml",
                "[visual_polar]\neccentricity = 2\n",
                "eccentricity",
            ),
            (
                "ecc_clip.toml",
                "[visual_polar]\neccentricity = \"headset\"\nlayout = \"screen-clipped\"\n",
                "eccentricity",
            ),
            ("blur.toml", "[blur]\nsigma_at_30 = -1\n", "sigma_at_30"),
            (
                "blur_space.toml",
                "[blur]\nspace = \"pyramid\"\n",
                "[blur].space",
            ),
            (
                "composite_sigma.toml",
                "[composite]\nsigma = 0\n",
                "[composite].sigma",
            ),
            (
                "composite_mode.toml",
                "[composite]\nmode = \"fovea\"\n",
                "[composite].mode",
            ),
            ("composite_key.toml", "[composite]\nalpha = 2\n", "alpha"),
            (
                "type.toml",
                "[visual_polar]\naxis_scale = \"big\"\n",
                "axis_scale",
            ),
            ("svgf.toml", "[svgf]\natrous_iterations = 0\n", "svgf"),
            ("svgf_key.toml", "[svgf]\nsigma = 1\n", "sigma"),
            ("bmfr.toml", "[bmfr]\nalpha_filtered = 1.0\n", "bmfr"),
            ("bmfr_noise.toml", "[bmfr]\nnoise = -0.01\n", "bmfr"),
            ("bmfr_key.toml", "[bmfr]\nblock_size = 16\n", "block_size"),
            ("asvgf.toml", "[asvgf]\ngradient_iterations = 0\n", "asvgf"),
            (
                "asvgf_sigma.toml",
                "[asvgf]\ngradient_sigma_depth = -1\n",
                "asvgf",
            ),
            ("asvgf_key.toml", "[asvgf]\nalpha = 0.5\n", "alpha"),
            (
                "asvgf_svgf.toml",
                "[svgf]\nalpha_color = 0\n[asvgf]\n",
                "svgf",
            ),
            ("taa.toml", "[taa]\njitter_points = 64\n", "taa"),
            ("taa_weight.toml", "[taa]\ncurrent_weight = 1.5\n", "taa"),
            ("taa_key.toml", "[taa]\nfeedback = 0.9\n", "feedback"),
            (
                "lod.toml",
                "[textures]\nlod = \"trilinear\"\n",
                "[textures].lod",
            ),
            ("lod_key.toml", "[textures]\nbias = 1\n", "bias"),
            (
                "reg.toml",
                "[path]\nregularisation = -1\n",
                "[path].regularisation",
            ),
            (
                "reg_nan.toml",
                "[path]\nregularisation = nan\n",
                "[path].regularisation",
            ),
            (
                "reg_big.toml",
                "[path]\nregularisation = 101\n",
                "[path].regularisation",
            ),
            ("reg_key.toml", "[path]\nfilter = 1\n", "filter"),
            (
                "offscreen.toml",
                "[trace]\noffscreen = \"skip\"\n",
                "[trace].offscreen",
            ),
            ("offscreen_key.toml", "[trace]\ndepth = 1\n", "depth"),
        ];
        for (name, text, key) in cases {
            let err = format!("{:#}", load_str(name, text).unwrap_err());
            assert!(err.contains(name) && err.contains(key), "{name}: {err}");
        }
    }

    #[test]
    fn flags_override_and_are_checked() {
        let o = ProfileOverrides {
            clip_fraction: Some(0.2),
            radius: Some("500".into()),
            layout: Some("screen-clipped".into()),
            ..Default::default()
        };
        let p = RenderProfile::default().override_with(&o).unwrap();
        assert_eq!(p.visual_polar.clip_fraction, 0.2);
        assert_eq!(p.visual_polar.layout, VpLayout::ScreenClipped);
        let bad = ProfileOverrides {
            layout: Some("full".into()),
            ..Default::default()
        };
        assert!(format!(
            "{:#}",
            RenderProfile::default().override_with(&bad).unwrap_err()
        )
        .contains("--vp-layout"));
        assert_eq!(p.visual_polar.radius_mode, RadiusMode::Fixed(500.0));
        let p = load_str("lod_off.toml", "[textures]\nlod = \"off\"\n").unwrap();
        assert_eq!(p.texture_lod, TextureLod::Off);
        let o = ProfileOverrides {
            texture_lod: Some("cones".into()),
            ..Default::default()
        };
        assert_eq!(
            p.override_with(&o).unwrap().texture_lod,
            TextureLod::RayCones
        );
        let bad = ProfileOverrides {
            texture_lod: Some("on".into()),
            ..Default::default()
        };
        let err = format!(
            "{:#}",
            RenderProfile::default().override_with(&bad).unwrap_err()
        );
        assert!(
            err.contains("--texture-lod") && err.contains("cones, off"),
            "{err}"
        );
        let p = load_str("offscreen.toml", "[trace]\noffscreen = \"trace\"\n").unwrap();
        assert_eq!(p.offscreen_samples, OffscreenSamples::Trace);
        let o = ProfileOverrides {
            offscreen_samples: Some("cull".into()),
            ..Default::default()
        };
        assert_eq!(
            p.override_with(&o).unwrap().offscreen_samples,
            OffscreenSamples::Cull
        );
        let bad = ProfileOverrides {
            offscreen_samples: Some("skip".into()),
            ..Default::default()
        };
        let err = format!(
            "{:#}",
            RenderProfile::default().override_with(&bad).unwrap_err()
        );
        assert!(
            err.contains("--offscreen-samples") && err.contains("cull, trace"),
            "{err}"
        );
        let p = load_str("reg_off.toml", "[path]\nregularisation = 0\n").unwrap();
        assert_eq!(p.path_regularisation(), 0.0);
        let o = ProfileOverrides {
            path_regularisation: Some(2.5),
            ..Default::default()
        };
        assert_eq!(p.override_with(&o).unwrap().path_regularisation(), 2.5);
        for bad in [f32::NAN, -0.5, f32::INFINITY, 1e9] {
            let o = ProfileOverrides {
                path_regularisation: Some(bad),
                ..Default::default()
            };
            let err = format!(
                "{:#}",
                RenderProfile::default().override_with(&o).unwrap_err()
            );
            assert!(
                err.contains("--path-regularisation") && err.contains("[0, 100]"),
                "{err}"
            );
        }
        let o = ProfileOverrides {
            eccentricity: Some("headset".into()),
            ..Default::default()
        };
        assert_eq!(
            RenderProfile::default()
                .override_with(&o)
                .unwrap()
                .eccentricity,
            EccentricityMode::Headset
        );
        let bad = ProfileOverrides {
            eccentricity: Some("degrees".into()),
            ..Default::default()
        };
        assert!(format!(
            "{:#}",
            RenderProfile::default().override_with(&bad).unwrap_err()
        )
        .contains("--vp-eccentricity"));
        let bad = ProfileOverrides {
            eccentricity: Some("headset".into()),
            layout: Some("screen-clipped".into()),
            ..Default::default()
        };
        assert!(format!(
            "{:#}",
            RenderProfile::default().override_with(&bad).unwrap_err()
        )
        .contains("--vp-eccentricity"));
        for radius in ["1e30", "1e-30", "0.5", "NaN", "inf", "-1", "0"] {
            let bad = ProfileOverrides {
                radius: Some(radius.into()),
                ..Default::default()
            };
            let err = format!(
                "{:#}",
                RenderProfile::default().override_with(&bad).unwrap_err()
            );
            assert!(err.contains("--vp-radius") && err.contains(radius), "{err}");
        }
        for radius in ["1", "1000000"] {
            let o = ProfileOverrides {
                radius: Some(radius.into()),
                ..Default::default()
            };
            assert!(
                RenderProfile::default().override_with(&o).is_ok(),
                "{radius}"
            );
        }
        let bad = ProfileOverrides {
            axis_scale: Some(0.0),
            ..Default::default()
        };
        assert!(format!(
            "{:#}",
            RenderProfile::default().override_with(&bad).unwrap_err()
        )
        .contains("axis_scale"));
    }

    #[test]
    fn environment_section_and_flags() {
        let p = load_str(
            "env.toml",
            "[environment]\nsun = [45.0, 30.0]\nsky_intensity = 0.0\n",
        )
        .unwrap();
        assert_eq!(
            p.environment,
            EnvironmentOptions {
                sun: Some([45.0, 30.0]),
                sun_intensity: None,
                sky_intensity: Some(0.0),
                ..Default::default()
            }
        );
        let err = format!(
            "{:#}",
            load_str("env_bad.toml", "[environment]\nsun_intensity = -1.0\n").unwrap_err()
        );
        assert!(err.contains("[environment].sun_intensity"), "{err}");
        assert!(load_str("env_key.toml", "[environment]\nmoon = 1.0\n").is_err());
        let o = ProfileOverrides {
            environment: EnvironmentOptions {
                sky_intensity: Some(2.0),
                ..Default::default()
            },
            ..Default::default()
        };
        let merged = p.override_with(&o).unwrap();
        assert_eq!(merged.environment.sky_intensity, Some(2.0));
        assert_eq!(merged.environment.sun, Some([45.0, 30.0]));
        let bad = ProfileOverrides {
            environment: EnvironmentOptions {
                sun: Some([0.0, 95.0]),
                ..Default::default()
            },
            ..Default::default()
        };
        assert!(format!(
            "{:#}",
            RenderProfile::default().override_with(&bad).unwrap_err()
        )
        .contains("--sun"));
    }

    /// `env = "../x.exr"` or an absolute path read a map from outside the profile's folder; a
    /// link inside the folder that leads out is refused too.
    #[test]
    fn a_profile_reads_maps_only_inside_its_folder() {
        let root = std::env::temp_dir().join(format!("fovea-profile-env-{}", std::process::id()));
        let (dir, outside) = (root.join("profiles"), root.join("elsewhere"));
        std::fs::create_dir_all(dir.join("maps")).unwrap();
        std::fs::create_dir_all(&outside).unwrap();
        std::fs::write(outside.join("x.exr"), b"").unwrap();
        std::fs::write(dir.join("maps/in.exr"), b"").unwrap();
        let _ = std::fs::remove_file(dir.join("maps/out.exr"));
        std::os::unix::fs::symlink(outside.join("x.exr"), dir.join("maps/out.exr")).unwrap();
        let profile = dir.join("p.toml");
        let load = |env: &str| {
            std::fs::write(&profile, format!("[environment]\nenv = {env:?}\n")).unwrap();
            RenderProfile::load(&profile)
        };
        let ok = load("maps/in.exr").unwrap();
        assert_eq!(ok.environment.env, Some(dir.join("maps/in.exr")));
        for (env, needle) in [
            ("../elsewhere/x.exr", "without `..`"),
            (outside.join("x.exr").to_str().unwrap(), "without `..`"),
            ("maps/../maps/in.exr", "without `..`"),
            ("maps/out.exr", "through a symbolic link"),
        ] {
            let err = format!("{:#}", load(env).unwrap_err());
            assert!(
                err.contains("p.toml") && err.contains("[environment].env") && err.contains(needle),
                "{env}: {err}"
            );
        }
    }

    #[test]
    fn environment_map_keys_and_flags() {
        // The map's path is relative to the profile's folder.
        let dir = std::env::temp_dir().join(format!("fovea-profile-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("sky.hdr"), b"").unwrap();
        let p = load_str(
            "envmap.toml",
            "[environment]\nenv = \"sky.hdr\"\nenv_rotation = -90.0\nenv_intensity = 2.5\n",
        )
        .unwrap();
        assert_eq!(p.environment.env, Some(dir.join("sky.hdr")));
        assert_eq!(
            (p.environment.env_rotation, p.environment.env_intensity),
            (Some(-90.0), Some(2.5))
        );
        // Flags override the profile, key by key.
        let o = ProfileOverrides {
            environment: EnvironmentOptions {
                env_intensity: Some(1.0),
                ..Default::default()
            },
            ..Default::default()
        };
        let merged = p.clone().override_with(&o).unwrap();
        assert_eq!(
            (
                merged.environment.env_intensity,
                merged.environment.env_rotation
            ),
            (Some(1.0), Some(-90.0))
        );
        let o = ProfileOverrides {
            environment: EnvironmentOptions {
                env: Some("other.exr".into()),
                ..Default::default()
            },
            ..Default::default()
        };
        assert_eq!(
            p.override_with(&o).unwrap().environment.env,
            Some("other.exr".into())
        );
        // Errors name the file and the key.
        for (text, key) in [
            ("env = \"nowhere.exr\"", "[environment].env"),
            ("env = \"../sky.hdr\"", "--env FILE"),
            ("env = \"/etc/passwd.hdr\"", "--env FILE"),
            ("env = \"envmap.toml\"", "[environment].env"),
            ("env_intensity = -1.0", "[environment].env_intensity"),
            ("env_rotation = inf", "[environment].env_rotation"),
            ("sky = \"hosek\"", "[environment].sky"),
        ] {
            let err = format!(
                "{:#}",
                load_str("envmap_bad.toml", &format!("[environment]\n{text}\n")).unwrap_err()
            );
            assert!(
                err.contains("envmap_bad.toml") && err.contains(key),
                "{text}: {err}"
            );
        }
        let bad = ProfileOverrides {
            environment: EnvironmentOptions {
                env_intensity: Some(f32::NAN),
                ..Default::default()
            },
            ..Default::default()
        };
        assert!(format!(
            "{:#}",
            RenderProfile::default().override_with(&bad).unwrap_err()
        )
        .contains("--env-intensity"));
    }

    /// `[trace] stereo_noise` and `surface_cell` (and `--stereo-noise`) reach the profile; bad
    /// values are refused naming the file and key (or the flag) and the accepted ones.
    #[test]
    fn stereo_noise_and_surface_cell_from_file_and_flag() {
        let p = load_str(
            "stereo.toml",
            "[trace]\nstereo_noise = \"surface\"\nsurface_cell = 2\n",
        )
        .unwrap();
        assert_eq!(p.stereo_noise, StereoNoise::Surface);
        assert_eq!(p.surface_cell(), 2.0);
        assert_eq!(RenderProfile::default().stereo_noise, StereoNoise::Screen);
        assert_eq!(
            RenderProfile::default().surface_cell(),
            DEFAULT_SURFACE_CELL
        );
        let o = ProfileOverrides {
            stereo_noise: Some("independent".into()),
            ..Default::default()
        };
        assert_eq!(
            p.override_with(&o).unwrap().stereo_noise,
            StereoNoise::Independent
        );
        let err = format!(
            "{:#}",
            load_str("stereo_bad.toml", "[trace]\nstereo_noise = \"eyes\"\n").unwrap_err()
        );
        assert!(
            err.contains("stereo_bad.toml")
                && err.contains("[trace].stereo_noise")
                && err.contains("independent, screen, surface"),
            "{err}"
        );
        let err = format!(
            "{:#}",
            load_str("cell_bad.toml", "[trace]\nsurface_cell = 100\n").unwrap_err()
        );
        assert!(
            err.contains("cell_bad.toml") && err.contains("surface_cell = 100"),
            "{err}"
        );
        let bad = ProfileOverrides {
            stereo_noise: Some("eyes".into()),
            ..Default::default()
        };
        let err = format!(
            "{:#}",
            RenderProfile::default().override_with(&bad).unwrap_err()
        );
        assert!(err.contains("--stereo-noise"), "{err}");
    }

    /// `[trace] cross_eye_reuse` and `--cross-eye-reuse off|on|auto` reach the profile (`auto` by
    /// default); bad values are refused naming the flag or the file and key, and the accepted
    /// values.
    #[test]
    fn cross_eye_reuse_from_file_and_flag() {
        assert_eq!(
            RenderProfile::default().cross_eye_reuse,
            CrossEyeReuse::Auto
        );
        let p = load_str("stereo.toml", "[trace]\ncross_eye_reuse = \"on\"\n").unwrap();
        assert_eq!(p.cross_eye_reuse, CrossEyeReuse::On);
        let flag = |value: &str| ProfileOverrides {
            cross_eye_reuse: Some(value.into()),
            ..Default::default()
        };
        let off = p.clone().override_with(&flag("off")).unwrap();
        assert_eq!(off.cross_eye_reuse, CrossEyeReuse::Off);
        let err = format!(
            "{:#}",
            RenderProfile::default()
                .override_with(&flag("yes"))
                .unwrap_err()
        );
        assert!(
            err.contains("--cross-eye-reuse") && err.contains("off, on, auto"),
            "{err}"
        );
        let err = format!(
            "{:#}",
            load_str("bad.toml", "[trace]\ncross_eye_reuse = \"always\"\n").unwrap_err()
        );
        assert!(
            err.contains("bad.toml") && err.contains("cross_eye_reuse") && err.contains("auto"),
            "{err}"
        );
    }

    /// `[resampling]`: the mode and parameters onto the engine's defaults, checked by name;
    /// `--resampling` sets the mode and keeps the section's parameters.
    #[test]
    fn resampling_section_and_flag() {
        let p = load_str(
            "resampling.toml",
            "[resampling]\nmode = \"di\"\ncandidates = 16\nbrdf_candidates = 2\nradius = 4.0\n",
        )
        .unwrap();
        assert_eq!(p.resampling.mode, ResamplingMode::Di);
        assert_eq!(
            (
                p.resampling.candidates,
                p.resampling.brdf_candidates,
                p.resampling.radius,
                p.resampling.neighbours
            ),
            (16, 2, 4.0, ResamplingSettings::default().neighbours)
        );
        let off = ProfileOverrides {
            resampling: Some("off".into()),
            ..Default::default()
        };
        let p = p.override_with(&off).unwrap();
        assert_eq!(
            (p.resampling.mode, p.resampling.candidates),
            (ResamplingMode::Off, 16)
        );
        let gi = load_str("resampling_gi.toml", "[resampling]\nmode = \"di+gi\"\n").unwrap();
        assert_eq!(gi.resampling.mode, ResamplingMode::DiGi);
        let err = format!(
            "{:#}",
            load_str("resampling_bad.toml", "[resampling]\ncandidates = 0\n").unwrap_err()
        );
        assert!(
            err.contains("[resampling]") && err.contains("candidates"),
            "{err}"
        );
        let err = format!(
            "{:#}",
            load_str(
                "resampling_brdf.toml",
                "[resampling]\nbrdf_candidates = 9\n"
            )
            .unwrap_err()
        );
        assert!(
            err.contains("[resampling]") && err.contains("brdf_candidates"),
            "{err}"
        );
        let err = format!(
            "{:#}",
            load_str("resampling_mode.toml", "[resampling]\nmode = \"gi\"\n").unwrap_err()
        );
        assert!(err.contains("gi") && err.contains("di"), "{err}");
        let bad = ProfileOverrides {
            resampling: Some("on".into()),
            ..Default::default()
        };
        let err = format!(
            "{:#}",
            RenderProfile::default().override_with(&bad).unwrap_err()
        );
        assert!(
            err.contains("--resampling") && err.contains("off, di"),
            "{err}"
        );
    }
}
