//! Camera paths from a file (`--camera-path FILE.toml`): keyframes of the eye position, the point
//! looked at and optionally the vertical FOV, at times in seconds. Frame i is shown at
//! i / the headset's refresh rate; positions and look-at points follow a cubic Hermite spline
//! with Catmull-Rom tangents (through every key, C¹ at each), the FOV is linear. Before the first key and after the last the
//! camera holds still.
//!
//! ```toml
//! [[key]]
//! time = 0.0
//! position = [0.0, 1.6, 4.0]
//! look = [0.0, 1.2, 0.0]
//! fov = 60.0          # degrees, optional (all keys or none; without: the scene camera's)
//! ```

use anyhow::{bail, Context, Result};
use fovea_renderer::frame::CameraPose;
use fovea_scene::Camera;
use glam::{Vec3, Vec4};
use serde::Deserialize;
use std::path::Path;

/// More keys than this is not a camera path anyone authored by hand or tool (one per frame of an
/// hour at 90 Hz is 324 000): refused before anything is interpolated.
pub const MAX_KEYS: usize = 400_000;
/// Coordinates beyond this lose the centimetre at f32 precision.
const MAX_COORDINATE: f32 = 1e7;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct KeysFile {
    key: Vec<KeyEntry>,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(deny_unknown_fields)]
