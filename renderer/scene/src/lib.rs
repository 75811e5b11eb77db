//! CPU scene data for the fovea renderer: glTF 2.0 loading, a binned-SAH BVH laid out for GPU
//! traversal, a watertight CPU ray–triangle intersector (the reference the GPU is tested against)
//! and the light-selection table. No Vulkan here: the renderer uploads what this crate produces.
//!
//! Meshes placed once are flattened into world space (node transforms applied); meshes placed by
//! several nodes are kept once in object space with one transform per placement
//! ([`instancing`]). The tracer traverses one world-space BVH over the flattened triangles and a
//! top-level BVH over the instances, each leading to its mesh's object-space BVH.

pub mod bvh;
pub mod environment;
mod geometry;
mod images;
pub mod instancing;
pub mod intersect;
pub mod lights;
pub mod limits;
mod load;
mod load_material;
mod source;
mod validate;

#[cfg(test)]
mod test_util;

use glam::{Mat4, Vec2, Vec3, Vec4};
use std::path::{Path, PathBuf};

pub use bvh::{Bvh, BvhNode};
pub use environment::{EnvironmentDistribution, EnvironmentMap};
pub use instancing::{Instance, InstancedMesh, Instancing};
pub use intersect::{Hit, Ray};
pub use lights::{
    build_light_table, build_light_table_scaled, AliasSlot, LightEntry, LightKind, LightTable,
};
pub use limits::LoadLimits;
pub use validate::MAX_EMISSIVE_STRENGTH;

/// A loaded scene: meshes placed once flattened to world space, repeated ones instanced.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// World-space vertices of the meshes placed by exactly one node.
    pub vertices: Vec<Vertex>,
    /// Their triangles: placed ids `0 .. triangles.len()` (see [`instancing`]).
    pub triangles: Vec<Triangle>,
    /// Meshes placed by two or more nodes, once each in object space, and their placements.
    pub instancing: Instancing,
    /// glTF materials in document order; when some primitive has no material, one default material
    /// (all glTF defaults) is appended at the end. A material that no rendered primitive uses is
    /// kept (so indices stay glTF's) but without textures: its images are never decoded.
    pub materials: Vec<Material>,
    /// One entry per glTF *image* that a rendered material samples, in glTF image order
    /// (materials refer to images, so two glTF textures that share an image share the texels).
    /// Images nothing renders (an unused material's, a DDS alternative only an extension names)
    /// are neither read nor decoded.
    pub textures: Vec<Texture>,
    pub punctual_lights: Vec<PunctualLight>,
    /// Perspective cameras in scene-traversal order; `cameras[0]` is the default camera.
    pub cameras: Vec<Camera>,
    /// Radiance of rays that leave the scene (glTF has none: black unless the caller sets one).
    pub sky: Sky,
    /// An HDR environment map seen by escaping rays; replaces `sky` when set (see [`Scene::environment_map`]).
    pub environment: Option<EnvironmentMap>,
    /// Indexed by [`Triangle::mesh`]: the glTF mesh name, or `mesh<i>` when unnamed.
    pub mesh_names: Vec<String>,
    pub source: PathBuf,
    /// What the loader ignored and the user may want to know (each said once), e.g. extensions
    /// the renderer does not understand. Callers print them.
    pub warnings: Vec<String>,
}

/// A world-space vertex. `tangent.w` is the bitangent sign: `bitangent = cross(normal, tangent.xyz) * w`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vertex {
    pub position: Vec3,
    pub normal: Vec3,
    pub uv: Vec2,
    pub tangent: Vec4,
}

/// Indices into [`Scene::vertices`], counter-clockwise seen from the front face (also after
/// mirroring node transforms, which the loader compensates by swapping two indices).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Triangle {
    pub indices: [u32; 3],
    pub material: u32,
    /// Index of the glTF mesh this triangle came from (shared by all instances of that mesh).
    pub mesh: u32,
}

/// PBR metallic-roughness material plus the KHR extensions the tracer uses.
/// Texture fields index [`Scene::textures`].
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub base_color: Vec4,
    pub base_color_texture: Option<u32>,
    pub metallic: f32,
    pub roughness: f32,
    pub metallic_roughness_texture: Option<u32>,
    pub normal_texture: Option<u32>,
    pub normal_scale: f32,
    /// emissiveFactor × KHR_materials_emissive_strength.
    pub emissive: Vec3,
    pub emissive_texture: Option<u32>,
    pub specular_factor: f32,
    pub specular_texture: Option<u32>,
    pub specular_color: Vec3,
    pub specular_color_texture: Option<u32>,
    pub ior: f32,
    pub double_sided: bool,
    /// glTF `alphaMode: MASK`: hits where base-colour alpha (factor × texture) is below this
    /// cutoff are no hits. `None`: not masked.
    pub alpha_cutoff: Option<f32>,
    /// glTF `alphaMode: BLEND`, as stochastic transparency: a hit counts with probability alpha.
    pub alpha_blend: bool,
    /// KHR_texture_transform of each texture slot, in [`TextureSlot`] order (identity when none).
    pub uv_transforms: [UvTransform; TextureSlot::COUNT],
}

