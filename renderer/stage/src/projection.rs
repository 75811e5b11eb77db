//! How a rendered eye sees the scene: through its headset's frustum (the default) or through the
//! scene camera's own field of view (`--projection`).
//!
//! With `Projection::Headset` the scene camera (a glTF camera, the framing camera or the free
//! camera) is the viewer's head: its position and orientation place the head, its field of view
//! is not used. Each eye looks through its profile's asymmetric FOV tangents from its offset in
//! the headset, so the gaze, the Visual-Polar eccentricities and `fovea eval`'s rings (all
//! computed through the profile's FOV) describe the very image rendered — what the headset shows.
//! `Projection::SceneCamera` renders the scene camera's symmetric FOV at the output's aspect
//! ratio (pixels square), the eyes of a stereo run offset from it; it serves figures that need
//! the file's framing.

use anyhow::{bail, Result};
use fovea_hal::{Eye, HmdDescription};
use fovea_renderer::frame::CameraPose;
use fovea_renderer::scene::Camera;
use glam::{Mat4, Vec4};

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Projection {
    /// Each eye through the headset profile's frustum and eye offset, the scene camera the head.
    #[default]
    Headset,
    /// The scene camera's symmetric FOV (`--fov` may replace it), eyes offset only in stereo.
    SceneCamera,
}

impl Projection {
    pub const NAMES: &'static [&'static str] = &["headset", "scene-camera"];

    pub fn parse(name: &str) -> Result<Projection> {
        match name {
            "headset" => Ok(Projection::Headset),
            "scene-camera" => Ok(Projection::SceneCamera),
            other => bail!(
                "--projection {other}: expected one of {}",
                Projection::NAMES.join(", ")
            ),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Projection::Headset => "headset",
            Projection::SceneCamera => "scene-camera",
        }
    }
}

/// The tangents of `eye`'s four half-angles as the renderer takes them (left, right, down, up;
/// left and down negative).
pub fn eye_fov_tan(hmd: &HmdDescription, eye: Eye) -> Vec4 {
    let f = &hmd.eye(eye).fov;
    Vec4::new(
        f.angle_left.tan(),
        f.angle_right.tan(),
        f.angle_down.tan(),
        f.angle_up.tan(),
    )
}

/// The symmetric view (vertical FOV in radians, aspect width / height) that fits inside both of
/// `hmd`'s eye frustums: the framing camera placed for it keeps the scene's bounds inside every
/// eye's image.
pub fn inscribed_view(hmd: &HmdDescription) -> (f32, f32) {
    let [l, r, d, u] = [Eye::Left, Eye::Right]
        .map(|eye| eye_fov_tan(hmd, eye).abs())
        .into_iter()
        .reduce(|a, b| a.min(b))
        .expect("two eyes")
        .to_array();
    let (tx, ty) = (l.min(r), d.min(u));
    (2.0 * ty.atan(), tx / ty)
}

/// The view the framing camera fits the scene into (`EyeRig::framing`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Framing {
    /// Vertical FOV in radians; `None`: the framing camera's default.
    pub yfov: Option<f32>,
    /// Width / height.
    pub aspect: f32,
}

impl Framing {
    /// A symmetric view of `aspect` with the default FOV.
    pub fn aspect(aspect: f32) -> Framing {
        Framing { yfov: None, aspect }
    }
}

/// What every command that renders the scene camera needs to turn it into each eye's camera.
#[derive(Clone, Debug)]
pub struct EyeRig {
    pub projection: Projection,
    pub hmd: HmdDescription,
    /// Both eyes rendered (a stereo run offsets the eyes in either projection).
    pub stereo: bool,
    pub width: u32,
    pub height: u32,
    /// Metres per scene unit: the eyes' offsets (metres) in scene units.
    pub metres_per_unit: f32,
}

impl EyeRig {
    /// The view the framing camera fits the scene into.
    pub fn framing(&self) -> Framing {
        match self.projection {
            Projection::Headset => {
                let (yfov, aspect) = inscribed_view(&self.hmd);
                Framing {
                    yfov: Some(yfov),
                    aspect,
                }
            }
            Projection::SceneCamera => Framing::aspect(self.width as f32 / self.height as f32),
        }
    }

    /// The head pose from the chosen camera (its FOV: the scene camera's fitted to the output,
    /// which only `Projection::SceneCamera` uses).
    pub fn head(&self, camera: &Camera) -> CameraPose {
        CameraPose::from_scene_camera(camera, self.width, self.height)
    }

