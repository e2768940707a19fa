//! The module layout's rules, checked on the source (parsed with syn):
//!
//! * no import circle between modules (a module is a file; a path through a re-export counts as
//!   an import of the module that defines the item). A submodule using its parent's own items
//!   (`super::SimError` in `sim/propagate.rs`) is not counted: the parent's file is the hub of its
//!   folder, which its submodules share, as in most Rust crates;
//! * no import running back up the stage order [`STAGES`] (the order of `src/lib.rs`);
//! * no file in `src/` over [`MAX_LINES`] lines.
//!
//! Imports are `use` items and paths in code (`crate::io::read_input(..)`, `super::fit::joint`),
//! in tests inside the files as well; doc links are not imports.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use syn::visit::Visit;

/// The stages in data-path order: a module may import from its own stage and the stages before
/// it, never from a later one. The first three are the shared vocabulary and file handling;
/// `fe` (elastic bodies from finite-element models) comes before the machine that uses them;
/// `rtest` (the evaluation math) comes before `sim`, which writes its circle tests as the
/// evaluation's `CircleSeries`; `measured` reads files into what `rtest` evaluates; `cli` is the
/// binary (`src/main.rs`). A new top-level module has to be placed here.
const STAGES: &[&str] = &[
    "text",
    "axes",
    "io",
    "fe",
    "machine",
    "mbs",
    "control",
    "rtest",
    "sim",
    "measured",
    "predict",
    "ident",
    "map",
    "compensation",
    "report",
    "cli",
    "main",
];

/// The longest file allowed in `src/`.
const MAX_LINES: usize = 700;

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// A module path from the crate root (`["rtest", "fit"]`); the binary's `main.rs` is `["main"]`
/// and its modules hang under the root as if in the library (`cli` is not a library module).
type ModPath = Vec<String>;

fn name(path: &[String]) -> String {
    if path.is_empty() {
        "crate".into()
    } else {
        path.join("::")
    }
}

/// One file: its module path, its child modules and the names its `use` items bind.
struct Module {
    file: PathBuf,
    syntax: syn::File,
    children: BTreeSet<String>,
    /// Name bound by a `use` item (at file level or in an inline module) -> the absolute path.
    bindings: BTreeMap<String, ModPath>,
}

/// Reads the module tree from `src/lib.rs` and `src/main.rs` by their `mod` declarations.
fn modules() -> BTreeMap<ModPath, Module> {
    let mut out = BTreeMap::new();
    let mut todo = vec![
        (Vec::new(), src().join("lib.rs")),
        (vec!["main".to_string()], src().join("main.rs")),
    ];
    while let Some((path, file)) = todo.pop() {
        let text =
            std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        let syntax = syn::parse_file(&text).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        // Child files sit beside lib.rs/main.rs/mod.rs, otherwise in a folder named after the file.
        let stem = file.file_stem().unwrap().to_str().unwrap();
        let dir = if ["lib", "main", "mod"].contains(&stem) {
            file.parent().unwrap().to_path_buf()
        } else {
            file.with_extension("")
        };
        let mut children = BTreeSet::new();
        for item in &syntax.items {
            if let syn::Item::Mod(m) = item {
                if m.content.is_none() {
                    let child = m.ident.to_string();
                    let flat = dir.join(format!("{child}.rs"));
                    let nested = dir.join(&child).join("mod.rs");
                    let child_file = if flat.exists() { flat } else { nested };
                    // The binary's modules are named from the root, like the library's.
                    let mut child_path = if path == ["main"] {
                        Vec::new()
                    } else {
                        path.clone()
                    };
                    child_path.push(child.clone());
                    todo.push((child_path, child_file));
                    children.insert(child);
                }
            }
        }
        let module = Module {
            file,
            syntax,
            children,
            bindings: BTreeMap::new(),
        };
        out.insert(path, module);
    }
    // The root's children include the binary's (`crate::cli` from inside the binary).
    let main_children = out[&vec!["main".to_string()]].children.clone();
    out.get_mut(&Vec::new())
        .unwrap()
        .children
        .extend(main_children);
    let paths: Vec<ModPath> = out.keys().cloned().collect();
    for path in paths {
        let mut bindings = BTreeMap::new();
        let module = &out[&path];
        let scope = Scope {
            module: &path,
            inline: Vec::new(),
            children: &module.children,
            bindings: &BTreeMap::new(),
        };
        collect_bindings(&module.syntax.items, &scope, &mut bindings);
        out.get_mut(&path).unwrap().bindings = bindings;
    }
    out
}