/// A material's texture slots, in the order the GPU material and [`Material::uv_transforms`] use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TextureSlot {
    BaseColor,
    MetallicRoughness,
    Normal,
    Emissive,
    Specular,
    SpecularColor,
}

impl TextureSlot {
    pub const COUNT: usize = 6;
    pub const ALL: [TextureSlot; TextureSlot::COUNT] = [
        Self::BaseColor,
        Self::MetallicRoughness,
        Self::Normal,
        Self::Emissive,
        Self::Specular,
        Self::SpecularColor,
    ];

    /// Whether the slot's texels are sRGB-encoded colour (glTF: base colour, emissive, specular
    /// colour); the others hold linear data.
    pub fn is_srgb(self) -> bool {
        matches!(self, Self::BaseColor | Self::Emissive | Self::SpecularColor)
    }
}

impl Material {
    /// The texture (index into [`Scene::textures`]) bound to `slot`, if any.
    pub fn texture(&self, slot: TextureSlot) -> Option<u32> {
        match slot {
            TextureSlot::BaseColor => self.base_color_texture,
            TextureSlot::MetallicRoughness => self.metallic_roughness_texture,
            TextureSlot::Normal => self.normal_texture,
            TextureSlot::Emissive => self.emissive_texture,
            TextureSlot::Specular => self.specular_texture,
            TextureSlot::SpecularColor => self.specular_color_texture,
        }
    }
}

/// KHR_texture_transform: uv' = T · R · S · uv, in glTF's order (scale, then rotation by
/// `rotation` radians, then the offset).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    pub offset: Vec2,
    pub rotation: f32,
    pub scale: Vec2,
}

impl UvTransform {
    pub const IDENTITY: UvTransform = UvTransform {
        offset: Vec2::ZERO,
        rotation: 0.0,
        scale: Vec2::ONE,
    };

    /// The affine map as two rows: u' = rows[0].xy · uv + rows[0].z, v' likewise with rows[1]
    /// (the extension's matrix T · R · S).
    pub fn rows(&self) -> [Vec3; 2] {
        let (sin, cos) = self.rotation.sin_cos();
        [
            Vec3::new(cos * self.scale.x, sin * self.scale.y, self.offset.x),
            Vec3::new(-sin * self.scale.x, cos * self.scale.y, self.offset.y),
        ]
    }

    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let [u, v] = self.rows();
        Vec2::new(u.truncate().dot(uv) + u.z, v.truncate().dot(uv) + v.z)
    }
}

impl Default for UvTransform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Default for Material {
    /// The glTF default material ("a material with no properties specified"): white, metallic 1,
    /// roughness 1, with the extension defaults (specular 1, specular colour 1, ior 1.5).
    fn default() -> Self {
        Material {
            base_color: Vec4::ONE,
            base_color_texture: None,
            metallic: 1.0,
            roughness: 1.0,
            metallic_roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            emissive: Vec3::ZERO,
            emissive_texture: None,
            specular_factor: 1.0,
            specular_texture: None,
            specular_color: Vec3::ONE,
            specular_color_texture: None,
            ior: 1.5,
            double_sided: false,
            alpha_cutoff: None,
            alpha_blend: false,
            uv_transforms: [UvTransform::IDENTITY; TextureSlot::COUNT],
        }
    }
}

/// Raw RGBA8 texels, row-major from the top-left. Colour-space decoding is the shader's job
/// (base colour, emissive and specular colour are sRGB; the others are linear).
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    pub width: u32,
    pub height: u32,
    pub rgba8: Vec<u8>,
}

/// KHR_lights_punctual lights in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PunctualLight {
    Point {
        position: Vec3,
        intensity: Vec3,
        range: Option<f32>,
    },
    Spot {
        position: Vec3,
        direction: Vec3,
        intensity: Vec3,
        range: Option<f32>,
        inner_cone: f32,
        outer_cone: f32,
    },
    Directional {
        direction: Vec3,
        illuminance: Vec3,
    },
}

/// A perspective camera. `world_from_view` maps glTF view space (−Z forward, +Y up, +X right)
/// to world space; any node scale is removed so its 3×3 part is a rotation.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub world_from_view: Mat4,
    /// Vertical field of view in radians.
    pub yfov: f32,
    pub aspect: Option<f32>,
    pub znear: f32,
    pub name: String,
}

