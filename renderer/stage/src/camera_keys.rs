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
/// The look-at point must be this far from the eye (relative to the coordinates' size, since
/// f32 resolves no finer) for the pair to give a view direction.
pub const MIN_VIEW_DISTANCE: f32 = 1e-5;

/// The file cut before each line that opens an array-of-tables header (`[[key]]`), each piece
/// with its first line's number (from 1). Only such headers may follow the first one in a valid
/// file (every value is a number or an array of numbers), so each piece parses as the file would.
fn key_tables(text: &str) -> impl Iterator<Item = (usize, &str)> {
    let mut lines = text.split_inclusive('\n').peekable();
    let (mut offset, mut line) = (0, 1);
    std::iter::from_fn(move || {
        let (start, start_line) = (offset, line);
        while let Some(next) = lines.peek() {
            if offset > start && next.trim_start().starts_with("[[") {
                break;
            }
            offset += next.len();
            line += 1;
            lines.next();
        }
        (offset > start).then(|| (start_line, &text[start..offset]))
    })
}

/// `look - position` gives a direction at f32 precision.
fn has_view(position: Vec3, look: Vec3) -> bool {
    let scale = position
        .abs()
        .max_element()
        .max(look.abs().max_element())
        .max(1.0);
    let d = position.distance(look);
    d.is_finite() && d >= MIN_VIEW_DISTANCE * scale
}

