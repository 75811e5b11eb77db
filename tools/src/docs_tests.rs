//! The documentation against the product: docs/cli.md is what the command-line definitions
//! generate, every `fovea …` command line in the README and docs/ parses, every relative link,
//! picture and anchor there resolves, and the product describes the software as it is (no
//! development narrative). A unit-test module of the binary, so it reaches the private `Cli`
//! without moving the definitions out of main.rs.

use clap::error::ErrorKind;
use clap::Parser;
use fovea_tools::cli::Cli;
use pulldown_cmark::{CodeBlockKind, Event, Options, Parser as Markdown, Tag, TagEnd};
use regex::Regex;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Regenerates docs/cli.md when set (to anything): the test then writes instead of comparing.
const UPDATE_VAR: &str = "FOVEA_UPDATE_CLI_DOCS";

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tools/ has a parent")
        .to_path_buf()
}

fn relative(path: &Path) -> String {
    path.strip_prefix(repo())
        .unwrap_or(path)
        .display()
        .to_string()
}

/// Every file under `dir` (recursively) that `keep` accepts, sorted; hidden folders and build
/// output are skipped.
fn files_under(dir: &Path, keep: &dyn Fn(&Path) -> bool) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            let name = entry.file_name().to_string_lossy().into_owned();
            if name.starts_with('.') || name == "target" {
                continue;
            }
            match entry.file_type() {
                Ok(t) if t.is_dir() => stack.push(path),
                Ok(t) if t.is_file() && keep(&path) => out.push(path),
                _ => {}
            }
        }
    }
    out.sort();
    out
}

fn has_ext(path: &Path, exts: &[&str]) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| exts.contains(&e))
}

/// The Markdown the user reads: README.md, hal/README.md, CHANGELOG.md and docs/**/*.md.
fn markdown_files() -> Vec<PathBuf> {
    let root = repo();
    let mut files = vec![
        root.join("README.md"),
        root.join("hal/README.md"),
        root.join("CHANGELOG.md"),
    ];
    files.extend(files_under(&root.join("docs"), &|p| has_ext(p, &["md"])));
    files
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", relative(path)))
}

/// 1-based line of byte `offset` in `text`.
fn line_of(text: &str, offset: usize) -> usize {
    text[..offset].matches('\n').count() + 1
}

fn markdown(text: &str) -> impl Iterator<Item = (Event<'_>, std::ops::Range<usize>)> {
    Markdown::new_ext(text, Options::ENABLE_TABLES).into_offset_iter()
}

// ---- docs/cli.md -------------------------------------------------------------------------------

/// docs/cli.md as the command-line definitions write it.
fn cli_reference() -> String {
    let options = clap_markdown::MarkdownOptions::new()
        .title("Command-line reference: `fovea`".to_string())
        .show_footer(false);
    let body = clap_markdown::help_markdown_custom::<Cli>(&options);
    format!(
        "<!-- Generated from tools/src/cli/mod.rs by clap-markdown; do not edit. Regenerate with\n     \
         {UPDATE_VAR}=1 cargo test -p fovea-tools --bin fovea cli_reference -->\n\n{}\n",
        body.trim_end()
    )
}

#[test]
fn cli_reference_is_what_the_definitions_generate() {
    let path = repo().join("docs/cli.md");
    let generated = cli_reference();
    if std::env::var_os(UPDATE_VAR).is_some() {
        std::fs::write(&path, &generated).unwrap();
        eprintln!("wrote {}", relative(&path));
        return;
    }
    let on_disk = std::fs::read_to_string(&path).unwrap_or_default();
    if on_disk != generated {
        let first = on_disk
            .lines()
            .zip(generated.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| on_disk.lines().count().min(generated.lines().count()));
        panic!(
            "docs/cli.md differs from the command-line definitions (first at line {}: {:?} \
             against {:?}); regenerate it with\n  {UPDATE_VAR}=1 cargo test -p fovea-tools --bin \
             fovea cli_reference",
            first + 1,
            on_disk.lines().nth(first).unwrap_or("<end of file>"),
            generated.lines().nth(first).unwrap_or("<end of file>"),
        );
    }
}

