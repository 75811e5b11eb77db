//! No import cycles between the modules of the engine (renderer/), the embedding library
//! (renderer/stage/) and the tools (tools/): a type two modules share lives where both can import
//! it. The test reads every source file of the three crates with `syn`, builds the module tree from the `mod` items (`#[path]` included), and draws
//! an edge from a module to the module that defines each name it reaches through a `crate::`,
//! `super::`, `self::` or child-module path — in `use` items, in code and in macro arguments.
//! `pub use` re-exports are followed to the defining module and are no edge themselves (a facade
//! is not a dependency). A cycle is a strongly connected component of that graph.
//!
//! No crate has a cycle. `KNOWN_TOOLS_CYCLES` tolerates a listed tools cycle while it is
//! being broken (and fails on a listed one it cannot find); it is empty.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use syn::visit::Visit;

/// Cycles in tools/ to be broken, each as its modules (sorted). Remove an entry once its cycle
/// is gone: the test fails on a listed cycle it cannot find.
const KNOWN_TOOLS_CYCLES: &[&[&str]] = &[];

/// One module: its place in the tree, the names its `use` items bring in and the paths it uses.
#[derive(Default)]
struct Module {
    name: String,
    parent: Option<usize>,
    children: BTreeMap<String, usize>,
    /// Local name → the path it stands for (as written, relative to this module).
    imports: BTreeMap<String, Vec<String>>,
    /// Paths this module depends on: its private `use` items and the paths in its code.
    uses: Vec<Vec<String>>,
    file: PathBuf,
}

struct Crate {
    modules: Vec<Module>,
}

impl Crate {
    fn load(name: &str, root_file: &Path) -> Crate {
        let mut krate = Crate {
            modules: Vec::new(),
        };
        let dir = root_file.parent().unwrap().to_path_buf();
        krate.load_file(name, None, root_file, &dir);
        krate
    }

    /// Adds the module in `file` (child of `parent`); `dir` is where its `mod x;` items' files
    /// lie.
    fn load_file(&mut self, name: &str, parent: Option<usize>, file: &Path, dir: &Path) -> usize {
        let text = std::fs::read_to_string(file)
            .unwrap_or_else(|e| panic!("reading {}: {e}", file.display()));
        let ast =
            syn::parse_file(&text).unwrap_or_else(|e| panic!("parsing {}: {e}", file.display()));
        self.add_module(name, parent, file, dir, &ast.items)
    }

    fn add_module(
        &mut self,
        name: &str,
        parent: Option<usize>,
        file: &Path,
        dir: &Path,
        items: &[syn::Item],
    ) -> usize {
        let index = self.modules.len();
        self.modules.push(Module {
            name: name.to_string(),
            parent,
            file: file.to_path_buf(),
            ..Default::default()
        });
        if let Some(p) = parent {
            let short = name.rsplit("::").next().unwrap().to_string();
            self.modules[p].children.insert(short, index);
        }
        let mut collector = PathCollector::default();
        for item in items {
            match item {
                syn::Item::Mod(m) => {
                    let child = format!("{name}::{}", m.ident);
                    let child_dir = dir.join(m.ident.to_string());
                    match &m.content {
                        Some((_, inner)) => {
                            self.add_module(&child, Some(index), file, &child_dir, inner);
                        }
                        None => {
                            let (child_file, grandchildren) = module_file(file, dir, m);
                            self.load_file(&child, Some(index), &child_file, &grandchildren);
                        }
                    }
                }
                syn::Item::Use(u) => {
                    let mut leaves = Vec::new();
                    use_leaves(&u.tree, &mut Vec::new(), &mut leaves);
                    let reexport = !matches!(u.vis, syn::Visibility::Inherited);
                    for leaf in leaves {
                        match leaf {
                            UseLeaf::Name(local, path) => {
                                if !reexport {
                                    self.modules[index].uses.push(path.clone());
                                }
                                self.modules[index].imports.insert(local, path);
                            }
                            UseLeaf::Glob(path) => {
                                if !reexport {
                                    self.modules[index].uses.push(path);
                                }
                            }
                        }
                    }
                }
                other => collector.visit_item(other),
            }
        }
        self.modules[index].uses.extend(collector.paths);
        index
    }

    fn find(&self, name: &str) -> Option<usize> {
        self.modules.iter().position(|m| m.name == name)
    }