/// The most bytes of one `[[key]]` table, and of the text before the first (a key takes about
/// 100). Each table is parsed on its own, so the TOML parser's memory (up to 75 × what it parses)
/// is bounded by this rather than by the file: a 64 MiB file of tiny values parsed whole took 5 GB.
pub const MAX_KEY_TABLE_BYTES: usize = 64 << 10;
/// The largest camera path file (400 000 keys written by a tool take about 45 MB).
pub const MAX_FILE_BYTES: u64 = 64 << 20;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct KeysFile {
    #[serde(default)]
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
        let text = fovea_hal::file::read_text(path, MAX_FILE_BYTES, "a camera path")
            .with_context(|| format!("reading camera path {}", path.display()))?;
        let mut entries = Vec::new();
        let mut tables = key_tables(&text).peekable();
        while let Some((line, table)) = tables.next() {
            if table.len() > MAX_KEY_TABLE_BYTES {
                bail!(
                    "{}: invalid camera path at line {line}: {} bytes before the next [[key]], at most {MAX_KEY_TABLE_BYTES} (a key takes about 100)",
                    path.display(),
                    table.len()
                );
            }
            let file: KeysFile = toml::from_str(table).map_err(|e| {
                let offset = e.span().map_or(0, |s| s.start.min(table.len()));
                let at = line
                    + table.as_bytes()[..offset]
                        .iter()
                        .filter(|&&b| b == b'\n')
                        .count();
                anyhow::anyhow!(
                    "{}: invalid camera path at line {at}: {}",
                    path.display(),
                    e.message().trim_end()
                )
            })?;
            if line == 1
                && tables.peek().is_some()
                && !file.key.is_empty()
                && !table.trim_start().starts_with("[[")
            {
                bail!(
                    "{}: invalid camera path: `key` is given as an array before [[key]] tables (use one form)",
                    path.display()
                );
            }
            entries.extend(file.key);
            if entries.len() > MAX_KEYS {
                bail!("{}: more than {MAX_KEYS} keys", path.display());
            }
        }
        let keys = entries
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
            if !has_view(k.position, k.look) {
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

    /// Position, look-at point and FOV at `time` seconds. The spline is evaluated in f64 (keys
    /// 1e300 s apart made its tangents 0 × ∞ = NaN in f32: a black frame); where the position
    /// comes within [`MIN_VIEW_DISTANCE`] of the look-at point (the two splines cross), the view
    /// direction is the keys' directions blended, so every frame has one.
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
        let h = t1 - t0;
        let s = ((time - t0) / h).clamp(0.0, 1.0);
        let tangent = |j: usize, value: fn(&Key) -> Vec3| {
            let (a, b) = (j.saturating_sub(1), (j + 1).min(last));
            (value(&k[b]).as_dvec3() - value(&k[a]).as_dvec3()) / (k[b].time - k[a].time)
        };
        let hermite = |value: fn(&Key) -> Vec3| {
            let (s2, s3) = (s * s, s * s * s);
            let v = value(&k[i]).as_dvec3() * (2.0 * s3 - 3.0 * s2 + 1.0)
                + tangent(i, value) * h * (s3 - 2.0 * s2 + s)
                + value(&k[i + 1]).as_dvec3() * (-2.0 * s3 + 3.0 * s2)
                + tangent(i + 1, value) * h * (s3 - s2);
            v.as_vec3()
        };
        let position = hermite(|key| key.position);
        let mut look = hermite(|key| key.look);
        if !has_view(position, look) {
            let dir = |key: &Key| (key.look - key.position).normalize();
            let (a, b) = (dir(&k[i]), dir(&k[i + 1]));
            let blend = a.lerp(b, s as f32);
            let direction = if blend.length() > 1e-3 {
                blend.normalize()
            } else {
                a
            };
            look = position + direction * position.abs().max_element().max(1.0);
        }
        let s = s as f32;
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

    /// Each key valid, but the eye passes through the (still) look-at point half-way: the
    /// frame there had no view direction (NaN pose, a black frame).
    #[test]
    fn a_path_through_its_look_at_point_keeps_a_view_direction() {
        let keys = [-1.0f32, 1.0].map(|x| Key {
            time: (x as f64 + 1.0) * 0.5,
            position: Vec3::new(x, 0.0, 0.0),
            look: Vec3::ZERO,
            fov: None,
        });
        let path = CameraKeys::new(keys.to_vec()).unwrap();
        let start = CameraPose {
            world_from_view: glam::Mat4::IDENTITY,
            fov_tan: Vec4::new(-1.0, 1.0, -1.0, 1.0),
        };
        for step in 0..=100 {
            let key = path.at(step as f64 / 100.0);
            assert!(
                has_view(key.position, key.look),
                "t {}: {key:?}",
                step as f64 / 100.0
            );
            let pose = path.pose(key.time, &start);
            assert!(pose.world_from_view.is_finite(), "t {}: {pose:?}", key.time);
        }
    }

    /// Keys 1e300 s apart: the f32 tangents were 0 × ∞ = NaN.
    #[test]
    fn keys_far_apart_in_time_interpolate_finitely() {
        let path = CameraKeys::new(vec![key(0.0, 0.0), key(1e300, 4.0), key(2e300, 0.0)]).unwrap();
        for t in [0.5, 1e3, 1e299, 1.5e300] {
            let k = path.at(t);
            assert!(k.position.is_finite() && k.look.is_finite(), "t {t}: {k:?}");
            assert!(has_view(k.position, k.look), "t {t}: {k:?}");
        }
        assert!((path.at(1e300).position.x - 4.0).abs() < 1e-4);
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

    /// Each `[[key]]` table is parsed alone: errors still give the line in the file, the inline
    /// form still loads, a table past the size limit is refused before it is parsed.
    #[test]
    fn tables_are_parsed_one_at_a_time_with_file_lines() {
        let dir = std::env::temp_dir().join(format!("fovea-camera-tables-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let write = |name: &str, text: &str| {
            let path = dir.join(name);
            std::fs::write(&path, text).unwrap();
            path
        };
        let table =
            |t: u32| format!("[[key]]\ntime = {t}\nposition = [0, 1, 2]\nlook = [0, 0, 0]\n");
        let text = format!(
            "# a path\n{}{}[[key]]\ntime = 2\nposition = [0, 1]\n",
            table(0),
            table(1)
        );
        let err = format!(
            "{:#}",
            CameraKeys::load(&write("lines.toml", &text)).unwrap_err()
        );
        assert!(
            err.contains("lines.toml: invalid camera path at line 12"),
            "{err}"
        );
        let inline = "key = [{ time = 0, position = [0, 1, 2], look = [0, 0, 0] }]\n";
        let path = CameraKeys::load(&write("inline.toml", inline)).unwrap();
        assert_eq!(path.keys().len(), 1);
        let both = format!("{inline}{}", table(1));
        let err = format!(
            "{:#}",
            CameraKeys::load(&write("both.toml", &both)).unwrap_err()
        );
        assert!(err.contains("one form"), "{err}");
        let huge = format!(
            "{}{}# {}\n",
            table(0),
            table(1),
            "x".repeat(MAX_KEY_TABLE_BYTES)
        );
        let err = format!(
            "{:#}",
            CameraKeys::load(&write("huge.toml", &huge)).unwrap_err()
        );
        assert!(
            err.contains("huge.toml: invalid camera path at line 5")
                && err.contains("at most 65536"),
            "{err}"
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
