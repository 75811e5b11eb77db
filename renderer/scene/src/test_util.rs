//! Shared test helpers: a seeded RNG (no dependency needed for tests) and test meshes.

use glam::Vec3;
use std::path::PathBuf;

/// SplitMix64: tiny, seeded, good enough for test inputs.
pub struct TestRng(u64);

impl TestRng {
    pub fn new(seed: u64) -> Self {
        TestRng(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f32()
    }
    pub fn vec3(&mut self, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
    }
    pub fn unit_vector(&mut self) -> Vec3 {
        loop {
            let v = self.vec3(-1.0, 1.0);
            if v.length_squared() > 1e-4 && v.length_squared() <= 1.0 {
                return v.normalize();
            }
        }
    }
}

/// UV sphere of radius `r` around `c`.
pub fn sphere(c: Vec3, r: f32, rings: u32, segments: u32) -> Vec<[Vec3; 3]> {
    let p = |i: u32, j: u32| {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        let phi = std::f32::consts::TAU * j as f32 / segments as f32;
        c + r * Vec3::new(
            theta.sin() * phi.cos(),
            theta.cos(),
            theta.sin() * phi.sin(),
        )
    };
    let mut tris = Vec::new();
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, cc, d) = (p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
            tris.push([a, b, cc]);
            tris.push([a, cc, d]);
        }
    }
    tris
}

pub fn triangle_soup(rng: &mut TestRng, count: usize, extent: f32, size: f32) -> Vec<[Vec3; 3]> {
    (0..count)
        .map(|_| {
            let c = rng.vec3(-extent, extent);
            [
                c + rng.vec3(-size, size),
                c + rng.vec3(-size, size),
                c + rng.vec3(-size, size),
            ]
        })
        .collect()
}

/// Long, thin triangles (width 1e-4 to 1e-2 of their length).
pub fn slivers(rng: &mut TestRng, count: usize) -> Vec<[Vec3; 3]> {
    (0..count)
        .map(|_| {
            let a = rng.vec3(-1.0, 1.0);
            let b = a + rng.unit_vector() * 2.0;
            let width = 2e-4 * 100f32.powf(rng.f32());
            [a, b, b + rng.unit_vector() * width]
        })
        .collect()
}

/// An n×n grid of unit quads (two triangles each) in the plane z = 0 covering [0, n]², with
/// alternating diagonals so rays through grid vertices meet 4–8 triangles.
pub fn quad_grid(n: u32) -> Vec<[Vec3; 3]> {
    let mut tris = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let p = |dx: u32, dy: u32| Vec3::new((x + dx) as f32, (y + dy) as f32, 0.0);
            if (x + y) % 2 == 0 {
                tris.push([p(0, 0), p(1, 0), p(1, 1)]);
                tris.push([p(0, 0), p(1, 1), p(0, 1)]);
            } else {
                tris.push([p(0, 0), p(1, 0), p(0, 1)]);
                tris.push([p(1, 0), p(1, 1), p(0, 1)]);
            }
        }
    }
    tris
}

/// The shared Stanford bunny (ASCII PLY), or None when it is absent and not required (the rule of
/// `fovea_test_kit::data::shared_data`).
pub fn bunny() -> Option<Vec<[Vec3; 3]>> {
    let path = fovea_test_kit::data::shared_data("bunny.ply")?;
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    let mut lines = text.lines();
    let (mut vertex_count, mut face_count) = (0usize, 0usize);
    for line in lines.by_ref() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["element", "vertex", n] => vertex_count = n.parse().expect("bunny.ply: vertex count"),
            ["element", "face", n] => face_count = n.parse().expect("bunny.ply: face count"),
            ["end_header"] => break,
            _ => {}
        }
    }
    let vertices: Vec<Vec3> = lines
        .by_ref()
        .take(vertex_count)
        .map(|l| {
            let v: Vec<f32> = l
                .split_whitespace()
                .take(3)
                .filter_map(|w| w.parse().ok())
                .collect();
            Vec3::new(v[0], v[1], v[2])
        })
        .collect();
    let tris = lines
        .take(face_count)
        .map(|l| {
            let idx: Vec<usize> = l
                .split_whitespace()
                .skip(1)
                .take(3)
                .filter_map(|w| w.parse().ok())
                .collect();
            [vertices[idx[0]], vertices[idx[1]], vertices[idx[2]]]
        })
        .collect();
    Some(tris)
}

/// Standard base64 (for data URIs in hand-written test glTF files).
pub fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// A fresh temporary directory per test (removed at the start, so reruns are clean).
pub fn temp_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fovea-scene-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create temp dir");
    dir
}