    /// The module that defines what `path` names, seen from module `from`; `None` outside the
    /// crate (std, other crates) and for local names.
    fn resolve(&self, from: usize, path: &[String], depth: u32) -> Option<usize> {
        if depth > 32 || path.is_empty() {
            return None;
        }
        let m = &self.modules[from];
        let (start, rest) = match path[0].as_str() {
            "crate" => (0, &path[1..]),
            "self" => (from, &path[1..]),
            "super" => {
                let mut cur = from;
                let mut i = 0;
                while path.get(i).is_some_and(|s| s == "super") {
                    cur = self.modules[cur].parent?;
                    i += 1;
                }
                (cur, &path[i..])
            }
            first if m.children.contains_key(first) => (from, path),
            first => {
                let target = m.imports.get(first)?;
                if target.len() == 1 && target[0] == first {
                    return None;
                }
                let full: Vec<String> = target.iter().chain(&path[1..]).cloned().collect();
                return self.resolve(from, &full, depth + 1);
            }
        };
        let mut cur = start;
        for (i, segment) in rest.iter().enumerate() {
            let module = &self.modules[cur];
            if segment == "self" {
                continue;
            }
            if let Some(&child) = module.children.get(segment) {
                cur = child;
            } else if let Some(target) = module.imports.get(segment) {
                let full: Vec<String> = target.iter().chain(&rest[i + 1..]).cloned().collect();
                return self.resolve(cur, &full, depth + 1);
            } else {
                return Some(cur);
            }
        }
        Some(cur)
    }

    /// Module → modules it depends on, each edge with one path that makes it.
    fn edges(&self) -> BTreeMap<usize, BTreeMap<usize, String>> {
        let mut edges: BTreeMap<usize, BTreeMap<usize, String>> = BTreeMap::new();
        for (from, m) in self.modules.iter().enumerate() {
            for path in &m.uses {
                if let Some(to) = self.resolve(from, path, 0).filter(|&to| to != from) {
                    edges
                        .entry(from)
                        .or_default()
                        .entry(to)
                        .or_insert_with(|| path.join("::"));
                }
            }
        }
        edges
    }
}

/// The file of `mod m;` declared in `file`, and the folder of its own `mod` items.
fn module_file(file: &Path, dir: &Path, m: &syn::ItemMod) -> (PathBuf, PathBuf) {
    let name = m.ident.to_string();
    let path_attr = m.attrs.iter().find_map(|a| match &a.meta {
        syn::Meta::NameValue(nv) if nv.path.is_ident("path") => match &nv.value {
            syn::Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Str(s),
                ..
            }) => Some(s.value()),
            _ => None,
        },
        _ => None,
    });
    if let Some(p) = path_attr {
        let child = file.parent().unwrap().join(p);
        let own = child.with_extension("");
        return (child, own);
    }
    let flat = dir.join(format!("{name}.rs"));
    if flat.exists() {
        return (flat, dir.join(&name));
    }
    let nested = dir.join(&name).join("mod.rs");
    assert!(
        nested.exists(),
        "mod {name} in {}: neither {} nor {}",
        file.display(),
        flat.display(),
        nested.display()
    );
    (nested, dir.join(name))
}

enum UseLeaf {
    /// The local name and the path it stands for.
    Name(String, Vec<String>),
    Glob(Vec<String>),
}

fn use_leaves(tree: &syn::UseTree, prefix: &mut Vec<String>, out: &mut Vec<UseLeaf>) {
    match tree {
        syn::UseTree::Path(p) => {
            prefix.push(p.ident.to_string());
            use_leaves(&p.tree, prefix, out);
            prefix.pop();
        }
        syn::UseTree::Name(n) => {
            let name = n.ident.to_string();
            if name == "self" {
                if let Some(last) = prefix.last() {
                    out.push(UseLeaf::Name(last.clone(), prefix.clone()));
                }
            } else {
                let mut path = prefix.clone();
                path.push(name.clone());
                out.push(UseLeaf::Name(name, path));
            }
        }
        syn::UseTree::Rename(r) => {
            let mut path = prefix.clone();
            if r.ident != "self" {
                path.push(r.ident.to_string());
            }
            out.push(UseLeaf::Name(r.rename.to_string(), path));
        }
        syn::UseTree::Glob(_) => out.push(UseLeaf::Glob(prefix.clone())),
        syn::UseTree::Group(g) => {
            for t in &g.items {
                use_leaves(t, prefix, out);
            }
        }
    }
}

/// Every path of two or more segments in an item's code, macro arguments and nested `use`
/// items included; nested modules are modules of their own.
#[derive(Default)]
struct PathCollector {
    paths: Vec<Vec<String>>,
}