/// A simple analytic sky seen by rays that escape the scene (+Y up, glTF's convention):
/// above the horizon the radiance goes from `horizon` to `zenith` with √(sin elevation), below
/// it it is `ground`. All three equal give a uniform environment (the furnace tests); all zero
/// (the default) is no environment at all.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sky {
    pub zenith: Vec3,
    pub horizon: Vec3,
    pub ground: Vec3,
}

impl Sky {
    /// The same radiance in every direction.
    pub fn uniform(radiance: Vec3) -> Sky {
        Sky {
            zenith: radiance,
            horizon: radiance,
            ground: radiance,
        }
    }
    pub fn is_black(&self) -> bool {
        self.zenith == Vec3::ZERO && self.horizon == Vec3::ZERO && self.ground == Vec3::ZERO
    }
}

/// Axis-aligned bounding box. The empty box has min = +1e30 and max = −1e30 so that a slab
/// test against it always misses (the same sentinel the GPU node layout uses).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(1e30),
        max: Vec3::splat(-1e30),
    };

    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }
    pub fn grow(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }
    pub fn contains_point(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }
    /// Surface area; 0 for an empty box (used by the SAH).
    pub fn surface_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.max - self.min;
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }
    /// Radius of the sphere around `center()` that encloses the box; 0 when empty.
    pub fn bounding_sphere_radius(&self) -> f32 {
        if self.is_empty() {
            0.0
        } else {
            (self.max - self.min).length() * 0.5
        }
    }
    pub fn of_points(points: &[Vec3]) -> Aabb {
        let mut b = Aabb::EMPTY;
        points.iter().for_each(|&p| b.grow(p));
        b
    }
}

/// Everything that can go wrong loading a scene. Every message names the file.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("{}: cannot read the file: {source}", file.display())]
    Io {
        file: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: not a readable glTF/GLB file (malformed JSON or binary container): {detail}", file.display())]
    Malformed { file: PathBuf, detail: String },
    #[error("{}: invalid glTF: {detail}", file.display())]
    Invalid { file: PathBuf, detail: String },
    #[error("{}: unsupported glTF feature: {feature}", file.display())]
    Unsupported { file: PathBuf, feature: String },
    #[error("{}: cannot load buffer or image data: {detail}", file.display())]
    Data { file: PathBuf, detail: String },
    #[error("{}: mesh '{mesh}' primitive {primitive}: {problem}", file.display())]
    BadPrimitive {
        file: PathBuf,
        mesh: String,
        primitive: usize,
        problem: String,
    },
    /// A buffer that cannot be read: `item` is e.g. `buffers[2]`; `uri` is shown without data-URI
    /// payloads.
    #[error("{}: {item} (uri \"{uri}\"): {reason}", file.display())]
    Reference {
        file: PathBuf,
        item: String,
        uri: String,
        reason: String,
    },
    /// An image that cannot be read or decoded; `location` is its URI or bufferView.
    #[error("{}: images[{index}] ({location}, mime type {mime}) cannot be loaded: {reason}", file.display())]
    Image {
        file: PathBuf,
        index: usize,
        location: String,
        mime: String,
        reason: String,
    },
    /// A [`LoadLimits`] budget would be exceeded; `detail` names the budget and how to raise it.
    #[error("{}: {detail}", file.display())]
    Budget { file: PathBuf, detail: String },
}

/// [`Scene::load_with_limits`] without its panic backstop, for the fuzz targets (`fuzz/`): there a
/// panic is a bug to find, not to hide. Renderers load with [`Scene::load_with_limits`].
#[doc(hidden)]
pub fn load_unguarded(path: &Path, limits: &LoadLimits) -> Result<Scene, SceneError> {
    load::load_unguarded(path, limits)
}

