//! What a rendered scene looks like beyond its file: the camera (`--camera`, the free camera of
//! `--camera-pos/--camera-look/--fov`, or one that frames the scene when the file has none) and
//! the default environment (a sun and an analytic sky) for scenes that bring no light of their own.
//! Every command that renders the scene camera (render, view, xr, replay, quality, reference)
//! loads its scene through [`load`], so they all see the same thing.
//!
//! The environment rule (`--default-light auto`, the default), by power rather than presence:
//! - a scene whose own emitters (emissive triangles, punctual lights) send out less than
//!   `MIN_OWN_LIGHT_SHARE` of the power the default sun sends through the scene's bounding sphere
//!   (`own_light_share`; powers as the light table counts them) is not lit by them — a model whose
//!   only emitters are small details (indicator lights, screens) would render near-black — and
//!   gets the default sun (a directional light in the light table, so next-event estimation
//!   samples it) and the default sky, as a scene without any light does;
//! - a scene lit by its own lights gets no sun, and the sky only when `--sky-intensity` (or the
//!   profile's `environment.sky_intensity`) is given explicitly and > 0;
//! - `--default-light on` adds the default sun and sky whatever the scene holds, `off` never;
//! - `--sun-intensity 0` / `--sky-intensity 0` turn either part off;
//! - `--env FILE` (an HDR environment map, `crate::env_map`) replaces the sky in every scene; the
//!   sun then stays off unless `--sun` (or the profile's `sun`) is given, because a captured map
//!   usually holds its own sun — adding one would light the scene twice. Scenes lit by their own
//!   lights never get the sun.

pub use crate::projection::{Framing, Projection};
pub use crate::sky_model::{default_sky, sun_direction};
use crate::sky_model::{preetham_map, SkyModel};
use anyhow::{bail, Context, Result};
use fovea_renderer::scene::{Camera, PunctualLight, Scene, Sky};
use glam::Vec3;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

/// The default sun: azimuth (degrees from +Z, the side glTF models face, toward +X) and elevation
/// above the horizon. High enough to reach into a courtyard, low enough to cast visible shadows.
pub const DEFAULT_SUN: [f32; 2] = [30.0, 60.0];
/// Illuminance (lux-like units) on a surface facing the sun: a white Lambertian surface lit
/// head-on has radiance E/π ≈ 0.95, bright but not clipped by the ACES curve at exposure 1.
pub const DEFAULT_SUN_INTENSITY: f32 = 3.0;
/// Scale of the default sky's radiance (see [`default_sky`]): with the default sun, sky light on
/// an open floor is about a sixth of the sun's.
pub const DEFAULT_SKY_INTENSITY: f32 = 0.5;
/// A scene's own emitters light it when they send out at least this share of the default sun's
/// power through the scene's bounding sphere. The Cornell box's ceiling light sends 25 % of it,
/// a car model's 10 cm² of indicator lights at emissive strength 1 about 0.02 %: 2 % keeps any
/// scene whose emitters are meant to light it, lamps in a room included, and lights the rest.
pub const MIN_OWN_LIGHT_SHARE: f32 = 0.02;
/// Largest sun illuminance / sky radiance scale: far beyond anything useful, small enough that
/// radiance sums stay finite in f32.
pub const MAX_INTENSITY: f32 = 1e6;
/// The vertical FOV of the framing camera without `--fov` (degrees).
pub const DEFAULT_FOV_DEG: f32 = 60.0;
/// `--fov` is accepted strictly inside this range (degrees): at 0 nothing is seen, at 180 the
/// pinhole projection is infinite.
pub const FOV_RANGE_DEG: (f32, f32) = (1.0, 170.0);

/// Largest `--env-rotation` magnitude (degrees): any angle is meaningful, this only keeps the
/// radians conversion exact enough.
pub const MAX_ENV_ROTATION_DEG: f32 = 1e6;

