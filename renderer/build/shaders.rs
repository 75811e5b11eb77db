//! Compiles every `*.comp` under `shaders/` (and the generated layout probes) to SPIR-V and writes
//! `shaders.rs`, a table of (name, bytes) the engine looks pipelines up in.
//!
//! A shader may declare variants with lines `//! variant NAME: DEFINE[=VALUE] …`; each variant is
//! compiled as `path.NAME` with those macros defined. `//! variants per space[ SUFFIX: DEFINES]`
//! stands for one such line per sampling space of `shaders/sampling/spaces.txt` (`NAME: DEFINES`),
//! named `SPACE SUFFIX` with the space's and the line's defines, so a new space is one line there,
//! not one in every kernel. `//! variants per trace space[ SUFFIX: DEFINES]` does the same over the
//! trace kernel's sampling variants of `shaders/sampling/trace_spaces.txt`, `//! variants per
//! gradient trace space SUFFIX: DEFINES` over those of its lines tagged `gradients`, and
//! `//! variants per resampling trace space SUFFIX: DEFINES` over those tagged `resampling`.
//!
//! A kernel that traces rays declares `//! traversals`: each of its variants (or the kernel
//! itself) is compiled a second time with `BVH_TRAVERSAL_GPU`, named with [`GPU_TRAVERSAL_SUFFIX`]
//! (the GPU-shaped BVH traversal of shaders/common/bvh.glsl; the engine picks per device).

use std::fmt::Write;
use std::path::{Path, PathBuf};

/// What the GPU-traversal twin of a kernel variant is named after (`passes/trace.cartesian+gpu`);
/// `fovea_renderer::traversal` looks pipelines up by it.
const GPU_TRAVERSAL_SUFFIX: &str = "+gpu";

/// Macro definitions of one variant: (name, optional value).
type Defines = Vec<(String, Option<String>)>;

/// The lists variant directives expand over.
struct SpaceLists {
    /// `spaces.txt`: the grid addressings of the per-space kernels.
    grid: Vec<(String, Defines)>,
    /// `trace_spaces.txt`: the tracer's sampling variants, and which can trace gradient samples.
    trace: Vec<(String, Defines)>,
    gradient_trace: Vec<(String, Defines)>,
    /// The trace variants of the spaces the resampling passes run in (ReSTIR DI).
    resampling_trace: Vec<(String, Defines)>,
}

fn read_list(root: &Path, file: &str) -> Result<Vec<(String, Vec<String>, Defines)>, String> {
    let path = root.join(file);
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let list: Vec<_> = text
        .lines()
        .filter(|l| !l.trim_start().starts_with('#'))
        .filter_map(|l| {
            let (head, defs) = l.split_once(':')?;
            let mut words = head.split_whitespace();
            let name = words.next()?.to_string();
            Some((
                name,
                words.map(str::to_string).collect(),
                parse_defines(defs),
            ))
        })
        .collect();
    if list.is_empty() {
        return Err(format!("{}: no sampling space listed", path.display()));
    }
    Ok(list)
}

impl SpaceLists {
    fn read(root: &Path) -> Result<SpaceLists, String> {
        let untagged = |list: Vec<(String, Vec<String>, Defines)>| {
            list.into_iter().map(|(n, _, d)| (n, d)).collect::<Vec<_>>()
        };
        let trace = read_list(root, "sampling/trace_spaces.txt")?;
        let tagged = |tag: &str| {
            untagged(
                trace
                    .iter()
                    .filter(|(_, tags, _)| tags.iter().any(|t| t == tag))
                    .cloned()
                    .collect(),
            )
        };
        Ok(SpaceLists {
            grid: untagged(read_list(root, "sampling/spaces.txt")?),
            gradient_trace: tagged("gradients"),
            resampling_trace: tagged("resampling"),
            trace: untagged(trace),
        })
    }
}

pub fn compile_all(
    root: &Path,
    out_dir: &Path,
    generated: &[(String, String)],
) -> Result<(), String> {
    let compiler = shaderc::Compiler::new().map_err(|e| format!("shaderc: {e}"))?;
    let spv_dir = out_dir.join("spv");
    std::fs::create_dir_all(&spv_dir).map_err(|e| e.to_string())?;

    let spaces = SpaceLists::read(root)?;
    let mut jobs: Vec<(String, PathBuf, String, Defines)> = Vec::new();
    for path in find_shaders(root) {
        let source =
            std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let stem = path
            .strip_prefix(root)
            .unwrap()
            .with_extension("")
            .to_string_lossy()
            .replace('\\', "/");
        let mut variants: Vec<(String, Defines)> = parse_variants(&source, &spaces)
            .into_iter()
            .map(|(variant, defines)| (format!("{stem}.{variant}"), defines))
            .collect();
        if variants.is_empty() {
            variants.push((stem, Vec::new()));
        }
        if source.lines().any(|l| l.trim() == "//! traversals") {
            let gpu: Vec<(String, Defines)> = variants
                .iter()
                .map(|(name, defines)| {
                    let mut defines = defines.clone();
                    defines.push(("BVH_TRAVERSAL_GPU".to_string(), None));
                    (format!("{name}{GPU_TRAVERSAL_SUFFIX}"), defines)
                })
                .collect();
            variants.extend(gpu);
        }
        for (name, defines) in variants {
            jobs.push((name, path.clone(), source.clone(), defines));
        }
    }
    for (name, source) in generated {
        jobs.push((
            name.clone(),
            root.join(format!("{name}.comp")),
            source.clone(),
            Vec::new(),
        ));
    }

    let mut errors = String::new();
    let mut table = String::from(
        "// Generated by build.rs. Do not edit.\npub static SHADERS: &[(&str, &[u8])] = &[\n",
    );
    for (name, path, source, defines) in &jobs {
        let options = options(root, defines)?;
        match compiler.compile_into_spirv(
            source,
            shaderc::ShaderKind::Compute,
            &path.to_string_lossy(),
            "main",
            Some(&options),
        ) {
            Ok(artifact) => {
                let file = spv_dir.join(format!("{}.spv", name.replace('/', "__")));
                let words = strip_source_debug(artifact.as_binary());
                let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
                std::fs::write(&file, bytes).map_err(|e| e.to_string())?;
                writeln!(
                    table,
                    "    (\"{name}\", include_bytes!(\"{}\")),",
                    file.display()
                )
                .unwrap();
            }
            Err(e) => writeln!(errors, "shader {name}:\n{e}").unwrap(),
        }
    }
    table.push_str("];\n");
    if !errors.is_empty() {
        return Err(errors);
    }
    std::fs::write(out_dir.join("shaders.rs"), table).map_err(|e| e.to_string())
}