/// Where a path is written: its file's module, the inline modules around it, and what the file
/// names locally.
struct Scope<'a> {
    module: &'a ModPath,
    inline: Vec<String>,
    children: &'a BTreeSet<String>,
    bindings: &'a BTreeMap<String, ModPath>,
}

impl Scope<'_> {
    /// The module path of the innermost scope (the file's module in the crate's tree, plus inline
    /// modules).
    fn here(&self) -> ModPath {
        let mut p = if self.module == &["main"] {
            Vec::new()
        } else {
            self.module.clone()
        };
        p.extend(self.inline.iter().cloned());
        p
    }

    /// The absolute path a written path starts from, or `None` when it names something outside
    /// the crate (std, another crate, a local item).
    fn absolute(&self, segments: &[String]) -> Option<ModPath> {
        let first = segments.first()?;
        let rest = &segments[1..];
        let mut base = match first.as_str() {
            "crate" | "eij" => Vec::new(),
            "self" => self.here(),
            "super" => {
                let mut p = self.here();
                p.pop()?;
                let mut rest = rest;
                while rest.first().is_some_and(|s| s == "super") {
                    p.pop()?;
                    rest = &rest[1..];
                }
                p.extend(rest.iter().cloned());
                return Some(p);
            }
            s if self.inline.is_empty() && self.children.contains(s) => {
                let mut p = self.here();
                p.push(s.to_string());
                p
            }
            s => self.bindings.get(s)?.clone(),
        };
        base.extend(rest.iter().cloned());
        Some(base)
    }
}

/// The names a `use` tree binds, with their absolute paths.
fn use_tree(
    tree: &syn::UseTree,
    prefix: &mut Vec<String>,
    out: &mut Vec<(Option<String>, Vec<String>)>,
) {
    match tree {
        syn::UseTree::Path(p) => {
            prefix.push(p.ident.to_string());
            use_tree(&p.tree, prefix, out);
            prefix.pop();
        }
        syn::UseTree::Name(n) if n.ident == "self" => {
            out.push((prefix.last().cloned(), prefix.clone()));
        }
        syn::UseTree::Name(n) => {
            let mut p = prefix.clone();
            p.push(n.ident.to_string());
            out.push((Some(n.ident.to_string()), p));
        }
        syn::UseTree::Rename(r) => {
            let mut p = prefix.clone();
            if r.ident != "self" {
                p.push(r.ident.to_string());
            }
            out.push((Some(r.rename.to_string()), p));
        }
        syn::UseTree::Glob(_) => out.push((None, prefix.clone())),
        syn::UseTree::Group(g) => {
            for t in &g.items {
                use_tree(t, prefix, out);
            }
        }
    }
}

fn collect_bindings(items: &[syn::Item], scope: &Scope, out: &mut BTreeMap<String, ModPath>) {
    for item in items {
        match item {
            syn::Item::Use(u) => {
                let mut found = Vec::new();
                use_tree(&u.tree, &mut Vec::new(), &mut found);
                for (bound, written) in found {
                    if let (Some(bound), Some(abs)) = (bound, scope.absolute(&written)) {
                        out.entry(bound).or_insert(abs);
                    }
                }
            }
            syn::Item::Mod(m) => {
                if let Some((_, inner)) = &m.content {
                    let mut inline = scope.inline.clone();
                    inline.push(m.ident.to_string());
                    let scope = Scope { inline, ..*scope };
                    collect_bindings(inner, &scope, out);
                }
            }
            _ => {}
        }
    }
}