/// The default environment's settings, each `None` when neither the flag nor the profile gave it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EnvironmentOptions {
    /// Azimuth, elevation in degrees.
    pub sun: Option<[f32; 2]>,
    pub sun_intensity: Option<f32>,
    pub sky_intensity: Option<f32>,
    /// An equirectangular HDR environment map (`--env`; a profile's path is relative to its file).
    pub env: Option<PathBuf>,
    /// Degrees about +Y, counter-clockwise seen from above (default 0).
    pub env_rotation: Option<f32>,
    /// Radiance scale of the map (default 1).
    pub env_intensity: Option<f32>,
    /// The sky's model (`--sky`; default the gradient).
    pub sky: Option<SkyModel>,
    /// When the default sun and sky light the scene (`--default-light`; default `Auto`).
    pub default_light: Option<DefaultLight>,
}

/// `--default-light`: when a scene gets the default sun and sky (see the module's rule).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DefaultLight {
    /// When the scene's own emitters send out less than `MIN_OWN_LIGHT_SHARE` of the sun's power.
    #[default]
    Auto,
    /// Always, beside the scene's own lights.
    On,
    /// Never: the scene as authored.
    Off,
}

impl DefaultLight {
    pub const NAMES: &'static [&'static str] = &["auto", "on", "off"];

    pub fn parse(name: &str) -> Result<DefaultLight> {
        match name {
            "auto" => Ok(DefaultLight::Auto),
            "on" => Ok(DefaultLight::On),
            "off" => Ok(DefaultLight::Off),
            other => bail!(
                "--default-light {other}: expected one of {}",
                DefaultLight::NAMES.join(", ")
            ),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            DefaultLight::Auto => "auto",
            DefaultLight::On => "on",
            DefaultLight::Off => "off",
        }
    }
}

/// The power `scene`'s own emitters send out (emissive triangles with their mean emissive
/// texture colour, punctual lights; the light table's rule) over the power of the default sun
/// through the scene's bounding sphere. 0 for a scene without emitters.
pub fn own_light_share(scene: &Scene) -> f32 {
    let own = fovea_renderer::scene::lights::build_light_table(scene).total_power;
    let r = scene.bounds().bounding_sphere_radius();
    let sun = DEFAULT_SUN_INTENSITY * std::f32::consts::PI * r * r;
    if sun > 0.0 {
        own / sun
    } else {
        0.0
    }
}

/// Whether the scene's own lights light it (no default sun and sky), by `env.default_light`.
/// The second value is the measured share, for the notice.
fn lit_by_its_own_lights(scene: &Scene, env: &EnvironmentOptions) -> (bool, f32) {
    let share = own_light_share(scene);
    let lit = match env.default_light.unwrap_or_default() {
        DefaultLight::Auto => share >= MIN_OWN_LIGHT_SHARE,
        DefaultLight::On => false,
        DefaultLight::Off => true,
    };
    (lit, share)
}

/// Why the default light is on, for the notice.
fn default_light_reason(share: f32, env: &EnvironmentOptions) -> String {
    match env.default_light.unwrap_or_default() {
        DefaultLight::On => "--default-light on".into(),
        _ if share <= 0.0 => "no lights in the scene".into(),
        _ => format!(
            "the scene's own emitters send out {:.2} % of the default sun's power through its bounds \
             (they light a scene from {:.0} %; --default-light off keeps the scene as authored)",
            share * 100.0,
            MIN_OWN_LIGHT_SHARE * 100.0
        ),
    }
}

/// The names used in error messages: the flags, or a profile's keys.
pub struct EnvironmentNames {
    pub sun: String,
    pub sun_intensity: String,
    pub sky_intensity: String,
    pub env_rotation: String,
    pub env_intensity: String,
}

impl EnvironmentNames {
    pub fn flags() -> EnvironmentNames {
        EnvironmentNames {
            sun: "--sun".into(),
            sun_intensity: "--sun-intensity".into(),
            sky_intensity: "--sky-intensity".into(),
            env_rotation: "--env-rotation".into(),
            env_intensity: "--env-intensity".into(),
        }
    }
    /// `FILE: [environment].key`.
    pub fn profile(file: &str) -> EnvironmentNames {
        let key = |k: &str| format!("{file}: [environment].{k}");
        EnvironmentNames {
            sun: key("sun"),
            sun_intensity: key("sun_intensity"),
            sky_intensity: key("sky_intensity"),
            env_rotation: key("env_rotation"),
            env_intensity: key("env_intensity"),
        }
    }
}