impl<'ast> Visit<'ast> for PathCollector {
    fn visit_item_mod(&mut self, _: &'ast syn::ItemMod) {}

    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        let mut leaves = Vec::new();
        use_leaves(&u.tree, &mut Vec::new(), &mut leaves);
        self.paths.extend(leaves.into_iter().map(|l| match l {
            UseLeaf::Name(_, p) | UseLeaf::Glob(p) => p,
        }));
    }

    fn visit_path(&mut self, p: &'ast syn::Path) {
        if p.segments.len() > 1 {
            self.paths
                .push(p.segments.iter().map(|s| s.ident.to_string()).collect());
        }
        syn::visit::visit_path(self, p);
    }

    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        macro_paths(m.tokens.clone(), &mut self.paths);
        syn::visit::visit_macro(self, m);
    }
}

/// `a::b::c` sequences in a macro's tokens (which `syn` leaves unparsed).
fn macro_paths(tokens: proc_macro2::TokenStream, out: &mut Vec<Vec<String>>) {
    use proc_macro2::TokenTree;
    let tokens: Vec<TokenTree> = tokens.into_iter().collect();
    let mut i = 0;
    while i < tokens.len() {
        match &tokens[i] {
            TokenTree::Group(g) => {
                macro_paths(g.stream(), out);
                i += 1;
            }
            TokenTree::Ident(first) => {
                let mut path = vec![first.to_string()];
                let mut j = i + 1;
                while let (Some(TokenTree::Punct(a)), Some(TokenTree::Punct(b))) =
                    (tokens.get(j), tokens.get(j + 1))
                {
                    match (a.as_char(), b.as_char(), tokens.get(j + 2)) {
                        (':', ':', Some(TokenTree::Ident(next))) => {
                            path.push(next.to_string());
                            j += 3;
                        }
                        _ => break,
                    }
                }
                if path.len() > 1 {
                    out.push(path);
                }
                i = j.max(i + 1);
            }
            _ => i += 1,
        }
    }
}

/// Strongly connected components with more than one module (Tarjan).
fn cycles(n: usize, edges: &BTreeMap<usize, BTreeMap<usize, String>>) -> Vec<Vec<usize>> {
    struct State<'a> {
        edges: &'a BTreeMap<usize, BTreeMap<usize, String>>,
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        on_stack: Vec<bool>,
        stack: Vec<usize>,
        next: usize,
        out: Vec<Vec<usize>>,
    }
    fn visit(s: &mut State, v: usize) {
        s.index[v] = Some(s.next);
        s.low[v] = s.next;
        s.next += 1;
        s.stack.push(v);
        s.on_stack[v] = true;
        let targets: Vec<usize> = s
            .edges
            .get(&v)
            .map(|t| t.keys().copied().collect())
            .unwrap_or_default();
        for w in targets {
            match s.index[w] {
                None => {
                    visit(s, w);
                    s.low[v] = s.low[v].min(s.low[w]);
                }
                Some(iw) if s.on_stack[w] => s.low[v] = s.low[v].min(iw),
                Some(_) => {}
            }
        }
        if Some(s.low[v]) == s.index[v] {
            let mut component = Vec::new();
            loop {
                let w = s.stack.pop().unwrap();
                s.on_stack[w] = false;
                component.push(w);
                if w == v {
                    break;
                }
            }
            if component.len() > 1 {
                component.sort();
                s.out.push(component);
            }
        }
    }
    let mut s = State {
        edges,
        index: vec![None; n],
        low: vec![0; n],
        on_stack: vec![false; n],
        stack: Vec::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in 0..n {
        if s.index[v].is_none() {
            visit(&mut s, v);
        }
    }
    s.out
}