/// The module that defines what an absolute path names, following re-exports (`pub use`).
fn resolve(modules: &BTreeMap<ModPath, Module>, path: &[String]) -> ModPath {
    let mut path = path.to_vec();
    let mut current: ModPath = Vec::new();
    let mut i = 0;
    let mut hops = 0;
    while i < path.len() && hops < 32 {
        let module = &modules[&current];
        let seg = &path[i];
        if module.children.contains(seg) {
            current.push(seg.clone());
            if !modules.contains_key(&current) {
                // A child of the binary's root, which sits under the root in `modules`.
                break;
            }
            i += 1;
        } else if let Some(target) = module.bindings.get(seg) {
            let mut next = target.clone();
            next.extend(path[i + 1..].iter().cloned());
            path = next;
            current = Vec::new();
            i = 0;
            hops += 1;
        } else {
            break;
        }
    }
    current
}

/// Every path a file writes, with the absolute path it stands for.
struct Imports<'a> {
    scope: Scope<'a>,
    found: Vec<(String, ModPath)>,
}

impl<'ast> Visit<'ast> for Imports<'_> {
    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        let mut found = Vec::new();
        use_tree(&u.tree, &mut Vec::new(), &mut found);
        for (_, written) in found {
            if let Some(abs) = self.scope.absolute(&written) {
                self.found.push((written.join("::"), abs));
            }
        }
    }

    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        self.scope.inline.push(m.ident.to_string());
        syn::visit::visit_item_mod(self, m);
        self.scope.inline.pop();
    }

    fn visit_path(&mut self, p: &'ast syn::Path) {
        let written: Vec<String> = p.segments.iter().map(|s| s.ident.to_string()).collect();
        if written.len() > 1 {
            if let Some(abs) = self.scope.absolute(&written) {
                self.found.push((written.join("::"), abs));
            }
        }
        syn::visit::visit_path(self, p);
    }
}

/// Edges between modules: (importer, imported) -> the paths written for it.
fn imports(modules: &BTreeMap<ModPath, Module>) -> BTreeMap<(ModPath, ModPath), BTreeSet<String>> {
    let mut edges: BTreeMap<(ModPath, ModPath), BTreeSet<String>> = BTreeMap::new();
    for (path, module) in modules {
        let scope = Scope {
            module: path,
            inline: Vec::new(),
            children: &module.children,
            bindings: &module.bindings,
        };
        let mut visitor = Imports {
            scope,
            found: Vec::new(),
        };
        visitor.visit_file(&module.syntax);
        for (written, abs) in visitor.found {
            let target = resolve(modules, &abs);
            // Neither the module itself, nor an ancestor (the hub of the module's folder).
            if !path.starts_with(&target) {
                edges
                    .entry((path.clone(), target))
                    .or_default()
                    .insert(written);
            }
        }
    }
    edges
}

/// Strongly connected components of more than one module (Tarjan).
fn circles(
    nodes: &[ModPath],
    edges: &BTreeMap<(ModPath, ModPath), BTreeSet<String>>,
) -> Vec<Vec<ModPath>> {
    struct Tarjan<'a> {
        next: BTreeMap<&'a ModPath, Vec<&'a ModPath>>,
        index: BTreeMap<&'a ModPath, usize>,
        low: BTreeMap<&'a ModPath, usize>,
        stack: Vec<&'a ModPath>,
        on_stack: BTreeSet<&'a ModPath>,
        out: Vec<Vec<ModPath>>,
    }
    impl<'a> Tarjan<'a> {
        fn visit(&mut self, v: &'a ModPath) {
            let i = self.index.len();
            self.index.insert(v, i);
            self.low.insert(v, i);
            self.stack.push(v);
            self.on_stack.insert(v);
            for w in self.next.get(v).cloned().unwrap_or_default() {
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let lw = self.low[w];
                    let lv = self.low.get_mut(v).unwrap();
                    *lv = (*lv).min(lw);
                } else if self.on_stack.contains(w) {
                    let iw = self.index[w];
                    let lv = self.low.get_mut(v).unwrap();
                    *lv = (*lv).min(iw);
                }
            }
            if self.low[v] == self.index[v] {
                let mut component = Vec::new();
                while let Some(w) = self.stack.pop() {
                    self.on_stack.remove(w);
                    component.push(w.clone());
                    if w == v {
                        break;
                    }
                }
                if component.len() > 1 {
                    component.sort();
                    self.out.push(component);
                }
            }
        }
    }
    let mut next: BTreeMap<&ModPath, Vec<&ModPath>> = BTreeMap::new();
    for (a, b) in edges.keys() {
        next.entry(a).or_default().push(b);
    }
    let mut t = Tarjan {
        next,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in nodes {
        if !t.index.contains_key(v) {
            t.visit(v);
        }
    }
    t.out
}