impl EnvironmentOptions {
    /// `self` with every value `over` gives replaced.
    pub fn overridden(&self, over: &EnvironmentOptions) -> EnvironmentOptions {
        EnvironmentOptions {
            sun: over.sun.or(self.sun),
            sun_intensity: over.sun_intensity.or(self.sun_intensity),
            sky_intensity: over.sky_intensity.or(self.sky_intensity),
            env: over.env.clone().or_else(|| self.env.clone()),
            env_rotation: over.env_rotation.or(self.env_rotation),
            env_intensity: over.env_intensity.or(self.env_intensity),
            sky: over.sky.or(self.sky),
            default_light: over.default_light.or(self.default_light),
        }
    }

    /// The settings as replay baselines record them: the sun and sky fields always, the map's
    /// fields only when given (so baselines made without a map do not read as changed).
    pub fn describe(&self) -> String {
        let base = format!(
            "EnvironmentOptions {{ sun: {:?}, sun_intensity: {:?}, sky_intensity: {:?}",
            self.sun, self.sun_intensity, self.sky_intensity
        );
        let sky = self
            .sky
            .map_or(String::new(), |m| format!(", sky: {}", m.name()));
        let light = self
            .default_light
            .map_or(String::new(), |d| format!(", default_light: {}", d.name()));
        if self.env.is_none() && self.env_rotation.is_none() && self.env_intensity.is_none() {
            return format!("{base}{sky}{light} }}");
        }
        format!(
            "{base}, env: {:?}, env_rotation: {:?}, env_intensity: {:?}{sky}{light} }}",
            self.env, self.env_rotation, self.env_intensity
        )
    }

    pub fn validate(&self, names: &EnvironmentNames) -> Result<()> {
        if let Some([azimuth, elevation]) = self.sun {
            if !(azimuth.is_finite()
                && elevation.is_finite()
                && elevation > 0.0
                && elevation <= 90.0)
            {
                bail!(
                    "{} {azimuth},{elevation}: expected AZIMUTH,ELEVATION in degrees, azimuth finite, elevation in (0, 90] (a sun at or below the horizon lights nothing from above)",
                    names.sun
                );
            }
        }
        if let Some(r) = self
            .env_rotation
            .filter(|r| !(r.is_finite() && r.abs() <= MAX_ENV_ROTATION_DEG))
        {
            bail!(
                "{} {r:?}: must be a finite angle in degrees within ±{MAX_ENV_ROTATION_DEG:e}",
                names.env_rotation
            );
        }
        check_intensity(self.sun_intensity, &names.sun_intensity)?;
        check_intensity(self.sky_intensity, &names.sky_intensity)?;
        check_intensity(self.env_intensity, &names.env_intensity)
    }
}

fn check_intensity(value: Option<f32>, name: &str) -> Result<()> {
    match value {
        Some(v) if !(v.is_finite() && (0.0..=MAX_INTENSITY).contains(&v)) => {
            bail!("{name} {v:?}: must be finite and in [0, {MAX_INTENSITY:e}] (0 turns it off)")
        }
        _ => Ok(()),
    }
}

/// `AZIMUTH,ELEVATION` (degrees) as `--sun` takes it.
pub fn parse_sun(text: &str) -> Result<[f32; 2]> {
    let values = parse_floats(text)
        .with_context(|| format!("--sun {text}: expected AZIMUTH,ELEVATION in degrees"))?;
    match values[..] {
        [a, e] => Ok([a, e]),
        _ => bail!("--sun {text}: expected two numbers, AZIMUTH,ELEVATION in degrees"),
    }
}

