pub mod bench;
mod bench_counters;
pub mod bench_headsets;
mod bench_loop;
mod bench_rays;
pub mod bench_vp;
pub mod debug_views;
pub mod eval;
pub mod flags;
pub mod gaze_eval;
pub mod gen_scene;
pub mod headsets;
pub mod info;
pub mod method_table;
pub mod methods;
pub mod overview;
pub mod perceptual_report;
pub mod quality;
mod quality_stereo;
pub mod reference;
pub mod render;
pub mod render_args;
pub mod replay;
pub mod setup;
pub mod view;
pub mod xr;
mod xr_report;

use anyhow::{Context as _, Result};
use fovea_renderer::traversal::TraversalChoice;
use fovea_renderer::vk::{Context, ContextOptions, DeviceSelector};
use std::sync::Arc;

/// The BVH traversal every device this process opens runs (`--traversal`; auto unless chosen).
static TRAVERSAL: std::sync::OnceLock<TraversalChoice> = std::sync::OnceLock::new();

/// Sets the process's `--traversal` (the first call wins: a command chooses once).
pub fn choose_traversal(choice: TraversalChoice) {
    let _ = TRAVERSAL.set(choice);
}

/// Opens the Vulkan device. Validation is on in debug builds and with `--validation`.
pub fn open_device(device: Option<&str>, validation: bool) -> Result<Arc<Context>> {
    Context::new(&device_options(device, validation)).context("opening the Vulkan device")
}

/// The device options every command starts from (the viewer adds its window's extensions).
pub fn device_options(device: Option<&str>, validation: bool) -> ContextOptions {
    ContextOptions {
        validation: validation || cfg!(debug_assertions),
        device: device
            .map(|d| d.parse::<DeviceSelector>().expect("infallible"))
            .unwrap_or_default(),
        traversal: TRAVERSAL.get().copied().unwrap_or_default(),
        ..Default::default()
    }
}

/// Fails the run if the validation layer reported any warning or error.
pub fn check_validation(ctx: &Context) -> Result<()> {
    let problems = ctx.validation.problems();
    if problems > 0 {
        anyhow::bail!(
            "{problems} Vulkan validation warning(s)/error(s): {:?}",
            ctx.validation.messages()
        );
    }
    Ok(())
}