// ---- command lines ------------------------------------------------------------------------------

/// A `fovea …` command shown in Markdown: its line, its words, and whether it is a whole command
/// line (a code block's) or a mention in prose (inline code, which may name a command or a flag
/// without the arguments it requires).
type Shown = (usize, Vec<String>, bool);

/// The `fovea …` commands of one Markdown text: each line of a shell code block (continuation
/// backslashes joined, a `$ ` prompt, `#` comments and other commands around `&&` or `;`
/// dropped) and each inline code span that is one.
fn command_lines(text: &str) -> Vec<Shown> {
    let mut out = Vec::new();
    // (line of the block's first content line, its text) while inside a shell code block.
    let mut block: Option<(usize, String)> = None;
    for (event, range) in markdown(text) {
        match event {
            Event::Start(Tag::CodeBlock(kind)) => {
                let at = line_of(text, range.start);
                block = match &kind {
                    CodeBlockKind::Fenced(lang) if lang.is_empty() || lang.as_ref() == "sh" => {
                        Some((at + 1, String::new()))
                    }
                    CodeBlockKind::Indented => Some((at, String::new())),
                    CodeBlockKind::Fenced(_) => None,
                };
            }
            Event::Text(t) => {
                if let Some((_, code)) = block.as_mut() {
                    code.push_str(&t);
                }
            }
            Event::End(TagEnd::CodeBlock) => {
                let Some((first, code)) = block.take() else {
                    continue;
                };
                let mut joined = String::new();
                let mut start = None;
                for (i, l) in code.split('\n').enumerate() {
                    let at = *start.get_or_insert(first + i);
                    if let Some(head) = l.strip_suffix('\\') {
                        joined.push_str(head);
                        joined.push(' ');
                        continue;
                    }
                    joined.push_str(l);
                    out.extend(commands_in(&joined).into_iter().map(|c| (at, c, true)));
                    joined.clear();
                    start = None;
                }
            }
            Event::Code(code) => {
                let c = code.trim();
                if c == "fovea" || c.starts_with("fovea ") {
                    let words = shlex::split(c).unwrap_or_else(|| vec![c.to_string()]);
                    out.push((line_of(text, range.start), words, false));
                }
            }
            _ => {}
        }
    }
    out
}

/// The `fovea` commands of one shell line.
fn commands_in(line: &str) -> Vec<Vec<String>> {
    let line = line.trim().trim_start_matches("$ ");
    let mut out = Vec::new();
    for part in line.split("&&").flat_map(|p| p.split(';')) {
        let Some(words) = shlex::split(part.trim()) else {
            continue;
        };
        let words: Vec<String> = words
            .into_iter()
            .take_while(|w| !w.starts_with('#'))
            .collect();
        let is_fovea = words
            .first()
            .is_some_and(|w| w == "fovea" || w.ends_with("/fovea"));
        if is_fovea {
            let mut words = words;
            words[0] = "fovea".to_string();
            out.push(words);
        }
    }
    out
}