fn parse_floats(text: &str) -> Result<Vec<f32>> {
    text.split(',')
        .map(|v| {
            v.trim()
                .parse::<f32>()
                .with_context(|| format!("'{}' is not a number", v.trim()))
        })
        .collect()
}

/// Adds the default sun and sky where the rule of this module says so; returns the one-line
/// notice to print when it did.
pub fn apply_environment(scene: &mut Scene, env: &EnvironmentOptions) -> Option<String> {
    let (lit, share) = lit_by_its_own_lights(scene, env);
    if lit {
        // The scene's own lighting stays as authored; only an explicit sky is added.
        if let Some(s) = env.sky_intensity.filter(|&s| s > 0.0) {
            set_sky(scene, env, s);
        }
        return None;
    }
    let [azimuth, elevation] = env.sun.unwrap_or(DEFAULT_SUN);
    let sun = env.sun_intensity.unwrap_or(DEFAULT_SUN_INTENSITY);
    let sky = env.sky_intensity.unwrap_or(DEFAULT_SKY_INTENSITY);
    if sun > 0.0 {
        // `direction` is where the light travels: away from the sun.
        scene.punctual_lights.push(PunctualLight::Directional {
            direction: -sun_direction(azimuth, elevation),
            illuminance: Vec3::splat(sun),
        });
    }
    set_sky(scene, env, sky);
    let model = env.sky.unwrap_or_default().name();
    Some(format!(
        "{}: using the default sun and sky (sun at azimuth {azimuth}°, elevation {elevation}°, intensity {sun}; {model} sky, intensity {sky}; \
         change with --sun AZIMUTH,ELEVATION, --sun-intensity, --sky-intensity, --sky gradient|preetham or a profile's [environment]; 0 turns either off)",
        default_light_reason(share, env)
    ))
}

/// The sky of intensity `intensity` in the chosen model: the gradient as the scene's `Sky`, the
/// Preetham sky (around the sun's position, with or without the sun light itself) as a baked map.
fn set_sky(scene: &mut Scene, env: &EnvironmentOptions, intensity: f32) {
    match env.sky.unwrap_or_default() {
        SkyModel::Gradient => scene.sky = default_sky(intensity),
        SkyModel::Preetham if intensity > 0.0 => {
            let [azimuth, elevation] = env.sun.unwrap_or(DEFAULT_SUN);
            scene.sky = Sky::default();
            scene.environment = Some(preetham_map(sun_direction(azimuth, elevation), intensity));
        }
        SkyModel::Preetham => scene.sky = Sky::default(),
    }
}

/// With `--env`: the map replaces the sky; the sun only with an explicit `sun` in a scene without
/// lights (see the module's rule). Returns the notice for scenes without lights of their own.
pub fn apply_environment_map(
    scene: &mut Scene,
    env: &EnvironmentOptions,
) -> Result<Option<String>> {
    let Some(path) = &env.env else {
        return Ok(apply_environment(scene, env));
    };
    let map = crate::env_map::load(
        path,
        env.env_rotation.unwrap_or(0.0),
        env.env_intensity.unwrap_or(1.0),
    )?;
    let (lit, share) = lit_by_its_own_lights(scene, env);
    scene.environment = Some(map);
    scene.sky = Sky::default();
    if lit {
        return Ok(None);
    }
    let sun = match env.sun {
        Some([azimuth, elevation]) if env.sun_intensity.unwrap_or(DEFAULT_SUN_INTENSITY) > 0.0 => {
            let e = env.sun_intensity.unwrap_or(DEFAULT_SUN_INTENSITY);
            scene.punctual_lights.push(PunctualLight::Directional {
                direction: -sun_direction(azimuth, elevation),
                illuminance: Vec3::splat(e),
            });
            format!("sun at azimuth {azimuth}°, elevation {elevation}°, intensity {e}")
        }
        _ => "no sun: --sun AZIMUTH,ELEVATION adds one".into(),
    };
    Ok(Some(format!(
        "{}: lit by the environment map {} ({sun})",
        default_light_reason(share, env),
        path.display()
    )))
}

