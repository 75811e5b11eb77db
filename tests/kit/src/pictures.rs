//! Picture comparisons that leave their evidence behind (wgpu's habit): when one fails, the actual
//! picture, the expected one and their FLIP difference (NVIDIA's implementation, magma colours)
//! are written to `target/test-failures/<test binary>.<test>/<label>/`, and the failure message
//! names that folder. HDR pictures are also written as EXR, with their exact values.

use std::fmt::Display;
use std::path::{Path, PathBuf};

/// FLIP's default viewing condition: a 0.7 m wide 4K monitor seen from 0.7 m.
const FLIP_PPD: f32 = 67.02064;

/// The texels of a picture, row-major.
#[derive(Clone, Copy)]
pub enum Texels<'a> {
    /// Linear RGBA floats (shown through a clamp and the sRGB curve).
    Hdr(&'a [[f32; 4]]),
    /// sRGB bytes, RGBA.
    Rgba8(&'a [u8]),
}

/// A picture to compare: its size and texels.
#[derive(Clone, Copy)]
pub struct Picture<'a> {
    pub width: u32,
    pub height: u32,
    pub texels: Texels<'a>,
}

impl<'a> Picture<'a> {
    pub fn hdr(width: u32, height: u32, texels: &'a [[f32; 4]]) -> Self {
        assert_eq!(texels.len(), (width * height) as usize, "HDR picture size");
        Picture {
            width,
            height,
            texels: Texels::Hdr(texels),
        }
    }

    pub fn rgba8(width: u32, height: u32, bytes: &'a [u8]) -> Self {
        assert_eq!(
            bytes.len(),
            (width * height * 4) as usize,
            "RGBA8 picture size"
        );
        Picture {
            width,
            height,
            texels: Texels::Rgba8(bytes),
        }
    }

    /// The picture as displayed (sRGB bytes).
    pub fn to_rgba8(&self) -> Vec<u8> {
        match self.texels {
            Texels::Rgba8(bytes) => bytes.to_vec(),
            Texels::Hdr(texels) => texels
                .iter()
                .flat_map(|p| {
                    let srgb = |c: f32| {
                        let c = if c.is_finite() {
                            c.clamp(0.0, 1.0)
                        } else {
                            1.0
                        };
                        let v = if c <= 0.0031308 {
                            12.92 * c
                        } else {
                            1.055 * c.powf(1.0 / 2.4) - 0.055
                        };
                        (v * 255.0 + 0.5) as u8
                    };
                    [srgb(p[0]), srgb(p[1]), srgb(p[2]), 255]
                })
                .collect(),
        }
    }

    /// Texels that differ in any bit.
    pub fn differing_texels(&self, other: &Picture) -> usize {
        match (self.texels, other.texels) {
            (Texels::Hdr(a), Texels::Hdr(b)) => a
                .iter()
                .zip(b)
                .filter(|(x, y)| x.map(f32::to_bits) != y.map(f32::to_bits))
                .count(),
            (Texels::Rgba8(a), Texels::Rgba8(b)) => a
                .chunks_exact(4)
                .zip(b.chunks_exact(4))
                .filter(|(x, y)| x != y)
                .count(),
            _ => panic!("comparing an HDR picture with an RGBA8 one"),
        }
    }
}

/// `target/test-failures/<test binary>.<test>/<label>` (emptied): where a failing comparison of
/// the running test leaves its pictures.
pub fn failure_dir(label: &str) -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| crate::data::repo_root().join("target"));
    let dir = target
        .join("test-failures")
        .join(test_name())
        .join(sanitize(label));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("creating {}: {e}", dir.display()));
    dir
}

