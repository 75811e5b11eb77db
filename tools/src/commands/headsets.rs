//! `fovea headsets`: the headset profiles compiled in from config/headsets/.

use anyhow::Result;
use fovea_hal::{Eye, HmdDescription};

pub fn run() -> Result<()> {
    println!(
        "{:<16} {:<28} {:>11} {:>7} {:>22} {:>9}",
        "name", "display name", "per eye", "refresh", "FOV l/r/d/u (deg)", "tracker"
    );
    for hmd in HmdDescription::list_builtin() {
        let eye = hmd.eye(Eye::Left);
        let f = eye.fov;
        println!(
            "{:<16} {:<28} {:>11} {:>5} Hz {:>22} {:>6} Hz",
            hmd.id,
            hmd.display_name,
            format!("{}×{}", eye.recommended_width, eye.recommended_height),
            hmd.refresh_hz,
            format!(
                "{:.1}/{:.1}/{:.1}/{:.1}",
                f.angle_left.to_degrees(),
                f.angle_right.to_degrees(),
                f.angle_down.to_degrees(),
                f.angle_up.to_degrees()
            ),
            hmd.tracker.rate_hz
        );
    }
    println!("\nUse --headset <name> or --headset path/to/profile.toml (format: hal/README.md).");
    Ok(())
}
