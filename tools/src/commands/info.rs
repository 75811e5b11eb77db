//! `fovea info`: Vulkan devices, the one `fovea` would choose, and its limits.

use super::flags::DeviceArgs;
use anyhow::Result;
use fovea_renderer::vk::Context;

pub fn run(device: Option<&str>) -> Result<()> {
    let devices = Context::enumerate()?;
    if devices.is_empty() {
        println!("no Vulkan devices (install mesa-vulkan-drivers for lavapipe)");
    }
    for d in &devices {
        let note = match &d.suitable {
            Ok(()) => String::new(),
            Err(why) => format!("  [unsuitable: {why}]"),
        };
        println!(
            "[{}] {} ({}, Vulkan {}){note}",
            d.index, d.name, d.kind, d.api_version
        );
    }
    let ctx = super::open_device(device, false)?;
    let i = &ctx.info;
    println!("\nchosen: [{}] {}", i.index, i.name);
    println!(
        "  BVH traversal:                     {} (--traversal)",
        ctx.traversal.name()
    );
    println!(
        "  max compute workgroup invocations: {}",
        i.max_compute_workgroup_invocations
    );
    println!(
        "  max storage buffer range:          {} bytes",
        i.max_storage_buffer_range
    );
    println!(
        "  max texel buffer elements:         {}",
        i.max_texel_buffer_elements
    );
    println!(
        "  max 2-D image dimension:           {}",
        i.max_image_dimension_2d
    );
    println!(
        "  max push constants:                {} bytes",
        i.max_push_constants_size
    );
    println!(
        "  timestamp period:                  {} ns",
        i.timestamp_period_ns
    );
    Ok(())
}

// `fovea info` (its help is the variant's in `crate::cli::Command`).
#[derive(clap::Args)]
pub struct InfoCommand {
    #[command(flatten)]
    pub device: DeviceArgs,
}

impl InfoCommand {
    pub fn run(self) -> Result<()> {
        self.device.choose_traversal()?;
        run(self.device.device.as_deref())
    }
}
