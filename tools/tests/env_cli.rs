//! `fovea render --env FILE` end to end through the binary's flags: a tiny EXR written here, seen
//! directly by a free camera that looks away from the Cornell box, with `--env-rotation` turning
//! which half of the map it sees and `--env-intensity` scaling it (linear EXR frames compared
//! exactly: nearest-texel lookups of a two-colour map). A bad map ends the run with its name.

use std::path::{Path, PathBuf};
use std::process::Command;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fovea-env-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn render(map: &Path, rotation: &str, out: &Path) -> std::process::Output {
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes/cornell-box.gltf");
    Command::new(env!("CARGO_BIN_EXE_fovea"))
        .arg("render")
        .arg("--scene")
        .arg(&scene)
        .args([
            "--method",
            "cartesian",
            "--width",
            "64",
            "--height",
            "72",
            "--frames",
            "1",
            "--exr",
            "--validation",
        ])
        // Looking along +X from far outside the box: every camera ray escapes.
        .args([
            "--camera-pos",
            "50,0.5,0",
            "--camera-look",
            "100,0.5,0",
            "--fov",
            "20",
            "--projection",
            "scene-camera",
        ])
        .arg("--env")
        .arg(map)
        .args(["--env-rotation", rotation, "--env-intensity", "3", "--out"])
        .arg(out)
        .output()
        .unwrap()
}

#[test]
fn render_with_an_exr_environment_map() {
    use exr::prelude::*;
    let dir = temp_dir("render");
    let map = dir.join("halves.exr");
    // Columns u < ½ red, u ≥ ½ blue. +X is u = ¾ unrotated (the map's centre, u = ½, faces −Z).
    let channels = SpecificChannels::rgb(|Vec2(x, _y): Vec2<usize>| {
        if x < 8 {
            (2.0f32, 0.0f32, 0.0f32)
        } else {
            (0.0, 0.0, 2.0)
        }
    });
    Image::from_channels((16, 8), channels)
        .write()
        .to_file(&map)
        .unwrap();
    for (rotation, want) in [("0", [0.0, 0.0, 6.0]), ("180", [6.0, 0.0, 0.0])] {
        let out = dir.join(format!("out{rotation}"));
        let result = render(&map, rotation, &out);
        assert!(
            result.status.success(),
            "fovea render failed: {}",
            String::from_utf8_lossy(&result.stderr)
        );
        let (w, h, pixels) = fovea_tools::output::read_exr(&out.join("frame_0000.exr")).unwrap();
        assert_eq!((w, h), (64, 72));
        for p in &pixels {
            assert_eq!(p[..3], want, "rotation {rotation}");
        }
    }
    let bad = dir.join("missing.hdr");
    let result = render(&bad, "0", &dir.join("bad"));
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(
        !result.status.success() && stderr.contains("missing.hdr"),
        "{stderr}"
    );
}