/// How the camera is chosen (`--camera`, `--camera-pos`, `--camera-look`, `--fov`), as given.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraOptions {
    /// A glTF camera by index or name.
    pub camera: Option<String>,
    /// The free camera's position and the point it looks at, `X,Y,Z` each.
    pub position: Option<String>,
    pub look: Option<String>,
    /// Vertical FOV in degrees: the free or framing camera's, or overriding a glTF camera's
    /// (only `Projection::SceneCamera` renders through it).
    pub fov: Option<f32>,
    /// Each eye through its headset frustum (the camera is the head) or the camera's own FOV.
    pub projection: Projection,
    /// Metres per scene unit (`--world-scale`; glTF's metre is 1): the eyes' offsets and a
    /// headset's movements are metres, the scene's coordinates its own units.
    pub world_scale: f32,
}

impl Default for CameraOptions {
    fn default() -> Self {
        NO_CAMERA_FLAGS.clone()
    }
}

/// `--world-scale` range: from micrometre to kilometre units.
pub const WORLD_SCALE_RANGE: (f32, f32) = (1e-6, 1e3);

/// No camera flag: the file's first camera, else the framing one (code that builds arguments).
pub static NO_CAMERA_FLAGS: CameraOptions = CameraOptions {
    camera: None,
    position: None,
    look: None,
    fov: None,
    projection: Projection::Headset,
    world_scale: 1.0,
};

/// A checked camera choice.
#[derive(Clone, Debug, PartialEq)]
enum Choice {
    /// `--camera`, or the file's first camera (None), else the framing camera.
    Scene(Option<String>),
    Free {
        position: Vec3,
        look: Vec3,
    },
}

impl CameraOptions {
    fn choice(&self) -> Result<Choice> {
        let (lo, hi) = WORLD_SCALE_RANGE;
        if !(self.world_scale.is_finite() && (lo..=hi).contains(&self.world_scale)) {
            bail!(
                "--world-scale {:?}: metres per scene unit must be in [{lo:e}, {hi:e}] (1 for glTF's metres, 0.01 for a scene in centimetres)",
                self.world_scale
            );
        }
        if let Some(fov) = self.fov {
            let (lo, hi) = FOV_RANGE_DEG;
            if !(fov.is_finite() && fov > lo && fov < hi) {
                bail!("--fov {fov:?}: the vertical field of view must be in ({lo}, {hi}) degrees");
            }
            if self.projection == Projection::Headset {
                bail!(
                    "--fov {fov}: each eye is rendered through its headset profile's field of view \
                     (--projection headset, the default); --fov applies with --projection scene-camera"
                );
            }
        }
        match (&self.camera, &self.position, &self.look) {
            (camera, None, None) => Ok(Choice::Scene(camera.clone())),
            (Some(_), _, _) => bail!("--camera picks a camera of the scene; --camera-pos/--camera-look place a free one: give one or the other"),
            (None, Some(p), Some(l)) => {
                let position = parse_point(p, "--camera-pos")?;
                let look = parse_point(l, "--camera-look")?;
                if (look - position).length() <= 1e-6 * position.length().max(1.0) {
                    bail!("--camera-pos {p} and --camera-look {l}: the camera must look at a point other than its own position");
                }
                Ok(Choice::Free { position, look })
            }
            (None, Some(_), None) => bail!("--camera-pos needs --camera-look X,Y,Z (the point the camera looks at)"),
            (None, None, Some(_)) => bail!("--camera-look needs --camera-pos X,Y,Z (where the camera stands)"),
        }
    }

    /// Checks the flags alone (before a scene is loaded).
    pub fn check(&self) -> Result<()> {
        self.choice().map(|_| ())
    }

