//! `fovea view` in a real window: an Xvfb display (installed by scripts/setup), lavapipe,
//! validation on (the binary fails on any message). Its `--frames N --screenshot` image, copied
//! from the presented swapchain image, must equal `fovea render`'s frame N − 1 of the same camera,
//! gaze and settings (threshold: every channel within 1 of 255, documented in docs/guide/view.md;
//! on lavapipe the images are byte-identical).

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

struct Xvfb {
    child: Child,
    display: String,
}

impl Xvfb {
    /// A server on a display number nobody else holds: the number whose lock file names this
    /// server's own process (parallel tests and test runs may pick the same free number at once;
    /// the loser's server exits and it tries the next one).
    fn start() -> Xvfb {
        for number in 90..190 {
            if Path::new(&format!("/tmp/.X{number}-lock")).exists() {
                continue;
            }
            let mut child = Command::new("Xvfb")
                .args([
                    &format!(":{number}"),
                    "-screen",
                    "0",
                    "800x600x24",
                    "-nolisten",
                    "tcp",
                ])
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .expect("Xvfb (scripts/setup installs it: apt-get install xvfb)");
            let socket = PathBuf::from(format!("/tmp/.X11-unix/X{number}"));
            let pid = child.id();
            let ours = || {
                std::fs::read_to_string(format!("/tmp/.X{number}-lock"))
                    .is_ok_and(|text| text.trim().parse::<u32>() == Ok(pid))
            };
            let start = Instant::now();
            loop {
                if matches!(child.try_wait(), Ok(Some(_))) {
                    break; // another server holds this number
                }
                if socket.exists() && ours() {
                    return Xvfb {
                        child,
                        display: format!(":{number}"),
                    };
                }
                assert!(
                    start.elapsed() < Duration::from_secs(20),
                    "Xvfb :{number} did not start"
                );
                std::thread::sleep(Duration::from_millis(50));
            }
        }
        panic!("no free X display number in 90..190")
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn fovea(args: &[&str], display: Option<&str>) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_fovea"));
    cmd.args(args).arg("--validation");
    match display {
        Some(d) => cmd.env("DISPLAY", d).env_remove("WAYLAND_DISPLAY"),
        None => cmd.env_remove("DISPLAY"),
    };
    let out = cmd.output().expect("running fovea");
    assert!(
        out.status.success(),
        "fovea {args:?} failed:\n{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

fn rgba(path: &Path) -> image::RgbaImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgba8()
}

fn check_screenshot_matches_render(name: &str, extra: &[&str]) {
    let x = Xvfb::start();
    let dir = std::env::temp_dir().join(format!("fovea-view-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let shot = dir.join("shot.png");
    let render_out = dir.join("render");
    let common = [
        "--width", "80", "--height", "90", "--frames", "30", "--gaze", "sim:2", "--seed", "3",
    ];
    let view_args: Vec<&str> = ["view"]
        .iter()
        .chain(&common)
        .chain(extra)
        .copied()
        .chain(["--screenshot", shot.to_str().unwrap()])
        .collect();
    fovea(&view_args, Some(&x.display));
    let render_args: Vec<&str> = ["render"]
        .iter()
        .chain(&common)
        .chain(extra)
        .copied()
        .chain(["--out", render_out.to_str().unwrap()])
        .collect();
    fovea(&render_args, None);
    let shot = rgba(&shot);
    let stereo = extra.contains(&"both");
    let eyes: Vec<String> = if stereo {
        vec!["frame_0029_left.png".into(), "frame_0029_right.png".into()]
    } else {
        vec!["frame_0029.png".into()]
    };
    assert_eq!(shot.dimensions(), (80 * eyes.len() as u32, 90));
    for (i, file) in eyes.iter().enumerate() {
        let expected = rgba(&render_out.join(file));
        let mut worst = 0u8;
        for (x, y, p) in expected.enumerate_pixels() {
            let q = shot.get_pixel(x + 80 * i as u32, y);
            for c in 0..3 {
                worst = worst.max(p[c].abs_diff(q[c]));
            }
        }
        assert!(
            worst <= 1,
            "{name}: the window's {file} differs from fovea render's by up to {worst}/255"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn view_screenshot_matches_the_offline_render() {
    check_screenshot_matches_render("mono", &["--denoiser", "svgf"]);
}

#[test]
fn view_screenshot_of_both_eyes_matches_the_offline_stereo_render() {
    check_screenshot_matches_render("stereo", &["--eyes", "both", "--taa", "screen"]);
}

/// The debug views in the window: the density view of frame N − 1 equals `fovea render
/// --debug-views`' density picture of that frame byte for byte; the grid and rings views show
/// something else than the frame (stereo for the rings: both eyes get them); stereo-diff shows
/// each eye's binocular heat map, measured on most of the Cornell box's pixels.
#[test]
fn debug_views_in_the_window() {
    let x = Xvfb::start();
    let dir = std::env::temp_dir().join(format!("fovea-view-debug-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let common = [
        "--width", "80", "--height", "90", "--frames", "4", "--gaze", "sim:2",
    ];
    let shot = |view: &str, extra: &[&str]| {
        let path = dir.join(format!("{view}.png"));
        let args: Vec<&str> = ["view"]
            .iter()
            .chain(&common)
            .chain(extra)
            .copied()
            .chain(["--debug-view", view, "--screenshot", path.to_str().unwrap()])
            .collect();
        fovea(&args, Some(&x.display));
        rgba(&path)
    };
    let render_out = dir.join("render");
    let render_args: Vec<&str> = ["render"]
        .iter()
        .chain(&common)
        .copied()
        .chain(["--debug-views", "--out", render_out.to_str().unwrap()])
        .collect();
    fovea(&render_args, None);
    assert_eq!(
        shot("density", &[]),
        rgba(&render_out.join("debug_density_0003.png")),
        "the window's density view is render's"
    );
    let frame = rgba(&render_out.join("frame_0003.png"));
    let grid = shot("grid", &[]);
    assert_eq!(grid.dimensions(), (80, 90));
    assert_ne!(grid, frame, "the grid view is not the screen image");
    let rings = shot("rings", &["--eyes", "both"]);
    assert_eq!(rings.dimensions(), (160, 90));
    let white = |x0: u32| {
        (0..90)
            .flat_map(|y| (x0..x0 + 80).map(move |x| (x, y)))
            .filter(|&(x, y)| rings.get_pixel(x, y).0 == [255, 255, 255, 255])
            .count()
    };
    assert!(
        white(0) > 50 && white(80) > 50,
        "rings drawn in both eyes: {} and {} white pixels",
        white(0),
        white(80)
    );
    let diff = shot("stereo-diff", &["--eyes", "both", "--denoiser", "svgf"]);
    assert_eq!(diff.dimensions(), (160, 90));
    // Black: seen by one eye only (the walls near each eye's outer edge, occlusions).
    let measured = |x0: u32| {
        (0..90)
            .flat_map(|y| (x0..x0 + 80).map(move |x| (x, y)))
            .filter(|&(x, y)| diff.get_pixel(x, y).0 != [0, 0, 0, 255])
            .count()
    };
    assert!(
        measured(0) > 80 * 90 * 7 / 10 && measured(80) > 80 * 90 * 7 / 10,
        "heat maps cover most of both eyes: {} and {} pixels",
        measured(0),
        measured(80)
    );
}