/// Drops the source text and line tables that debug info adds (they bloat the binary and split
/// UTF-8 comments mid-character) while keeping OpName, which binding-by-name needs.
fn strip_source_debug(words: &[u32]) -> Vec<u32> {
    const DROPPED: [u32; 7] = [2, 3, 4, 7, 8, 317, 330]; // OpSourceContinued, OpSource, OpSourceExtension, OpString, OpLine, OpNoLine, OpModuleProcessed
    let mut out = words[..5].to_vec();
    let mut i = 5;
    while i < words.len() {
        let count = (words[i] >> 16) as usize;
        let opcode = words[i] & 0xffff;
        if count == 0 {
            break;
        }
        if !DROPPED.contains(&opcode) {
            out.extend_from_slice(&words[i..(i + count).min(words.len())]);
        }
        i += count;
    }
    out
}

fn options<'a>(
    root: &Path,
    defines: &[(String, Option<String>)],
) -> Result<shaderc::CompileOptions<'a>, String> {
    let mut options =
        shaderc::CompileOptions::new().map_err(|e| format!("shaderc options: {e}"))?;
    options.set_target_env(
        shaderc::TargetEnv::Vulkan,
        shaderc::EnvVersion::Vulkan1_2 as u32,
    );
    options.set_optimization_level(shaderc::OptimizationLevel::Performance);
    options.set_warnings_as_errors();
    // Keeps OpName through the optimiser: the engine binds resources by their GLSL names.
    options.set_generate_debug_info();
    for (k, v) in defines {
        options.add_macro_definition(k, v.as_deref());
    }
    let root = root.to_path_buf();
    options.set_include_callback(move |requested, kind, requester, _depth| {
        // Quoted includes resolve next to the including file first, then from shaders/.
        let mut candidates = Vec::new();
        if kind == shaderc::IncludeType::Relative {
            if let Some(dir) = Path::new(requester).parent() {
                candidates.push(dir.join(requested));
            }
        }
        candidates.push(root.join(requested));
        for candidate in candidates {
            if let Ok(content) = std::fs::read_to_string(&candidate) {
                return Ok(shaderc::ResolvedInclude {
                    resolved_name: candidate.to_string_lossy().into_owned(),
                    content,
                });
            }
        }
        Err(format!("{requester}: cannot find include \"{requested}\""))
    });
    Ok(options)
}

/// The variants a shader declares, `variants per …` lines expanded over their list.
fn parse_variants(source: &str, spaces: &SpaceLists) -> Vec<(String, Defines)> {
    let mut variants = parse_variant_list(
        source
            .lines()
            .filter_map(|l| l.trim().strip_prefix("//! variant ")),
    );
    let directives = [
        ("//! variants per space", &spaces.grid),
        ("//! variants per trace space", &spaces.trace),
        (
            "//! variants per gradient trace space",
            &spaces.gradient_trace,
        ),
        (
            "//! variants per resampling trace space",
            &spaces.resampling_trace,
        ),
    ];
    for (directive, list) in directives {
        for line in source
            .lines()
            .filter_map(|l| l.trim().strip_prefix(directive))
        {
            // A directive ends at a space or a colon, not inside a longer word.
            if !(line.is_empty() || line.starts_with(' ') || line.starts_with(':')) {
                continue;
            }
            let (suffix, extra) = match line.split_once(':') {
                Some((suffix, defs)) => (suffix.trim(), parse_defines(defs)),
                None => (line.trim(), Vec::new()),
            };
            for (space, defines) in list {
                variants.push((
                    format!("{space}{suffix}"),
                    defines.iter().chain(&extra).cloned().collect(),
                ));
            }
        }
    }
    variants
}

fn parse_defines(defs: &str) -> Defines {
    defs.split_whitespace()
        .map(|d| match d.split_once('=') {
            Some((k, v)) => (k.to_string(), Some(v.to_string())),
            None => (d.to_string(), None),
        })
        .collect()
}

/// `NAME: DEFINE[=VALUE] …` lines.
fn parse_variant_list<'a>(lines: impl Iterator<Item = &'a str>) -> Vec<(String, Defines)> {
    lines
        .filter_map(|rest| {
            let (name, defs) = rest.split_once(':')?;
            Some((name.trim().to_string(), parse_defines(defs)))
        })
        .collect()
}

fn find_shaders(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for entry in entries.flatten() {
            let p = entry.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "comp") {
                found.push(p);
            }
        }
    }
    found.sort();
    found
}
