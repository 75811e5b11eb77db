//! Debian 12's libshaderc_combined.a does not contain glslang and SPIRV-Tools, and its dynamic
//! libshaderc.so has undefined glslang symbols that rust-lld refuses (build-notes.md). Linking the
//! static archives from the same packages (libshaderc-dev, glslang-dev, spirv-tools) works.
//! Directives from a dependency's build script reach every binary that links it, the renderer's
//! build script included, which is why this is a crate of its own.

fn main() {
    let dir = std::env::var("FOVEA_GLSLANG_LIB_DIR")
        .unwrap_or_else(|_| "/usr/lib/x86_64-linux-gnu".into());
    println!("cargo:rerun-if-env-changed=FOVEA_GLSLANG_LIB_DIR");
    println!("cargo:rustc-link-search=native={dir}");
    for lib in [
        "glslang",
        "MachineIndependent",
        "GenericCodeGen",
        "OGLCompiler",
        "OSDependent",
        "SPIRV",
        "SPIRV-Tools-opt",
        "SPIRV-Tools",
    ] {
        if !std::path::Path::new(&dir)
            .join(format!("lib{lib}.a"))
            .exists()
        {
            panic!("{dir}/lib{lib}.a is missing: install libshaderc-dev glslang-dev spirv-tools (see .ci/setup)");
        }
        println!("cargo:rustc-link-lib=static={lib}");
    }
}
