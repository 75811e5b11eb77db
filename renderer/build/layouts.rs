//! Parses `shaders/common/layouts.glsl` (the one source of truth for GPU structs and constants)
//! and generates the matching Rust `#[repr(C)]` structs plus a probe shader per struct that a
//! device test uses to prove every field's std430 offset.
//!
//! Only 4-byte scalars, 2- and 4-component vectors, mat4 and structs declared earlier in the
//! header are allowed: vec3 and implicit padding are rejected so that `#[repr(C)]` and std430
//! cannot disagree silently (a nested struct has its members' largest alignment in both).

use std::fmt::Write;
use std::path::Path;

pub struct Field {
    pub name: String,
    rust: String,
    /// Size in 32-bit words.
    words: usize,
    /// std430 base alignment in bytes.
    align: usize,
    /// Each 32-bit word in memory order: the GLSL accessor appended to the field access, and how
    /// the probe shader turns it into a uint ("f" float, "u" uint, "i" int).
    word_access: Vec<(String, char)>,
}

impl Field {
    fn basic(ty: &FieldType, name: &str) -> Field {
        Field {
            name: name.to_string(),
            rust: ty.rust.to_string(),
            words: ty.words,
            align: ty.align,
            word_access: ty
                .components
                .iter()
                .map(|c| (c.to_string(), ty.scalar))
                .collect(),
        }
    }

    /// A field whose type is an earlier struct: its words are the struct's, in order.
    fn nested(inner: &Struct, name: &str) -> Field {
        let word_access = inner
            .fields
            .iter()
            .flat_map(|f| {
                f.word_access
                    .iter()
                    .map(move |(access, scalar)| (format!(".{}{access}", f.name), *scalar))
            })
            .collect::<Vec<_>>();
        Field {
            name: name.to_string(),
            rust: inner.name.clone(),
            words: word_access.len(),
            align: inner.fields.iter().map(|f| f.align).max().unwrap_or(4),
            word_access,
        }
    }
}

pub struct Struct {
    pub name: String,
    pub fields: Vec<Field>,
}

pub struct Constant {
    pub ty: &'static str,
    pub name: String,
    pub value: String,
}

pub struct Header {
    pub structs: Vec<Struct>,
    pub constants: Vec<Constant>,
}

/// A basic GLSL type: its Rust twin, size in words, std430 alignment in bytes, scalar kind and
/// the accessors of its words.
pub struct FieldType {
    glsl: &'static str,
    rust: &'static str,
    words: usize,
    align: usize,
    scalar: char,
    components: &'static [&'static str],
}

const VEC4: &[&str] = &[".x", ".y", ".z", ".w"];
const MAT4: &[&str] = &[
    "[0].x", "[0].y", "[0].z", "[0].w", "[1].x", "[1].y", "[1].z", "[1].w", "[2].x", "[2].y",
    "[2].z", "[2].w", "[3].x", "[3].y", "[3].z", "[3].w",
];

static TYPES: &[FieldType] = &[
    FieldType {
        glsl: "float",
        rust: "f32",
        words: 1,
        align: 4,
        scalar: 'f',
        components: &[""],
    },
    FieldType {
        glsl: "uint",
        rust: "u32",
        words: 1,
        align: 4,
        scalar: 'u',
        components: &[""],
    },
    FieldType {
        glsl: "int",
        rust: "i32",
        words: 1,
        align: 4,
        scalar: 'i',
        components: &[""],
    },
    FieldType {
        glsl: "vec2",
        rust: "glam::Vec2",
        words: 2,
        align: 8,
        scalar: 'f',
        components: &[".x", ".y"],
    },
    FieldType {
        glsl: "uvec2",
        rust: "glam::UVec2",
        words: 2,
        align: 8,
        scalar: 'u',
        components: &[".x", ".y"],
    },
    FieldType {
        glsl: "ivec2",
        rust: "glam::IVec2",
        words: 2,
        align: 8,
        scalar: 'i',
        components: &[".x", ".y"],
    },
    FieldType {
        glsl: "vec4",
        rust: "glam::Vec4",
        words: 4,
        align: 16,
        scalar: 'f',
        components: VEC4,
    },
    FieldType {
        glsl: "uvec4",
        rust: "glam::UVec4",
        words: 4,
        align: 16,
        scalar: 'u',
        components: VEC4,
    },
    FieldType {
        glsl: "ivec4",
        rust: "glam::IVec4",
        words: 4,
        align: 16,
        scalar: 'i',
        components: VEC4,
    },
    FieldType {
        glsl: "mat4",
        rust: "glam::Mat4",
        words: 16,
        align: 16,
        scalar: 'f',
        components: MAT4,
    },
];

