//! Build script: compiles every GLSL compute shader under `shaders/` to SPIR-V with shaderc and
//! generates the Rust side of the GPU struct layouts from `shaders/common/layouts.glsl`, the
//! single source of truth for every struct shared by Rust and GLSL.

#[path = "build/layouts.rs"]
mod layouts;
#[path = "build/shaders.rs"]
mod shaders;

use std::path::PathBuf;
// Brings in the static glslang archives shaderc needs on Debian 12 (see that crate's build.rs).
use fovea_shaderc_link as _;

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap());
    let shader_root = manifest.join("../shaders");
    let out_dir = PathBuf::from(std::env::var("OUT_DIR").unwrap());
    println!("cargo:rerun-if-changed={}", shader_root.display());
    println!("cargo:rerun-if-changed=build");

    let header = shader_root.join("common/layouts.glsl");
    let structs = match layouts::parse(&header) {
        Ok(s) => s,
        Err(e) => panic!("{e}"),
    };
    std::fs::write(out_dir.join("layouts.rs"), layouts::rust_source(&structs)).unwrap();
    let probes = layouts::probe_shaders(&structs);

    if let Err(e) = shaders::compile_all(&shader_root, &out_dir, &probes) {
        // A panic prints the message with file:line from shaderc and fails the build.
        panic!("\n{e}\n");
    }
}
