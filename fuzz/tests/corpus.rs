//! The fuzz targets on stable Rust, in every test run: each target gets every file of its
//! committed corpus (`fuzz/corpus/<target>/`, seeds and what libFuzzer runs added), then random
//! mutations of them for `FOVEA_FUZZ_SECONDS` seconds (default 6; nine targets, about a minute of
//! CPU in all). A panic fails the test, names the target and saves the input under
//! `target/fuzz-failures/` so it can be replayed and added to the corpus. Coverage-guided runs:
//! `scripts/fuzz` (libFuzzer).

use rand::{Rng, SeedableRng};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

fn corpus(target: &str) -> Vec<(PathBuf, Vec<u8>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("corpus")
        .join(target);
    let mut files: Vec<(PathBuf, Vec<u8>)> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("corpus {}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .map(|p| {
            let bytes = std::fs::read(&p).unwrap();
            (p, bytes)
        })
        .collect();
    files.sort();
    assert!(!files.is_empty(), "corpus {} is empty", dir.display());
    files
}

/// Values that break readers: numbers at and past the limits, special floats, long runs.
const INTERESTING: &[&[u8]] = &[
    b"0",
    b"-1",
    b"1e39",
    b"1e300",
    b"-1e300",
    b"NaN",
    b"inf",
    b"-inf",
    b"4294967295",
    b"18446744073709551615",
    b"9223372036854775807",
    b"100000",
    b"1e-30",
    b"-0",
    b"\xff\xff\xff\xff",
    b"\x00\x00\x00\x00",
    b"\x7f\xff\xff\xff",
    b"\x00\x00\x80\x7f",
    b"[[key]]",
    b"\"",
    b"{",
    b"[",
];

/// One to eight edits of `seed`: bit flips, random bytes, insertions, deletions, duplicated
/// ranges, interesting values, splices with `other`.
fn mutate(rng: &mut impl Rng, seed: &[u8], other: &[u8]) -> Vec<u8> {
    let mut data = seed.to_vec();
    for _ in 0..rng.random_range(1..=8) {
        let len = data.len();
        let at = if len == 0 {
            0
        } else {
            rng.random_range(0..len)
        };
        match rng.random_range(0..7) {
            0 if len > 0 => data[at] ^= 1 << rng.random_range(0..8),
            1 if len > 0 => data[at] = rng.random(),
            2 => {
                let n = rng.random_range(1..=16);
                let bytes: Vec<u8> = (0..n).map(|_| rng.random()).collect();
                data.splice(at..at, bytes);
            }
            3 if len > 0 => {
                let end = (at + rng.random_range(1..=64)).min(len);
                data.drain(at..end);
            }
            4 if len > 0 => {
                let end = (at + rng.random_range(1..=256)).min(len);
                let copy = data[at..end].to_vec();
                let to = rng.random_range(0..=len);
                data.splice(to..to, copy);
            }
            5 => {
                let value = INTERESTING[rng.random_range(0..INTERESTING.len())];
                // Over a number where there is one (text formats), else inserted.
                let end = data[at..]
                    .iter()
                    .position(|c| !(c.is_ascii_digit() || b".-+eE".contains(c)))
                    .map_or(len, |n| at + n);
                data.splice(at..end.max(at), value.iter().copied());
            }
            _ if !other.is_empty() => {
                let from = rng.random_range(0..other.len());
                let end = (from + rng.random_range(1..=512)).min(other.len());
                data.truncate(at);
                data.extend_from_slice(&other[from..end]);
            }
            _ => {}
        }
    }
    data
}

fn failure(target: &str, data: &[u8]) -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/fuzz-failures");
    std::fs::create_dir_all(&dir).unwrap();
    let hash = data.iter().fold(0xcbf29ce484222325u64, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x100000001b3)
    });
    let path = dir.join(format!("{target}-{hash:016x}.bin"));
    std::fs::write(&path, data).unwrap();
    path
}

fn run(target: &str, f: fn(&[u8])) {
    let call = |data: &[u8], what: &str| {
        if std::panic::catch_unwind(|| f(data)).is_err() {
            panic!(
                "fuzz target {target} panicked on {what}; input saved as {}",
                failure(target, data).display()
            );
        }
    };
    let seeds = corpus(target);
    for (path, bytes) in &seeds {
        call(bytes, &path.display().to_string());
    }
    let seconds = std::env::var("FOVEA_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .unwrap_or(6.0);
    let until = Instant::now() + Duration::from_secs_f64(seconds);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(target.len() as u64 * 7919 + 1);
    let mut runs = 0u64;
    while Instant::now() < until {
        let seed = &seeds[rng.random_range(0..seeds.len())].1;
        let other = &seeds[rng.random_range(0..seeds.len())].1;
        let data = mutate(&mut rng, seed, other);
        call(&data, &format!("mutation {runs}"));
        runs += 1;
    }
    eprintln!(
        "fuzz target {target}: {} corpus files, {runs} mutations",
        seeds.len()
    );
}

fn target(name: &str) -> fn(&[u8]) {
    fovea_fuzz::TARGETS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, f)| *f)
        .unwrap()
}

#[test]
fn gltf() {
    run("gltf", target("gltf"));
}

#[test]
fn trace() {
    run("trace", target("trace"));
}

#[test]
fn headset() {
    run("headset", target("headset"));
}

#[test]
fn render_profile() {
    run("render_profile", target("render_profile"));
}

#[test]
fn camera_path() {
    run("camera_path", target("camera_path"));
}

#[test]
fn baseline_manifest() {
    run("baseline_manifest", target("baseline_manifest"));
}

#[test]
fn png() {
    run("png", target("png"));
}

#[test]
fn exr() {
    run("exr", target("exr"));
}

#[test]
fn hdr() {
    run("hdr", target("hdr"));
}

#[test]
fn every_target_has_a_test_and_a_libfuzzer_binary() {
    let bins = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz_targets");
    for (name, _) in fovea_fuzz::TARGETS {
        assert!(
            bins.join(format!("{name}.rs")).is_file(),
            "fuzz_targets/{name}.rs"
        );
        corpus(name);
    }
}