    /// The camera these options choose in `scene`; `framing` sizes the framing camera so the
    /// scene fits both ways. The bool is true when the framing camera stands in for a file
    /// without one.
    pub fn camera_for(&self, scene: &Scene, framing: Framing) -> Result<(Camera, bool)> {
        let fov = self.fov.map(f32::to_radians);
        let aspect = framing.aspect;
        match self.choice()? {
            Choice::Free { position, look } => Ok((
                Camera::look_at(
                    position,
                    look,
                    fov.unwrap_or(DEFAULT_FOV_DEG.to_radians()),
                    "free (--camera-pos)",
                ),
                false,
            )),
            Choice::Scene(Some(wanted)) => {
                let mut camera = find_camera(scene, &wanted)?.clone();
                camera.yfov = fov.unwrap_or(camera.yfov);
                Ok((camera, false))
            }
            Choice::Scene(None) => match scene.default_camera() {
                Some(camera) => Ok((
                    Camera {
                        yfov: fov.unwrap_or(camera.yfov),
                        ..camera.clone()
                    },
                    false,
                )),
                None => {
                    let yfov = fov.or(framing.yfov);
                    let framing =
                        scene.framing_camera(yfov.unwrap_or(DEFAULT_FOV_DEG.to_radians()), aspect);
                    let framing = framing.with_context(|| {
                        format!(
                            "{}: the scene is empty: no camera can frame it",
                            scene.source.display()
                        )
                    })?;
                    Ok((framing, true))
                }
            },
        }
    }
}

fn parse_point(text: &str, flag: &str) -> Result<Vec3> {
    let values = parse_floats(text).with_context(|| format!("{flag} {text}: expected X,Y,Z"))?;
    match values[..] {
        [x, y, z] if [x, y, z].iter().all(|v| v.is_finite()) => Ok(Vec3::new(x, y, z)),
        [_, _, _] => bail!("{flag} {text}: every coordinate must be finite"),
        _ => bail!("{flag} {text}: expected three numbers X,Y,Z"),
    }
}

/// A glTF camera by index (digits) or by name; the error lists what the file has.
fn find_camera<'a>(scene: &'a Scene, wanted: &str) -> Result<&'a Camera> {
    let by_index = wanted
        .parse::<usize>()
        .ok()
        .and_then(|i| scene.cameras.get(i));
    if let Some(camera) = by_index.or_else(|| scene.cameras.iter().find(|c| c.name == wanted)) {
        return Ok(camera);
    }
    if scene.cameras.is_empty() {
        bail!(
            "--camera {wanted}: {} has no perspective camera (without --camera a default camera frames the scene; --camera-pos/--camera-look place one)",
            scene.source.display()
        );
    }
    let list: Vec<String> = scene
        .cameras
        .iter()
        .enumerate()
        .map(|(i, c)| format!("{i} \"{}\"", c.name))
        .collect();
    bail!(
        "--camera {wanted}: no such camera in {}; it has {}",
        scene.source.display(),
        list.join(", ")
    )
}

/// Says `text` on stderr once per process (`fovea quality` sets up many runs of one scene).
fn notice_once(flag: &AtomicBool, text: &str) {
    if !flag.swap(true, Ordering::Relaxed) {
        eprintln!("{text}");
    }
}

static ENVIRONMENT_NOTICE: AtomicBool = AtomicBool::new(false);
static CAMERA_NOTICE: AtomicBool = AtomicBool::new(false);

/// Loads `--scene` with its default environment (when the rule says so) and the chosen camera.
pub fn load(
    scene_name: &str,
    camera: &CameraOptions,
    env: &EnvironmentOptions,
    framing: Framing,
) -> Result<(Scene, Camera)> {
    camera.check()?;
    env.validate(&EnvironmentNames::flags())?;
    let mut scene = crate::scenes::load(scene_name)?;
    if let Some(notice) = apply_environment_map(&mut scene, env)? {
        notice_once(&ENVIRONMENT_NOTICE, &notice);
    }
    let (chosen, framed) = camera.camera_for(&scene, framing)?;
    if framed {
        notice_once(
            &CAMERA_NOTICE,
            &format!(
                "{}: no camera in the file: using one that frames the scene's bounds (--camera-pos/--camera-look/--fov place another)",
                scene.source.display()
            ),
        );
    }
    Ok((scene, chosen))
}

#[cfg(test)]
#[path = "look_tests.rs"]
mod tests;