pub fn parse(path: &Path) -> Result<Header, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut structs = Vec::new();
    let mut constants = Vec::new();
    let mut current: Option<Struct> = None;
    for (index, raw) in text.lines().enumerate() {
        let at = || format!("{}:{}", path.display(), index + 1);
        let line = raw.split("//").next().unwrap().trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        if let Some(rest) = line.strip_prefix("struct ") {
            let name = rest.trim_end_matches('{').trim().to_string();
            current = Some(Struct {
                name,
                fields: Vec::new(),
            });
        } else if line == "};" {
            let s = current
                .take()
                .ok_or_else(|| format!("{}: '}};' outside a struct", at()))?;
            check_layout(&s).map_err(|e| format!("{}: struct {}: {e}", at(), s.name))?;
            structs.push(s);
        } else if let Some(rest) = line.strip_prefix("const ") {
            let (decl, value) = rest
                .split_once('=')
                .ok_or_else(|| format!("{}: constant without value", at()))?;
            let mut parts = decl.split_whitespace();
            let (ty, name) = (parts.next().unwrap_or(""), parts.next().unwrap_or(""));
            let ty = match ty {
                "uint" => "u32",
                "int" => "i32",
                "float" => "f32",
                _ => return Err(format!("{}: constant type '{ty}' not supported", at())),
            };
            let value = value
                .trim()
                .trim_end_matches(';')
                .trim()
                .trim_end_matches('u')
                .to_string();
            constants.push(Constant {
                ty,
                name: name.to_string(),
                value,
            });
        } else if let Some(s) = current.as_mut() {
            let decl = line.trim_end_matches(';');
            let mut parts = decl.split_whitespace();
            let (ty, name) = (parts.next().unwrap_or(""), parts.next().unwrap_or(""));
            let field = if let Some(basic) = TYPES.iter().find(|t| t.glsl == ty) {
                Field::basic(basic, name)
            } else if let Some(inner) = structs.iter().find(|st: &&Struct| st.name == ty) {
                Field::nested(inner, name)
            } else {
                return Err(format!(
                    "{}: field type '{ty}' not allowed (use 4-byte scalars, vec2/vec4 kinds, mat4 or a struct declared above; \
                     vec3 breaks std430/repr(C) agreement)",
                    at()
                ));
            };
            s.fields.push(field);
        } else {
            return Err(format!("{}: unexpected line '{line}'", at()));
        }
    }
    Ok(Header { structs, constants })
}

fn check_layout(s: &Struct) -> Result<(), String> {
    let mut offset = 0;
    let mut align = 4;
    for f in &s.fields {
        if offset % f.align != 0 {
            return Err(format!(
                "field {} at byte {offset} needs {}-byte alignment: reorder or pad explicitly",
                f.name, f.align
            ));
        }
        offset += f.words * 4;
        align = align.max(f.align);
    }
    if offset % align != 0 {
        return Err(format!(
            "size {offset} is not a multiple of its alignment {align}: pad explicitly"
        ));
    }
    Ok(())
}

pub fn rust_source(header: &Header) -> String {
    let mut out =
        String::from("// Generated by build.rs from shaders/common/layouts.glsl. Do not edit.\n\n");
    for c in &header.constants {
        writeln!(out, "pub const {}: {} = {};", c.name, c.ty, c.value).unwrap();
    }
    for s in &header.structs {
        writeln!(out, "\n#[repr(C)]\n#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]").unwrap();
        writeln!(out, "pub struct {} {{", s.name).unwrap();
        for f in &s.fields {
            writeln!(out, "    pub {}: {},", f.name, f.rust).unwrap();
        }
        writeln!(out, "}}").unwrap();
    }
    out.push_str(
        "\n/// Every shared struct with each field's Rust offset, for the on-device layout test.\n",
    );
    out.push_str("pub static STRUCT_LAYOUTS: &[StructLayout] = &[\n");
    for s in &header.structs {
        writeln!(
            out,
            "    StructLayout {{ name: \"{0}\", size: core::mem::size_of::<{0}>(), fields: &[",
            s.name
        )
        .unwrap();
        for f in &s.fields {
            writeln!(
                out,
                "        FieldLayout {{ name: \"{}\", offset: core::mem::offset_of!({}, {}), words: {} }},",
                f.name, s.name, f.name, f.words
            )
            .unwrap();
        }
        out.push_str("    ] },\n");
    }
    out.push_str("];\n");
    out
}

/// One compute shader per struct: it reads every word of `src.data` through the GLSL layout and
/// writes them in declaration order, so the test can compare with the Rust offsets.
pub fn probe_shaders(header: &Header) -> Vec<(String, String)> {
    header
        .structs
        .iter()
        .map(|s| {
            let mut body = String::new();
            let mut k = 0;
            for f in &s.fields {
                for (c, scalar) in &f.word_access {
                    let access = format!("src.data.{}{}", f.name, c);
                    let word = match scalar {
                        'f' => format!("floatBitsToUint({access})"),
                        'i' => format!("uint({access})"),
                        _ => access,
                    };
                    writeln!(body, "    dst.words[{k}] = {word};").unwrap();
                    k += 1;
                }
            }
            let source = format!(
                "#version 460\n#include \"common/layouts.glsl\"\nlayout(local_size_x = 1) in;\n\
                 layout(std430, set = 0, binding = 0) readonly buffer Src {{ {name} data; }} src;\n\
                 layout(std430, set = 0, binding = 1) writeonly buffer Dst {{ uint words[]; }} dst;\n\
                 void main() {{\n{body}}}\n",
                name = s.name
            );
            (format!("layout_probe/{}", s.name), source)
        })
        .collect()
}