struct KeyEntry {
    time: f64,
    position: [f32; 3],
    look: [f32; 3],
    fov: Option<f32>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Key {
    pub time: f64,
    pub position: Vec3,
    pub look: Vec3,
    /// Vertical FOV in degrees.
    pub fov: Option<f32>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct CameraKeys {
    keys: Vec<Key>,
}

impl CameraKeys {
    pub fn load(path: &Path) -> Result<CameraKeys> {
        let limit = fovea_hal::file::MAX_PROFILE_BYTES * 64;
        let text = fovea_hal::file::read_text(path, limit, "a camera path")
            .with_context(|| format!("reading camera path {}", path.display()))?;
        let file: KeysFile = toml::from_str(&text)
            .with_context(|| format!("{}: invalid camera path", path.display()))?;
        let keys = file
            .key
            .iter()
            .map(|k| Key {
                time: k.time,
                position: Vec3::from(k.position),
                look: Vec3::from(k.look),
                fov: k.fov,
            })
            .collect();
        CameraKeys::new(keys).with_context(|| path.display().to_string())
    }

    /// Checks the keys: at least one, times finite and increasing, points finite and apart, FOV in
    /// (1°, 170°) on all keys or none.
    pub fn new(keys: Vec<Key>) -> Result<CameraKeys> {
        if keys.is_empty() {
            bail!("a camera path needs at least one [[key]]");
        }
        if keys.len() > MAX_KEYS {
            bail!("{} keys: at most {MAX_KEYS}", keys.len());
        }
        for (i, k) in keys.iter().enumerate() {
            if !(k.time.is_finite() && k.time >= 0.0) {
                bail!("key[{i}].time = {}: must be finite and ≥ 0 seconds", k.time);
            }
            if i > 0 && k.time <= keys[i - 1].time {
                bail!(
                    "key[{i}].time = {} s: must be after key[{}]'s {} s",
                    k.time,
                    i - 1,
                    keys[i - 1].time
                );
            }
            for (field, v) in [("position", k.position), ("look", k.look)] {
                if !(v.is_finite() && v.abs().max_element() <= MAX_COORDINATE) {
                    bail!("key[{i}].{field} = {v}: must be finite and within ±{MAX_COORDINATE:e}");
                }
            }
            if k.position.distance(k.look) < 1e-6 {
                bail!("key[{i}]: position and look are the same point (no view direction)");
            }
            if let Some(fov) = k.fov.filter(|f| !(f.is_finite() && *f > 1.0 && *f < 170.0)) {
                bail!("key[{i}].fov = {fov}: must be in (1, 170) degrees");
            }
            if k.fov.is_some() != keys[0].fov.is_some() {
                bail!(
                    "key[{i}].fov: give fov on every key or on none (key[0] {})",
                    if keys[0].fov.is_some() {
                        "has one"
                    } else {
                        "has none"
                    }
                );
            }
        }
        Ok(CameraKeys { keys })
    }

    /// Position, look-at point and FOV at `time` seconds.
    pub fn at(&self, time: f64) -> Key {
        let k = &self.keys;
        let last = k.len() - 1;
        if time <= k[0].time || last == 0 {
            return Key { time, ..k[0] };
        }
        if time >= k[last].time {
            return Key { time, ..k[last] };
        }
        let i = k.partition_point(|key| key.time <= time) - 1;
        let (t0, t1) = (k[i].time, k[i + 1].time);
        let h = (t1 - t0) as f32;
        let s = ((time - t0) / (t1 - t0)) as f32;
        let tangent = |j: usize, value: fn(&Key) -> Vec3| {
            let (a, b) = (j.saturating_sub(1), (j + 1).min(last));
            (value(&k[b]) - value(&k[a])) / (k[b].time - k[a].time) as f32
        };
        let hermite = |value: fn(&Key) -> Vec3| {
            let (s2, s3) = (s * s, s * s * s);
            value(&k[i]) * (2.0 * s3 - 3.0 * s2 + 1.0)
                + tangent(i, value) * h * (s3 - 2.0 * s2 + s)
                + value(&k[i + 1]) * (-2.0 * s3 + 3.0 * s2)
                + tangent(i + 1, value) * h * (s3 - s2)
        };
        let position = hermite(|key| key.position);
        let mut look = hermite(|key| key.look);
        if position.distance(look) < 1e-6 {
            look = k[i + 1].look; // the spline crossed the eye: keep a view direction
        }
        let fov = k[i].fov.zip(k[i + 1].fov).map(|(a, b)| a + (b - a) * s);
        Key {
            time,
            position,
            look,
            fov,
        }
    }

    /// The camera at `time`: the key's position and look-at point, its FOV when the keys give
    /// one (the aspect ratio of `start`), else `start`'s.
    pub fn pose(&self, time: f64, start: &CameraPose) -> CameraPose {
        let key = self.at(time);
        let fov_tan = match key.fov {
            Some(fov) => {
                let aspect = start.fov_tan.y / start.fov_tan.w;
                let ty = (fov.to_radians() * 0.5).tan();
                Vec4::new(-ty * aspect, ty * aspect, -ty, ty)
            }
            None => start.fov_tan,
        };
        let camera = Camera::look_at(key.position, key.look, 1.0, "camera path");
        CameraPose {
            world_from_view: camera.world_from_view,
            fov_tan,
        }
    }

    pub fn keys(&self) -> &[Key] {
        &self.keys
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(time: f64, x: f32) -> Key {
        Key {
            time,
            position: Vec3::new(x, 0.0, 0.0),
            look: Vec3::new(x, 0.0, -1.0),
            fov: None,
        }
    }

    #[test]
    fn passes_through_every_key_and_holds_outside() {
        let path = CameraKeys::new(vec![
            key(0.0, 0.0),
            key(1.0, 1.0),
            key(3.0, -2.0),
            key(3.5, 4.0),
        ])
        .unwrap();
        for k in path.keys() {
            assert!(path.at(k.time).position.distance(k.position) < 1e-5);
        }
        assert_eq!(path.at(-1.0).position, Vec3::ZERO);
        assert_eq!(path.at(10.0).position, Vec3::new(4.0, 0.0, 0.0));
    }

    #[test]
    fn evenly_timed_collinear_keys_move_at_constant_speed() {
        // Catmull-Rom reproduces linear motion exactly (the tangents are the chords).
        let path = CameraKeys::new(
            (0..5)
                .map(|i| key(i as f64 * 0.5, i as f32 * 2.0))
                .collect(),
        )
        .unwrap();
        for step in 0..=40 {
            let t = step as f64 * 0.05;
            let x = path.at(t).position.x;
            assert!((x - 4.0 * t as f32).abs() < 1e-4, "t {t}: x {x}");
        }
    }

    #[test]
    fn the_motion_is_smooth_through_keys() {
        let path = CameraKeys::new(vec![
            key(0.0, 0.0),
            key(1.0, 3.0),
            key(2.0, 1.0),
            key(4.0, 5.0),
        ])
        .unwrap();
        // Velocity just before and after an interior key agrees (C¹).
        for t in [1.0, 2.0] {
            let e = 1e-3;
            let before = (path.at(t).position - path.at(t - e).position) / e as f32;
            let after = (path.at(t + e).position - path.at(t).position) / e as f32;
            assert!(
                (before - after).length() < 0.05 * before.length().max(1.0),
                "t {t}: {before} vs {after}"
            );
        }
    }

    #[test]
    fn fov_interpolates_and_sets_the_pose_tangents() {
        let mut keys = vec![key(0.0, 0.0), key(2.0, 0.0)];
        (keys[0].fov, keys[1].fov) = (Some(40.0), Some(80.0));
        let path = CameraKeys::new(keys).unwrap();
        assert!((path.at(1.0).fov.unwrap() - 60.0).abs() < 1e-4);
        let start = CameraPose {
            world_from_view: glam::Mat4::IDENTITY,
            fov_tan: Vec4::new(-2.0, 2.0, -1.0, 1.0),
        };
        let pose = path.pose(1.0, &start);
        let ty = 30f32.to_radians().tan();
        assert!((pose.fov_tan - Vec4::new(-2.0 * ty, 2.0 * ty, -ty, ty)).length() < 1e-5);
        // Looking down −Z from the origin: the view matrix is the identity.
        assert!(pose.world_from_view.abs_diff_eq(glam::Mat4::IDENTITY, 1e-5));
    }

    #[test]
    fn bad_keys_are_named() {
        let cases: [(Vec<Key>, &str); 5] = [
            (vec![], "at least one"),
            (vec![key(1.0, 0.0), key(0.5, 1.0)], "key[1].time"),
            (vec![key(f64::NAN, 0.0)], "key[0].time"),
            (
                vec![Key {
                    look: Vec3::ZERO,
                    ..key(0.0, 0.0)
                }],
                "same point",
            ),
            (
                vec![Key {
                    fov: Some(200.0),
                    ..key(0.0, 0.0)
                }],
                "key[0].fov",
            ),
        ];
        for (keys, needle) in cases {
            let err = format!("{:#}", CameraKeys::new(keys).unwrap_err());
            assert!(err.contains(needle), "{needle}: {err}");
        }
        let mixed = vec![
            Key {
                fov: Some(50.0),
                ..key(0.0, 0.0)
            },
            key(1.0, 1.0),
        ];
        assert!(
            format!("{:#}", CameraKeys::new(mixed).unwrap_err()).contains("every key or on none")
        );
    }

    #[test]
    fn files_are_read_strictly_and_errors_name_the_file() {
        let dir = std::env::temp_dir().join(format!("fovea-camera-keys-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let good = dir.join("path.toml");
        std::fs::write(&good, "[[key]]\ntime = 0\nposition = [0, 1, 2]\nlook = [0, 0, 0]\n[[key]]\ntime = 1.5\nposition = [1, 1, 2]\nlook = [0, 0, 0]\n").unwrap();
        let path = CameraKeys::load(&good).unwrap();
        assert_eq!(path.keys().len(), 2);
        assert_eq!(path.keys()[1].position, Vec3::new(1.0, 1.0, 2.0));
        let bad = dir.join("bad.toml");
        std::fs::write(
            &bad,
            "[[key]]\ntime = 0\nposition = [0, 1, 2]\nlook = [0, 0, 0]\nroll = 3\n",
        )
        .unwrap();
        let err = format!("{:#}", CameraKeys::load(&bad).unwrap_err());
        assert!(err.contains("bad.toml") && err.contains("roll"), "{err}");
        let order = dir.join("order.toml");
        std::fs::write(&order, "[[key]]\ntime = 2\nposition = [0, 1, 2]\nlook = [0, 0, 0]\n[[key]]\ntime = 1\nposition = [0, 1, 2]\nlook = [0, 0, 0]\n").unwrap();
        let err = format!("{:#}", CameraKeys::load(&order).unwrap_err());
        assert!(
            err.contains("order.toml") && err.contains("key[1].time"),
            "{err}"
        );
        let missing = format!(
            "{:#}",
            CameraKeys::load(&dir.join("none.toml")).unwrap_err()
        );
        assert!(missing.contains("none.toml"), "{missing}");
    }
}