/// Each cycle of `krate` as its sorted module names, with the edges that close it.
fn crate_cycles(krate: &Crate) -> Vec<(Vec<String>, String)> {
    let edges = krate.edges();
    cycles(krate.modules.len(), &edges)
        .into_iter()
        .map(|component| {
            let mut names: Vec<String> = component
                .iter()
                .map(|&m| krate.modules[m].name.clone())
                .collect();
            names.sort();
            let inside: BTreeSet<usize> = component.iter().copied().collect();
            let detail = component
                .iter()
                .flat_map(|&from| {
                    edges[&from]
                        .iter()
                        .filter(|(to, _)| inside.contains(to))
                        .map(move |(&to, path)| (from, to, path))
                })
                .map(|(from, to, path)| {
                    format!(
                        "    {} -> {} ({}: {path})",
                        krate.modules[from].name,
                        krate.modules[to].name,
                        krate.modules[from].file.display()
                    )
                })
                .collect::<Vec<_>>()
                .join("\n");
            (names, detail)
        })
        .collect()
}

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Fails with every cycle found in the crate rooted at `root` (relative to the workspace).
fn assert_no_cycle(name: &str, root: &str) {
    let krate = Crate::load(name, &workspace().join(root));
    let found = crate_cycles(&krate);
    let report: Vec<String> = found
        .iter()
        .map(|(names, detail)| format!("{}:\n{detail}", names.join(" <-> ")))
        .collect();
    assert!(
        found.is_empty(),
        "import cycles in {root} (move the shared item where both modules can import it):\n{}",
        report.join("\n")
    );
}

#[test]
fn the_engine_has_no_import_cycle() {
    assert_no_cycle("fovea_renderer", "renderer/src/lib.rs");
}

#[test]
fn the_embedding_library_has_no_import_cycle() {
    assert_no_cycle("fovea_stage", "renderer/stage/src/lib.rs");
}

#[test]
fn the_tools_have_no_import_cycle_but_the_listed_ones() {
    let krate = Crate::load("fovea_tools", &workspace().join("tools/src/lib.rs"));
    let found = crate_cycles(&krate);
    let known: BTreeSet<Vec<String>> = KNOWN_TOOLS_CYCLES
        .iter()
        .map(|c| c.iter().map(|s| s.to_string()).collect())
        .collect();
    for (names, detail) in &found {
        eprintln!(
            "known cycle, to be broken: {}:\n{detail}",
            names.join(" <-> ")
        );
    }
    let new: Vec<String> = found
        .iter()
        .filter(|(names, _)| !known.contains(names))
        .map(|(names, detail)| format!("{}:\n{detail}", names.join(" <-> ")))
        .collect();
    let gone: Vec<String> = known
        .iter()
        .filter(|k| !found.iter().any(|(names, _)| names == *k))
        .map(|k| k.join(" <-> "))
        .collect();
    assert!(
        new.is_empty(),
        "import cycles in tools/ (move the shared item where both modules can import it):\n{}",
        new.join("\n")
    );
    assert!(
        gone.is_empty(),
        "KNOWN_TOOLS_CYCLES lists cycles the tools do not have (remove them): {}",
        gone.join("; ")
    );
}

/// The checker itself: a cycle through a `super::` use and an inline path is found, a
/// re-export is followed to the defining module, and an external path is no edge.
#[test]
fn the_checker_finds_a_cycle_and_follows_re_exports() {
    let dir = std::env::temp_dir().join(format!("fovea-import-cycles-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("space")).unwrap();
    let write = |name: &str, text: &str| std::fs::write(dir.join(name), text).unwrap();
    write("lib.rs", "pub mod a;\npub mod b;\npub mod space;\n");
    write(
        "a.rs",
        "use super::b::B;\npub struct A;\npub fn f() { let _ = std::mem::size_of::<B>(); }\n",
    );
    write(
        "b.rs",
        "pub struct B;\npub fn g() -> usize { crate::a::f(); 1 }\n",
    );
    write(
        "space/mod.rs",
        "mod inner;\nmod user;\npub use inner::Inner;\npub trait Space {}\n",
    );
    write(
        "space/inner.rs",
        "use super::Space;\npub struct Inner;\nimpl Space for Inner {}\n",
    );
    write(
        "space/user.rs",
        "use super::{Inner, Space};\nfn h(_: &dyn Space, _: Inner) {}\n",
    );
    let krate = Crate::load("probe", &dir.join("lib.rs"));
    let found = crate_cycles(&krate);
    assert_eq!(
        found.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>(),
        vec![vec!["probe::a".to_string(), "probe::b".to_string()]],
        "{:?}",
        found.iter().map(|(_, d)| d).collect::<Vec<_>>()
    );
    let user = krate.find("probe::space::user").unwrap();
    let inner = krate.find("probe::space::inner").unwrap();
    let path = |p: &str| p.split("::").map(String::from).collect::<Vec<_>>();
    assert_eq!(krate.resolve(user, &path("super::Inner"), 0), Some(inner));
    assert_eq!(krate.resolve(user, &path("std::mem::swap"), 0), None);
    std::fs::remove_dir_all(&dir).unwrap();
}