impl Scene {
    /// Loads a `.gltf` (with embedded or external buffers/images) or `.glb` file within the
    /// budgets of [`LoadLimits::from_env`] (the defaults unless `FOVEA_MAX_*` variables are set).
    /// Orthographic cameras are ignored (the tracer only has a perspective model); a scene without
    /// a perspective camera loads with `cameras` empty and the caller chooses a fallback.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let limits = LoadLimits::from_env().map_err(|detail| SceneError::Budget {
            file: path.to_path_buf(),
            detail,
        })?;
        load::load(path, &limits)
    }

    /// [`Scene::load`] with explicit budgets.
    pub fn load_with_limits(path: &Path, limits: &LoadLimits) -> Result<Scene, SceneError> {
        load::load(path, limits)
    }

    /// World-space bounds of all placed triangles (empty box for an empty scene).
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for (corners, _) in self.placed_triangles() {
            corners.iter().for_each(|&p| b.grow(p));
        }
        b
    }

    /// World-space corners of every placed triangle, by placed id (instances expanded: what a
    /// flat reference traverses; the world BVH's input is [`Scene::flat_positions`]).
    pub fn triangle_positions(&self) -> Vec<[Vec3; 3]> {
        self.placed_triangles()
            .map(|(corners, _)| corners)
            .collect()
    }

    /// World-space corners of the flattened triangles only (the world-space BVH's input).
    pub fn flat_positions(&self) -> Vec<[Vec3; 3]> {
        self.triangles
            .iter()
            .map(|t| t.indices.map(|i| self.vertices[i as usize].position))
            .collect()
    }

    /// The first perspective camera, if any.
    pub fn default_camera(&self) -> Option<&Camera> {
        self.cameras.first()
    }

    /// What escaping rays see, as one equirectangular map: the loaded environment map, else the
    /// analytic sky baked into one (so both take the same importance-sampled path), else none.
    pub fn environment_map(&self) -> Option<std::borrow::Cow<'_, EnvironmentMap>> {
        match &self.environment {
            Some(m) => Some(std::borrow::Cow::Borrowed(m)),
            None if !self.sky.is_black() => {
                Some(std::borrow::Cow::Owned(EnvironmentMap::from_sky(&self.sky)))
            }
            None => None,
        }
    }

    /// Whether anything in the scene emits light: a punctual light or an emissive material that
    /// a triangle uses (an emissive texture only modulates the factor, so a zero factor is dark).
    pub fn has_lights(&self) -> bool {
        if !self.punctual_lights.is_empty() {
            return true;
        }
        let emissive: Vec<bool> = self
            .materials
            .iter()
            .map(|m| m.emissive.max_element() > 0.0)
            .collect();
        let mut used = self
            .instancing
            .meshes
            .iter()
            .flat_map(|m| &m.triangles)
            .chain(&self.triangles);
        used.any(|t| emissive.get(t.material as usize).copied().unwrap_or(false))
    }

    /// A camera that frames the whole scene (see [`Camera::framing`]); `None` for an empty scene.
    pub fn framing_camera(&self, yfov: f32, aspect: f32) -> Option<Camera> {
        let bounds = self.bounds();
        (!bounds.is_empty()).then(|| Camera::framing(&bounds, yfov, aspect))
    }
}

/// The direction the framing camera looks from, seen from the bounds' centre: in front (+Z, the
/// side glTF models face), 30° to the right and 20° above, so that a room's floor and two walls
/// show rather than one flat wall.
const FRAMING_AZIMUTH_DEG: f32 = 30.0;
const FRAMING_ELEVATION_DEG: f32 = 20.0;
/// Extra distance so the bounding sphere does not touch the image's edge.
const FRAMING_MARGIN: f32 = 1.05;

impl Camera {
    /// A camera at `position` looking at `target` with +Y up (+Z when the view is vertical),
    /// vertical FOV `yfov` (radians). `position` ≠ `target`.
    pub fn look_at(position: Vec3, target: Vec3, yfov: f32, name: &str) -> Camera {
        let forward = (target - position).normalize();
        let up = if forward.cross(Vec3::Y).length_squared() < 1e-6 {
            Vec3::Z
        } else {
            Vec3::Y
        };
        let view_from_world = Mat4::look_at_rh(position, target, up);
        let distance = (target - position).length();
        Camera {
            world_from_view: view_from_world.inverse(),
            yfov,
            aspect: None,
            znear: (distance * 1e-3).max(1e-5),
            name: name.to_owned(),
        }
    }

    /// A camera that sees all of `bounds`: it looks at the centre from the front-right diagonal
    /// ([`FRAMING_AZIMUTH_DEG`], [`FRAMING_ELEVATION_DEG`]) at the distance where the bounding
    /// sphere fits the narrower of the vertical FOV `yfov` and the horizontal one that `aspect`
    /// (width / height) gives, with a 5 % margin. Every point of the bounds then projects inside
    /// the image.
    pub fn framing(bounds: &Aabb, yfov: f32, aspect: f32) -> Camera {
        let centre = bounds.center();
        let radius = bounds.bounding_sphere_radius().max(1e-3);
        let tan_y = (yfov * 0.5).tan();
        let half = tan_y.min(tan_y * aspect).atan();
        let distance = FRAMING_MARGIN * radius / half.sin();
        let (az, el) = (
            FRAMING_AZIMUTH_DEG.to_radians(),
            FRAMING_ELEVATION_DEG.to_radians(),
        );
        let from = Vec3::new(az.sin() * el.cos(), el.sin(), az.cos() * el.cos());
        Camera::look_at(
            centre + from * distance,
            centre,
            yfov,
            "default (frames the scene)",
        )
    }
}

#[cfg(test)]
mod load_safety_tests;
#[cfg(test)]
mod load_tests;