    /// `eye`'s camera for a head at `head` (a pose on the camera path).
    pub fn eye(&self, head: &CameraPose, eye: Eye) -> CameraPose {
        let offset = Mat4::from_translation(self.hmd.eye(eye).offset / self.metres_per_unit);
        match self.projection {
            Projection::Headset => CameraPose {
                world_from_view: head.world_from_view * offset,
                fov_tan: eye_fov_tan(&self.hmd, eye),
            },
            Projection::SceneCamera if self.stereo => CameraPose {
                world_from_view: head.world_from_view * offset,
                fov_tan: head.fov_tan,
            },
            Projection::SceneCamera => *head,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn rig(projection: Projection, stereo: bool) -> EyeRig {
        EyeRig {
            projection,
            hmd: HmdDescription::resolve("psvr2").unwrap(),
            stereo,
            width: 96,
            height: 98,
            metres_per_unit: 1.0,
        }
    }

    #[test]
    fn the_headset_projection_uses_each_eyes_own_asymmetric_frustum_and_offset() {
        let rig = rig(Projection::Headset, false);
        let head = CameraPose {
            world_from_view: Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0)),
            fov_tan: Vec4::new(-0.3, 0.3, -0.3, 0.3),
        };
        for eye in [Eye::Left, Eye::Right] {
            let pose = rig.eye(&head, eye);
            let f = &rig.hmd.eye(eye).fov;
            // PSVR2: 61.5° on the temporal side, 43.5° on the nasal one, 53° up and down.
            let expected = Vec4::new(
                f.angle_left.tan(),
                f.angle_right.tan(),
                f.angle_down.tan(),
                f.angle_up.tan(),
            );
            assert!((pose.fov_tan - expected).abs().max_element() < 1e-6);
            assert!(pose.fov_tan.x.abs() != pose.fov_tan.y.abs(), "asymmetric");
            let position = pose.world_from_view.w_axis.truncate();
            let want = Vec3::new(1.0, 2.0, 3.0) + rig.hmd.eye(eye).offset;
            assert!((position - want).length() < 1e-6, "{eye:?} at {position}");
        }
        let left = rig.eye(&head, Eye::Left).fov_tan;
        assert!(
            (left.x - (-61.5f32).to_radians().tan()).abs() < 1e-3,
            "{left}"
        );
        assert!((left.y - 43.5f32.to_radians().tan()).abs() < 1e-3, "{left}");
    }

    #[test]
    fn the_scene_camera_projection_keeps_the_head_in_mono_and_offsets_stereo_eyes() {
        let head = CameraPose {
            world_from_view: Mat4::IDENTITY,
            fov_tan: Vec4::new(-0.4, 0.4, -0.3, 0.3),
        };
        assert_eq!(
            rig(Projection::SceneCamera, false).eye(&head, Eye::Right),
            head
        );
        let right = rig(Projection::SceneCamera, true).eye(&head, Eye::Right);
        assert_eq!(right.fov_tan, head.fov_tan);
        assert!((right.world_from_view.w_axis.x - 0.0315).abs() < 1e-6);
    }

    #[test]
    fn the_inscribed_view_fits_inside_both_eyes() {
        let hmd = HmdDescription::resolve("psvr2").unwrap();
        let (yfov, aspect) = inscribed_view(&hmd);
        let (ty, tx) = ((yfov / 2.0).tan(), (yfov / 2.0).tan() * aspect);
        for eye in [Eye::Left, Eye::Right] {
            let t = eye_fov_tan(&hmd, eye);
            assert!(tx <= t.y + 1e-6 && tx <= -t.x + 1e-6 && ty <= t.w + 1e-6 && ty <= -t.z + 1e-6);
        }
        // The nasal 43.5° and the vertical 53° bound it.
        assert!((tx - 43.5f32.to_radians().tan()).abs() < 1e-4);
        assert!((ty - 53f32.to_radians().tan()).abs() < 1e-4);
    }

    #[test]
    fn projection_names_round_trip_and_unknown_ones_are_refused() {
        for name in Projection::NAMES {
            assert_eq!(Projection::parse(name).unwrap().name(), *name);
        }
        let err = Projection::parse("fisheye").unwrap_err().to_string();
        assert!(
            err.contains("--projection fisheye") && err.contains("scene-camera"),
            "{err}"
        );
    }
}