#[test]
fn every_fovea_command_line_in_the_docs_parses() {
    let mut failures = Vec::new();
    let mut checked = 0;
    for file in markdown_files() {
        // The changelog quotes history; cli.md is the definitions' own usage lines.
        if file.ends_with("CHANGELOG.md") || file.ends_with("docs/cli.md") {
            continue;
        }
        for (line, words, whole) in command_lines(&read(&file)) {
            checked += 1;
            let Err(e) = Cli::try_parse_from(&words) else {
                continue;
            };
            // A mention may leave out required arguments, or end on the flag it names.
            let mention_ok = !whole
                && (e.kind() == ErrorKind::MissingRequiredArgument
                    || (e.kind() == ErrorKind::InvalidValue
                        && words.last().is_some_and(|w| w.starts_with("--"))));
            if !mention_ok {
                let first = e.to_string().lines().next().unwrap_or("").to_string();
                failures.push(format!(
                    "{}:{line}: `{}`: {first}",
                    relative(&file),
                    words.join(" ")
                ));
            }
        }
    }
    assert!(
        checked > 50,
        "only {checked} command lines found: is the extraction broken?"
    );
    assert!(
        failures.is_empty(),
        "{} of {checked} command lines do not parse:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn command_lines_are_found_in_code_blocks_and_inline_code() {
    let text = "Run `fovea render --frames 2`.\n\n```sh\n$ fovea bench --scenes a \\\n    --frames 3  # comment\ncargo build && target/release/fovea info\n```\n\n```\nfovea view\n```\n\n```rust\nfovea not a command\n```\n";
    let found: Vec<(usize, String, bool)> = command_lines(text)
        .into_iter()
        .map(|(l, w, whole)| (l, w.join(" "), whole))
        .collect();
    assert_eq!(
        found,
        [
            (1, "fovea render --frames 2".to_string(), false),
            (4, "fovea bench --scenes a --frames 3".to_string(), true),
            (6, "fovea info".to_string(), true),
            (10, "fovea view".to_string(), true),
        ]
    );
    assert!(Cli::try_parse_from(["fovea", "render", "--frames", "N"]).is_err());
}

// ---- links --------------------------------------------------------------------------------------

/// GitHub's anchor for a heading: lower case, letters, digits, `-` and `_` kept, spaces to `-`,
/// everything else dropped; repeats get `-1`, `-2`, …
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// The anchors of a Markdown text's headings (and of explicit `id`/`name` attributes).
fn anchors(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    let mut heading: Option<String> = None;
    let html_id = Regex::new(r#"(?:id|name)\s*=\s*"([^"]+)""#).unwrap();
    for (event, _) in markdown(text) {
        match event {
            Event::Start(Tag::Heading { .. }) => heading = Some(String::new()),
            Event::Text(t) | Event::Code(t) if heading.is_some() => {
                heading.as_mut().unwrap().push_str(&t)
            }
            Event::End(TagEnd::Heading(_)) => {
                let base = slug(&heading.take().unwrap_or_default());
                let n = seen.entry(base.clone()).or_insert(0);
                out.insert(if *n == 0 {
                    base.clone()
                } else {
                    format!("{base}-{n}")
                });
                *n += 1;
            }
            Event::Html(h) | Event::InlineHtml(h) => {
                out.extend(html_id.captures_iter(&h).map(|c| c[1].to_string()))
            }
            _ => {}
        }
    }
    out
}

/// The relative links and pictures of a Markdown text (Markdown and HTML), with their lines.
fn links(text: &str) -> Vec<(usize, String)> {
    let html_link = Regex::new(r#"(?:src|href)\s*=\s*"([^"]+)""#).unwrap();
    let mut out = Vec::new();
    for (event, range) in markdown(text) {
        let line = line_of(text, range.start);
        match event {
            Event::Start(Tag::Link { dest_url, .. })
            | Event::Start(Tag::Image { dest_url, .. }) => out.push((line, dest_url.to_string())),
            Event::Html(h) | Event::InlineHtml(h) => out.extend(
                html_link
                    .captures_iter(&h)
                    .map(|c| (line, c[1].to_string())),
            ),
            _ => {}
        }
    }
    let scheme = Regex::new(r"^[A-Za-z][A-Za-z0-9+.-]*:").unwrap();
    out.retain(|(_, url)| !scheme.is_match(url));
    out
}

#[test]
fn every_relative_link_picture_and_anchor_resolves() {
    let root = repo().canonicalize().unwrap();
    let mut anchor_cache: BTreeMap<PathBuf, BTreeSet<String>> = BTreeMap::new();
    let mut failures = Vec::new();
    let mut checked = 0;
    for file in markdown_files() {
        let text = read(&file);
        for (line, url) in links(&text) {
            checked += 1;
            let at = format!("{}:{line}: {url}", relative(&file));
            let (path, anchor) = match url.split_once('#') {
                Some((p, a)) => (p, Some(a)),
                None => (url.as_str(), None),
            };
            let target = if path.is_empty() {
                file.clone()
            } else {
                file.parent().unwrap().join(path)
            };
            let Ok(target) = target.canonicalize() else {
                failures.push(format!("{at}: no such file"));
                continue;
            };
            if !target.starts_with(&root) {
                failures.push(format!("{at}: outside the repository"));
                continue;
            }
            let Some(anchor) = anchor else { continue };
            if !has_ext(&target, &["md"]) {
                failures.push(format!("{at}: an anchor into a file that is not Markdown"));
                continue;
            }
            let known = anchor_cache
                .entry(target.clone())
                .or_insert_with(|| anchors(&read(&target)));
            if !known.contains(anchor) {
                failures.push(format!("{at}: no heading with that anchor"));
            }
        }
    }
    assert!(
        checked > 100,
        "only {checked} links found: is the extraction broken?"
    );
    assert!(
        failures.is_empty(),
        "{} of {checked} links do not resolve:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn links_and_anchors_are_read_as_github_does() {
    assert_eq!(slug("One frame: fovea eval"), "one-frame-fovea-eval");
    assert_eq!(slug("The two ρ axes"), "the-two-ρ-axes");
    assert_eq!(slug("report.json"), "reportjson");
    let text = "# A b\n## A b\n### `fovea render`\n<a name=\"x\"></a>\n";
    let expected: BTreeSet<String> = ["a-b", "a-b-1", "fovea-render", "x"]
        .map(String::from)
        .into();
    assert_eq!(anchors(text), expected);
    let text = "[a](b.md#c) ![p](i.png) <img src=\"j.png\"> [w](https://x.org) [h](#top)\n";
    let found: Vec<String> = links(text).into_iter().map(|(_, u)| u).collect();
    assert_eq!(found, ["b.md#c", "i.png", "j.png", "#top"]);
}

// ---- wording ------------------------------------------------------------------------------------

/// Development narrative: the product describes the software as it is. Each pattern is
/// case-insensitive; `markdown_only` ones are checked in Markdown alone (in code "this session"
/// is an OpenXR session).
const NARRATIVE: &[(&str, bool)] = &[
    (r"\bissues? #?\d+", false),
    (
        r"\b(first|second|third|fourth|fifth|sixth|seventh|eighth|ninth|tenth|eleventh|twelfth|thirteenth|fourteenth|fifteenth|sixteenth|seventeenth|eighteenth|nineteenth|twentieth|\d+(st|nd|rd|th))[\s/–-]+sessions?\b",
        false,
    ),
    (r"\bsessions? \d+\b", false),
    (r"\bsession's (machine|code|figures?|runs?)\b", false),
    (
        r"\b(this|that|an earlier|a later|the previous|the next|the last|the same) session\b",
        true,
    ),
    (r"\brounds? of (work|development|review)\b", false),
    (
        r"\b(first|second|third|fourth|fifth|sixth|seventh|eighth|ninth|tenth|next|last|previous) round\b",
        false,
    ),
    (r"\bno longer\b", false),
    (r"\banymore\b", false),
    (r"\b(was|were|has been|have been|newly) added\b", false),
    (r"\bold code\b", false),
    (r"\b(is|are|was|were|has|have|had|does|do|did) now\b", false),
    (
        r"\bnow (uses?|runs?|comes?|goes|go|takes?|reads?|writes?|holds?|skips?|lives?|traces?|counts?|works?|meets?|passes|builds?|built|supports?|refuses?|has|have|is|are|also|only|the default)\b",
        false,
    ),
    (r"\b(and|until|since|from) now([^(\w]|$)", false),
];

/// "used to" that narrates ("X used to render black"), not the passive ("is used to label").
fn narrative_used_to(line: &str) -> bool {
    let passive = [
        "is", "are", "be", "been", "being", "was", "were", "only", "also", "get", "gets", "got",
        "not",
    ];
    let lower = line.to_lowercase();
    let words: Vec<&str> = lower
        .split(|c: char| !c.is_alphanumeric() && c != '\'')
        .filter(|w| !w.is_empty())
        .collect();
    words
        .windows(3)
        .any(|w| w[1] == "used" && w[2] == "to" && !passive.contains(&w[0]))
}

/// The product's text: README, hal/README, docs/ but the dated records under docs/bench and
/// docs/methods (the CHANGELOG holds the history), and the sources, scripts, shaders and
/// configuration (code, comments, CLI help, error messages).
fn product_files() -> Vec<PathBuf> {
    let root = repo();
    let mut files = vec![root.join("README.md"), root.join("hal/README.md")];
    files.extend(files_under(&root.join("docs"), &|p| {
        has_ext(p, &["md"])
            && !p.starts_with(root.join("docs/bench"))
            && !p.starts_with(root.join("docs/methods"))
    }));
    let this = Path::new(file!()).file_name().unwrap().to_owned();
    for dir in [
        "renderer", "tools", "hal", "shaders", "tests", "scripts", "config",
    ] {
        files.extend(files_under(&root.join(dir), &|p| {
            let script = p.starts_with(root.join("scripts")) && p.extension().is_none();
            (script || has_ext(p, &["rs", "glsl", "comp", "toml", "sh", "py", "txt", "md"]))
                && p.file_name() != Some(this.as_os_str())
                && !p.starts_with(root.join("tests/replay"))
                && !p.starts_with(root.join("tests/data"))
        }));
    }
    files.sort();
    files.dedup();
    files
}

#[test]
fn the_product_describes_the_software_as_it_is() {
    let patterns: Vec<(Regex, bool)> = NARRATIVE
        .iter()
        .map(|(p, md)| (Regex::new(&format!("(?i){p}")).unwrap(), *md))
        .collect();
    let mut failures = Vec::new();
    let files = product_files();
    assert!(
        files.len() > 200,
        "only {} files: is the walk broken?",
        files.len()
    );
    for file in &files {
        let Ok(text) = std::fs::read_to_string(file) else {
            continue;
        };
        let is_md = has_ext(file, &["md"]);
        for (i, line) in text.lines().enumerate() {
            let mut found: Vec<String> = patterns
                .iter()
                .filter(|(_, md)| is_md || !md)
                .filter_map(|(re, _)| re.find(line).map(|m| m.as_str().to_string()))
                .collect();
            if narrative_used_to(line) {
                found.push("used to".to_string());
            }
            if !found.is_empty() {
                failures.push(format!(
                    "{}:{}: {:?}: {}",
                    relative(file),
                    i + 1,
                    found,
                    line.trim()
                ));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "development narrative in the product (say what the software is and does; figures carry \
         their command, device and date; history goes in CHANGELOG.md):\n{}",
        failures.join("\n")
    );
}

#[test]
fn narrative_is_told_from_description() {
    let narrative = |line: &str| {
        NARRATIVE
            .iter()
            .any(|(p, _)| Regex::new(&format!("(?i){p}")).unwrap().is_match(line))
            || narrative_used_to(line)
    };
    for line in [
        "Write issue 14's method table",
        "measured in the eighth session",
        "(tenth/eleventh session)",
        "this session's machine",
        "They used to render black",
        "it is no longer traced",
        "the kernel now reads the cameras through a column index",
        "the default is now the SBVH",
    ] {
        assert!(narrative(line), "{line}");
    }
    for line in [
        "`file` is only used to label errors",
        "the runtime's clock now",
        "frame {frame} is not held: its slot holds a later frame",
        "SessionOwner::vulkan(&rt, binding)",
        "the slot comes round again",
        "interleaved, five rounds",
    ] {
        assert!(!narrative(line), "{line}");
    }
}