/// The stage of a module: its first segment (`main` for the binary's root).
fn stage(path: &[String]) -> Option<usize> {
    STAGES
        .iter()
        .position(|s| Some(*s) == path.first().map(String::as_str))
}

#[test]
fn no_import_circle_between_modules() {
    let modules = modules();
    let edges = imports(&modules);
    let nodes: Vec<ModPath> = modules.keys().cloned().collect();
    let mut report = String::new();
    for circle in circles(&nodes, &edges) {
        report += &format!(
            "circle of {}:\n",
            circle
                .iter()
                .map(|m| name(m))
                .collect::<Vec<_>>()
                .join(", ")
        );
        for ((a, b), written) in &edges {
            if circle.contains(a) && circle.contains(b) {
                let written: Vec<_> = written.iter().cloned().collect();
                report += &format!("  {} uses {} ({})\n", name(a), name(b), written.join(", "));
            }
        }
    }
    assert!(
        report.is_empty(),
        "import circles (break each by moving the shared item down):\n{report}"
    );
}

#[test]
fn no_import_runs_back_up_the_stages() {
    let modules = modules();
    let mut report = String::new();
    for path in modules.keys().filter(|p| !p.is_empty()) {
        if stage(path).is_none() {
            report += &format!(
                "{} ({}) is in no stage: place it in STAGES (tests/architecture.rs) and src/lib.rs\n",
                name(path),
                modules[path].file.display()
            );
        }
    }
    for ((a, b), written) in imports(&modules) {
        if let (Some(sa), Some(sb)) = (stage(&a), stage(&b)) {
            if sb > sa {
                let written: Vec<_> = written.into_iter().collect();
                report += &format!(
                    "{} (stage {}) uses {} of the later stage {}: {}\n",
                    name(&a),
                    STAGES[sa],
                    name(&b),
                    STAGES[sb],
                    written.join(", ")
                );
            }
        }
    }
    assert!(
        report.is_empty(),
        "imports against the stage order {STAGES:?}:\n{report}"
    );
}

#[test]
fn no_file_over_the_line_limit() {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }
    let mut files = Vec::new();
    walk(&src(), &mut files);
    let long: Vec<String> = files
        .iter()
        .filter_map(|f| {
            let lines = std::fs::read_to_string(f).unwrap().lines().count();
            (lines > MAX_LINES).then(|| format!("{} has {lines} lines", f.display()))
        })
        .collect();
    assert!(
        long.is_empty(),
        "files over {MAX_LINES} lines:\n{}",
        long.join("\n")
    );
}

/// The checks themselves see what they are meant to: the known imports of today's tree.
#[test]
fn the_checks_see_known_imports() {
    let modules = modules();
    let edges = imports(&modules);
    let has = |a: &[&str], b: &[&str]| {
        let a: ModPath = a.iter().map(|s| s.to_string()).collect();
        let b: ModPath = b.iter().map(|s| s.to_string()).collect();
        edges.contains_key(&(a, b))
    };
    // `use crate::machine::Machine` in mbs, through machine/mod.rs's definition.
    assert!(has(&["mbs"], &["machine"]));
    // A path in code through a re-export of the root: `crate::Eij`-style names resolve to axes.
    assert!(has(&["control"], &["axes"]));
    // The binary's modules import the library by its name.
    assert!(has(&["cli", "identify"], &["ident"]));
    assert!(modules.len() > 60, "{} modules found", modules.len());
}