/// `<test binary>.<test path>`: libtest runs each test on a thread named after it.
fn test_name() -> String {
    let binary = std::env::current_exe()
        .ok()
        .and_then(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .map(|stem| match stem.rsplit_once('-') {
            // cargo's `name-<16 hex digits>`
            Some((name, hash))
                if hash.len() == 16 && hash.chars().all(|c| c.is_ascii_hexdigit()) =>
            {
                name.to_string()
            }
            _ => stem,
        })
        .unwrap_or_else(|| "test".into());
    let test = std::thread::current()
        .name()
        .unwrap_or("unnamed")
        .replace("::", ".");
    sanitize(&format!("{binary}.{test}"))
}

fn sanitize(name: &str) -> String {
    name.chars()
        .map(|c| match c {
            'a'..='z' | 'A'..='Z' | '0'..='9' | '.' | '-' | '_' => c,
            _ => '_',
        })
        .collect()
}

/// Writes `actual.png`, `expected.png` and `flip.png` (and, for HDR pictures, `actual.exr` and
/// `expected.exr`) into [`failure_dir`]`(label)`; returns the folder and the mean FLIP.
pub fn save_failure(label: &str, actual: &Picture, expected: &Picture) -> (PathBuf, f64) {
    let dir = failure_dir(label);
    let (a, e) = (actual.to_rgba8(), expected.to_rgba8());
    write_png(&dir.join("actual.png"), actual.width, actual.height, &a);
    write_png(
        &dir.join("expected.png"),
        expected.width,
        expected.height,
        &e,
    );
    for (name, p) in [("actual.exr", actual), ("expected.exr", expected)] {
        if let Texels::Hdr(texels) = p.texels {
            let w = p.width as usize;
            exr::prelude::write_rgba_file(dir.join(name), w, p.height as usize, |x, y| {
                let t = texels[y * w + x];
                (t[0], t[1], t[2], t[3])
            })
            .unwrap_or_else(|e| panic!("writing {}: {e}", dir.join(name).display()));
        }
    }
    let mut mean_flip = f64::NAN;
    if (actual.width, actual.height) == (expected.width, expected.height) {
        let (w, h) = (actual.width, actual.height);
        let rgb = |rgba: &[u8]| {
            rgba.chunks_exact(4)
                .flat_map(|p| [p[0], p[1], p[2]])
                .collect::<Vec<u8>>()
        };
        let map = nv_flip::flip(
            nv_flip::FlipImageRgb8::with_data(w, h, &rgb(&e)),
            nv_flip::FlipImageRgb8::with_data(w, h, &rgb(&a)),
            FLIP_PPD,
        );
        let values = map.to_vec();
        mean_flip = values.iter().map(|&v| v as f64).sum::<f64>() / values.len().max(1) as f64;
        let coloured = map.apply_color_lut(&nv_flip::magma_lut()).to_vec();
        let rgba: Vec<u8> = coloured
            .chunks_exact(3)
            .flat_map(|p| [p[0], p[1], p[2], 255])
            .collect();
        write_png(&dir.join("flip.png"), w, h, &rgba);
    }
    (dir, mean_flip)
}

fn write_png(path: &Path, width: u32, height: u32, rgba: &[u8]) {
    image::save_buffer(path, rgba, width, height, image::ExtendedColorType::Rgba8)
        .unwrap_or_else(|e| panic!("writing {}: {e}", path.display()));
}

/// When `ok` is false: saves the pictures ([`save_failure`]) and panics with `message`, the folder
/// and the mean FLIP. Returns quietly otherwise.
#[track_caller]
pub fn assert_pictures(
    ok: bool,
    label: &str,
    actual: &Picture,
    expected: &Picture,
    message: impl Display,
) {
    if !ok {
        panic!("{}", failure_message(label, actual, expected, message));
    }
}

/// [`save_failure`]'s pictures and a message naming their folder, for a test that collects its
/// failures and asserts once at the end.
pub fn failure_message(
    label: &str,
    actual: &Picture,
    expected: &Picture,
    message: impl Display,
) -> String {
    let (dir, flip) = save_failure(label, actual, expected);
    format!(
        "{message}\n  actual, expected and FLIP difference (mean {flip:.4}) in {}",
        dir.display()
    )
}

/// Asserts that the two pictures hold the same bits (a failure counts the differing texels and
/// leaves the pictures behind).
#[track_caller]
pub fn assert_pictures_equal(label: &str, actual: &Picture, expected: &Picture) {
    assert_eq!(
        (actual.width, actual.height),
        (expected.width, expected.height),
        "{label}: sizes differ"
    );
    let differing = actual.differing_texels(expected);
    assert_pictures(
        differing == 0,
        label,
        actual,
        expected,
        format_args!("{label}: {differing} texels differ"),
    );
}

/// A 4×4 EXR whose header is rewritten to declare `width` × `height` pixels (the pixel data
/// stays that of the small image): a file that would make a trusting decoder allocate
/// `width × height` pixels before it found the data short.
pub fn exr_declaring(width: i32, height: i32) -> Vec<u8> {
    let mut bytes = std::io::Cursor::new(Vec::new());
    let grey = exr::prelude::SpecificChannels::rgba(|_: exr::prelude::Vec2<usize>| {
        (0.5f32, 0.5f32, 0.5f32, 0.5f32)
    });
    use exr::prelude::WritableImage;
    exr::prelude::Image::from_channels((4, 4), grey)
        .write()
        .to_buffered(&mut bytes)
        .expect("a 4×4 EXR in memory");
    let mut bytes = bytes.into_inner();
    for attribute in [&b"dataWindow\0box2i\0"[..], &b"displayWindow\0box2i\0"[..]] {
        let at = bytes
            .windows(attribute.len())
            .position(|w| w == attribute)
            .expect("the attribute")
            + attribute.len()
            + 4; // the attribute's size
        bytes[at + 8..at + 12].copy_from_slice(&(width - 1).to_le_bytes());
        bytes[at + 12..at + 16].copy_from_slice(&(height - 1).to_le_bytes());
    }
    bytes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_comparison_leaves_its_pictures_and_names_the_folder() {
        let a = vec![[0.25f32, 0.5, 1.0, 1.0]; 12 * 10];
        let mut b = a.clone();
        b[37] = [4.0, 0.0, 0.0, 1.0];
        let (actual, expected) = (Picture::hdr(12, 10, &b), Picture::hdr(12, 10, &a));
        let err = std::panic::catch_unwind(|| {
            assert_pictures_equal("one texel", &actual, &expected);
        })
        .unwrap_err();
        let msg = err.downcast_ref::<String>().unwrap();
        assert!(msg.contains("1 texels differ"), "{msg}");
        let dir = failure_dir_of(msg);
        assert!(
            dir.ends_with("fovea_test_kit.pictures.tests.a_failed_comparison_leaves_its_pictures_and_names_the_folder/one_texel"),
            "{dir:?}"
        );
        for f in [
            "actual.png",
            "expected.png",
            "flip.png",
            "actual.exr",
            "expected.exr",
        ] {
            assert!(dir.join(f).is_file(), "{f} missing in {dir:?}");
        }
        let flip = image::open(dir.join("flip.png")).unwrap().to_rgb8();
        // Magma: black-ish where equal, bright at the changed texel.
        let bright = |x, y| {
            flip.get_pixel(x, y)
                .0
                .iter()
                .map(|&c| c as u32)
                .sum::<u32>()
        };
        assert!(bright(1, 3) > bright(8, 8), "flip shows the difference");
        assert_pictures_equal("same", &expected, &expected);
        let _ = std::fs::remove_dir_all(dir.parent().unwrap());
    }

    fn failure_dir_of(msg: &str) -> PathBuf {
        PathBuf::from(msg.rsplit(" in ").next().unwrap().trim())
    }
}
