//! The library's import structure, checked on its source: no two files of `lib/`
//! import each other, directly or around a circle, and no file imports a layer
//! above its own.
//!
//! The graph has one node per file of the module tree that `lib/lib.rs` declares
//! (`mod` declarations give the tree, not arrows: a folder's `mod.rs` is its table
//! of contents). An arrow A → B is a path in A that names something of B: a `use`
//! (`crate::…`, `super::…`, `self::…`, a child module), or a path in code
//! (`crate::contact::pair::PairSolver::new`, `super::dual::Dual`, `child::f()`).
//! The graph is the library as it is built: `#[cfg(test)]` modules, which take
//! their fixtures from anywhere, are left out.
//! A name taken from a module that only re-exports it (`pub use child::Name` in a
//! `mod.rs`) or imports it is followed to the file that defines it; a glob
//! (`super::*`) or a name not found there stops at the module's file. A re-export
//! alone is no arrow (it hands the name on; whoever uses it gets the arrow to the
//! defining file); a module that also uses the name in its own code has it. Comments, doc links and string
//! literals are no arrows; test modules count like any other code.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers from the bottom up: a file may import its own layer and those below.
const LAYERS: &[(&str, &[&str])] = &[
    ("foundations", &["lib/mesh/", "lib/spline/", "lib/folder_lock.rs", "lib/os/"]),
    ("elements", &["lib/material/", "lib/fem/"]),
    ("assembly", &["lib/assembly/"]),
    ("contact", &["lib/contact/"]),
    ("post-processing", &["lib/post/"]),
    // formats read and write the data of the layers below (meshes, control nets,
    // contact settings); the solver configures itself from the setup and writes
    // its results through them
    ("formats", &["lib/format/"]),
    ("solver", &["lib/solver/"]),
    ("check", &["lib/check/"]),
    ("stages", &["lib/stages/"]),
    ("pipeline", &["lib/pipeline.rs", "lib/lib.rs"]),
];

/// Arrows against the layers that stand until their cause moves: (from, to, why).
const ALLOWED_UPWARD: &[(&str, &str, &str)] = &[
    ("lib/contact/", "lib/format/sccontact.rs", "the tagged contact pair (ContactPair, MasterKind) is defined with its file format"),
    ("lib/format/pipeline.rs", "lib/stages/", "the pipeline YAML is made of each stage's own settings"),
];

/// Circles that stand until their cause moves: (the files, why). A circle through
/// more files, or any other, fails.
const ALLOWED_CIRCLES: &[(&[&str], &str)] = &[
];

#[test]
fn no_import_circle_between_library_files() {
    let graph = library_graph();
    assert!(graph.files.len() > 50, "the scan found only {} files under lib/", graph.files.len());
    let circles: Vec<_> = graph
        .circles()
        .into_iter()
        .filter(|c| {
            let mut files: Vec<&str> = c.iter().map(|&f| graph.files[f].as_str()).collect();
            files.sort();
            !ALLOWED_CIRCLES.iter().any(|(allowed, _)| *allowed == files.as_slice())
        })
        .collect();
    assert!(circles.is_empty(), "import circles between files of lib/:\n{}", circles.iter().map(|c| graph.describe(c)).collect::<Vec<_>>().join("\n"));
}

#[test]
fn no_file_imports_a_layer_above_its_own() {
    let graph = library_graph();
    let mut wrong = Vec::new();
    for (&a, targets) in &graph.edges {
        for (&b, names) in targets {
            let (fa, fb) = (&graph.files[a], &graph.files[b]);
            let (la, lb) = (layer_of(fa), layer_of(fb));
            let allowed = ALLOWED_UPWARD.iter().any(|(from, to, _)| fa.starts_with(from) && fb.starts_with(to));
            if lb > la && !allowed {
                wrong.push(format!("{fa} ({}) -> {fb} ({}): {}", LAYERS[la].0, LAYERS[lb].0, names.iter().cloned().collect::<Vec<_>>().join(", ")));
            }
        }
    }
    assert!(wrong.is_empty(), "imports that run up the layers ({}):\n{}", LAYERS.iter().map(|l| l.0).collect::<Vec<_>>().join(" < "), wrong.join("\n"));
}

#[test]
fn every_library_file_has_a_layer() {
    let graph = library_graph();
    for f in &graph.files {
        layer_of(f);
    }
}

/// The cycle finder on a graph with a circle a → b → c → a (and d hanging on it),
/// and on the same graph with the closing arrow removed.
#[test]
fn the_cycle_finder_finds_a_planted_circle() {
    let mut g = Graph::default();
    for f in ["a", "b", "c", "d"] {
        g.files.push(f.to_string());
    }
    for (a, b) in [(0, 1), (1, 2), (2, 0), (3, 0)] {
        g.add(a, b, "x");
    }
    let circles = g.circles();
    assert_eq!(circles.len(), 1);
    assert_eq!(circles[0], vec![0, 1, 2]);
    assert!(g.describe(&circles[0]).contains("a -> b"), "{}", g.describe(&circles[0]));
    g.edges.get_mut(&2).unwrap().clear();
    assert!(g.circles().is_empty());
}

/// The scanner on a tiny crate: a `mod.rs` that re-exports from its child, a child
/// that takes a name of its parent's own, and the sibling reached through the
/// re-export (followed to the defining file, so not a circle).
#[test]
fn the_scanner_resolves_reexports_and_finds_a_circle_through_a_parent() {
    let files = [
        ("lib/lib.rs", "pub mod a;\npub mod b;\n"),
        ("lib/a/mod.rs", "//! `use crate::b::X` in a comment is no arrow\nmod inner;\nmod quiet;\npub use inner::Thing;\npub use quiet::Quiet;\npub struct Base;\npub fn make() -> Thing { todo!() }\n"),
        ("lib/a/inner.rs", "use super::Base;\npub struct Thing(Base);\nfn f() { let _ = \"crate::b::Y\"; }\n"),
        ("lib/a/quiet.rs", "pub struct Quiet(super::Base);\n"),
        ("lib/b.rs", "use crate::a::Thing;\npub struct X;\nfn h() { crate::a::free() }\n#[cfg(test)]\nmod tests {\n    fn g() -> crate::a::quiet::Quiet { todo!() }\n}\n"),
    ];
    let g = Graph::scan(files.iter().map(|(p, s)| (p.to_string(), s.to_string())).collect());
    let names: Vec<_> = g.files.iter().map(String::as_str).collect();
    assert_eq!(names, ["lib/a/inner.rs", "lib/a/mod.rs", "lib/a/quiet.rs", "lib/b.rs", "lib/lib.rs"]);
    let has = |a: usize, b: usize| g.edges.get(&a).is_some_and(|t| t.contains_key(&b));
    assert!(has(3, 0), "b -> a/inner.rs through the re-export");
    assert!(has(3, 1), "b -> a/mod.rs (a name a/mod.rs defines)");
    assert!(!has(3, 2), "a test module is no arrow");
    assert!(has(1, 0) && has(0, 1), "a/mod.rs uses what it re-exports from inner, inner uses its parent's Base");
    assert!(has(2, 1) && !has(1, 2), "a/mod.rs only re-exports quiet: no arrow back");
    assert!(!has(1, 3) && !has(0, 3), "no arrow from a comment or a string");
    let circles = g.circles();
    assert_eq!(circles.len(), 1, "{circles:?}");
    assert!(g.describe(&circles[0]).contains("Base"));
}

fn layer_of(file: &str) -> usize {
    LAYERS.iter().position(|(_, prefixes)| prefixes.iter().any(|p| file.starts_with(p))).unwrap_or_else(|| panic!("{file} is in no layer: add its folder to LAYERS in tests/structure.rs"))
}

fn library_graph() -> Graph {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    let mut stack = vec![root.join("lib")];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let rel = path.strip_prefix(root).unwrap().to_string_lossy().replace('\\', "/");
                files.push((rel, std::fs::read_to_string(&path).unwrap()));
            }
        }
    }
    Graph::scan(files)
}

/// The file-level import graph: `edges[a][b]` holds the names file `a` takes from `b`.
#[derive(Default)]
struct Graph {
    files: Vec<String>,
    edges: BTreeMap<usize, BTreeMap<usize, BTreeSet<String>>>,
}

impl Graph {
    fn add(&mut self, a: usize, b: usize, name: &str) {
        if a != b {
            self.edges.entry(a).or_default().entry(b).or_default().insert(name.to_string());
        }
    }

    /// Every strongly connected component of more than one file (Tarjan): the
    /// files that import each other around one or more circles.
    fn circles(&self) -> Vec<Vec<usize>> {
        struct State {
            index: Vec<Option<usize>>,
            low: Vec<usize>,
            on_stack: Vec<bool>,
            stack: Vec<usize>,
            next: usize,
            out: Vec<Vec<usize>>,
        }
        fn visit(g: &Graph, v: usize, s: &mut State) {
            s.index[v] = Some(s.next);
            s.low[v] = s.next;
            s.next += 1;
            s.stack.push(v);
            s.on_stack[v] = true;
            for &w in g.edges.get(&v).map(|t| t.keys().copied().collect::<Vec<_>>()).unwrap_or_default().iter() {
                match s.index[w] {
                    None => {
                        visit(g, w, s);
                        s.low[v] = s.low[v].min(s.low[w]);
                    }
                    Some(i) if s.on_stack[w] => s.low[v] = s.low[v].min(i),
                    Some(_) => {}
                }
            }
            if Some(s.low[v]) == s.index[v] {
                let mut scc = Vec::new();
                loop {
                    let w = s.stack.pop().unwrap();
                    s.on_stack[w] = false;
                    scc.push(w);
                    if w == v {
                        break;
                    }
                }
                if scc.len() > 1 {
                    scc.sort();
                    s.out.push(scc);
                }
            }
        }
        let n = self.files.len();
        let mut s = State { index: vec![None; n], low: vec![0; n], on_stack: vec![false; n], stack: Vec::new(), next: 0, out: Vec::new() };
        for v in 0..n {
            if s.index[v].is_none() {
                visit(self, v, &mut s);
            }
        }
        s.out
    }

    /// One circle inside a strongly connected component: the shortest way from its
    /// smallest file back to itself.
    fn circle_in(&self, scc: &[usize]) -> Vec<usize> {
        let inside: BTreeSet<usize> = scc.iter().copied().collect();
        let start = *inside.iter().next().unwrap();
        let mut came_from = BTreeMap::new();
        let mut queue = std::collections::VecDeque::from([start]);
        while let Some(v) = queue.pop_front() {
            for &w in self.edges.get(&v).map(|t| t.keys().copied().collect::<Vec<_>>()).unwrap_or_default().iter() {
                if !inside.contains(&w) || came_from.contains_key(&w) {
                    continue;
                }
                came_from.insert(w, v);
                if w == start {
                    let mut path = vec![v];
                    while *path.last().unwrap() != start {
                        path.push(came_from[path.last().unwrap()]);
                    }
                    path.reverse();
                    return path;
                }
                queue.push_back(w);
            }
        }
        scc.to_vec()
    }

    /// One circle of the component: "a -> b (names), b -> c (names), c -> a (names)".
    fn describe(&self, component: &[usize]) -> String {
        let circle = self.circle_in(component);
        let mut parts = Vec::new();
        for (k, &a) in circle.iter().enumerate() {
            let b = circle[(k + 1) % circle.len()];
            let names = self.edges.get(&a).and_then(|t| t.get(&b)).map(|n| n.iter().cloned().collect::<Vec<_>>().join(", ")).unwrap_or_default();
            parts.push(format!("{} -> {} ({names})", self.files[a], self.files[b]));
        }
        format!("  circle: {}{}", parts.join(", "), if component.len() > circle.len() {
            format!(" (and around other circles: {})", component.iter().filter(|f| !circle.contains(f)).map(|&f| self.files[f].as_str()).collect::<Vec<_>>().join(", "))
        } else {
            String::new()
        })
    }

    /// The graph of the crate whose files (path, source) are given; the module tree
    /// starts at `lib/lib.rs`.
    fn scan(files: Vec<(String, String)>) -> Graph {
        let sources: BTreeMap<String, String> = files.into_iter().collect();
        let mut crate_ = Crate::default();
        crate_.load(&sources, "lib/lib.rs", Vec::new());
        let mut g = Graph::default();
        let ids: BTreeMap<String, usize> = crate_.files.keys().cloned().enumerate().map(|(i, f)| (f, i)).collect();
        g.files = ids.keys().cloned().collect();
        for r in &crate_.references {
            if let Some((target, name)) = crate_.resolve(&r.module, &r.path, 0) {
                g.add(ids[&r.file], ids[&target], &name);
            }
        }
        g
    }
}

/// A module: the file that holds it, its child modules, and the names its `use`
/// declarations bring in (name → path, as written).
#[derive(Default, Clone)]
struct Module {
    file: String,
    children: BTreeSet<String>,
    imports: BTreeMap<String, Vec<String>>,
}

/// A path written in a file, inside module `module`.
struct Reference {
    file: String,
    module: Vec<String>,
    path: Vec<String>,
}

#[derive(Default)]
struct Crate {
    modules: BTreeMap<Vec<String>, Module>,
    files: BTreeMap<String, ()>,
    references: Vec<Reference>,
}

#[derive(Debug, Clone, PartialEq)]
enum Token {
    Ident(String),
    PathSep,
    Punct(char),
}

impl Crate {
    /// Reads the file of module `path` and, recursively, the files of the modules it
    /// declares.
    fn load(&mut self, sources: &BTreeMap<String, String>, file: &str, path: Vec<String>) {
        let Some(source) = sources.get(file) else { return };
        self.files.insert(file.to_string(), ());
        let tokens = tokenize(source);
        // the folder a child `mod x;` of this file lives in
        let dir = if file.ends_with("/mod.rs") || file.ends_with("/lib.rs") { PathBuf::from(file).parent().unwrap().to_path_buf() } else { PathBuf::from(file.trim_end_matches(".rs")) };
        let mut stack: Vec<(Vec<String>, usize)> = vec![(path.clone(), 0)];
        self.modules.entry(path.clone()).or_default().file = file.to_string();
        let mut depth = 0usize;
        let mut declared = Vec::new();
        let mut reexports = Vec::new();
        let used: BTreeSet<&str> = {
            // the identifiers of the file's code outside `use` declarations
            let mut used = BTreeSet::new();
            let mut in_use = false;
            for t in &tokens {
                match t {
                    Token::Ident(k) if k == "use" => in_use = true,
                    Token::Punct(';') => in_use = false,
                    Token::Ident(k) if !in_use => {
                        used.insert(k.as_str());
                    }
                    _ => {}
                }
            }
            used
        };
        let mut i = 0;
        while i < tokens.len() {
            let module = stack.last().unwrap().0.clone();
            match &tokens[i] {
                Token::Punct('#') if test_module_at(&tokens, i).is_some() => {
                    i = test_module_at(&tokens, i).unwrap();
                    continue;
                }
                Token::Punct('{') => depth += 1,
                Token::Punct('}') => {
                    depth = depth.saturating_sub(1);
                    if stack.len() > 1 && stack.last().unwrap().1 == depth + 1 {
                        stack.pop();
                    }
                }
                Token::Ident(k) if k == "mod" => {
                    if let Some(Token::Ident(name)) = tokens.get(i + 1) {
                        self.modules.get_mut(&module).unwrap().children.insert(name.clone());
                        let mut child = module.clone();
                        child.push(name.clone());
                        match tokens.get(i + 2) {
                            Some(Token::Punct('{')) => {
                                depth += 1;
                                self.modules.entry(child.clone()).or_default().file = file.to_string();
                                stack.push((child, depth));
                                i += 3;
                                continue;
                            }
                            Some(Token::Punct(';')) if module == path => declared.push((name.clone(), child)),
                            _ => {}
                        }
                        i += 2;
                        continue;
                    }
                }
                Token::Ident(k) if k == "use" => {
                    let end = tokens[i..].iter().position(|t| *t == Token::Punct(';')).map_or(tokens.len(), |e| i + e);
                    let public = i > 0 && (tokens[i - 1] == Token::Ident("pub".into()) || tokens[i - 1] == Token::Punct(')') && i >= 4 && tokens[i - 4] == Token::Ident("pub".into()));
                    let mut items = Vec::new();
                    use_tree(&tokens[i + 1..end], &mut 0, Vec::new(), &mut items);
                    for (p, alias) in items {
                        if let Some(alias) = &alias {
                            self.modules.get_mut(&module).unwrap().imports.insert(alias.clone(), p.clone());
                        }
                        let reference = Reference { file: file.to_string(), module: module.clone(), path: p };
                        match alias {
                            // a re-export hands the name on: an arrow only if this file uses it too
                            Some(alias) if public => reexports.push((alias, reference)),
                            None if public => {}
                            _ => self.references.push(reference),
                        }
                    }
                    i = end + 1;
                    continue;
                }
                Token::Ident(first) => {
                    let after_sep = i > 0 && tokens[i - 1] == Token::PathSep;
                    if !after_sep && tokens.get(i + 1) == Some(&Token::PathSep) {
                        let mut p = vec![first.clone()];
                        let mut j = i + 1;
                        while tokens.get(j) == Some(&Token::PathSep) {
                            match tokens.get(j + 1) {
                                Some(Token::Ident(s)) => p.push(s.clone()),
                                _ => break,
                            }
                            j += 2;
                        }
                        let first = first.trim_start_matches('$');
                        let relative = self.modules[&module].children.contains(first);
                        if matches!(first, "crate" | "super" | "self") || relative {
                            p[0] = first.to_string();
                            self.references.push(Reference { file: file.to_string(), module: module.clone(), path: p });
                        }
                        i = j;
                        continue;
                    }
                }
                _ => {}
            }
            i += 1;
        }
        for (alias, reference) in reexports {
            if used.contains(alias.as_str()) {
                self.references.push(reference);
            }
        }
        for (name, child) in declared {
            let candidates = [dir.join(format!("{name}.rs")), dir.join(&name).join("mod.rs")];
            if let Some(f) = candidates.iter().map(|c| c.to_string_lossy().replace('\\', "/")).find(|c| sources.contains_key(c)) {
                self.modules.entry(child.clone()).or_default();
                self.load(sources, &f, child);
            }
        }
    }

    /// The file that defines what `path` (written in module `module`) names, and
    /// the name, following re-exports and imports; `None` for another crate.
    fn resolve(&self, module: &[String], path: &[String], depth: usize) -> Option<(String, String)> {
        if depth > 16 || path.is_empty() {
            return None;
        }
        let mut m: Vec<String> = module.to_vec();
        let mut i = 0;
        match path[0].as_str() {
            "crate" => {
                m.clear();
                i = 1;
            }
            "self" => i = 1,
            "super" => {
                while path.get(i).is_some_and(|s| s == "super") {
                    m.pop();
                    i += 1;
                }
            }
            first if self.modules.get(&m).is_some_and(|md| md.children.contains(first)) => {}
            _ => return None,
        }
        while let Some(seg) = path.get(i) {
            let mut child = m.clone();
            child.push(seg.clone());
            if !self.modules.contains_key(&child) {
                break;
            }
            m = child;
            i += 1;
        }
        let md = self.modules.get(&m)?;
        let Some(name) = path.get(i) else { return Some((md.file.clone(), m.last().cloned().unwrap_or_default())) };
        if name != "*" {
            if let Some(target) = md.imports.get(name) {
                let mut through: Vec<String> = target.clone();
                through.extend(path[i + 1..].iter().cloned());
                if let Some(found) = self.resolve(&m, &through, depth + 1) {
                    return Some(found);
                }
            }
        }
        Some((md.file.clone(), name.clone()))
    }
}

/// Where the code after a `#[cfg(test)]` module starts, when the attribute at `i`
/// is one (`mod tests;` or `mod tests { … }`, other attributes and `pub` between).
fn test_module_at(t: &[Token], i: usize) -> Option<usize> {
    let ident = |k: usize, s: &str| t.get(k) == Some(&Token::Ident(s.into()));
    let punct = |k: usize, c: char| t.get(k) == Some(&Token::Punct(c));
    if !(punct(i + 1, '[') && ident(i + 2, "cfg") && punct(i + 3, '(') && ident(i + 4, "test") && punct(i + 5, ')') && punct(i + 6, ']')) {
        return None;
    }
    let mut j = i + 7;
    let close = |mut k: usize, open: char, shut: char| {
        let mut level = 0;
        while k < t.len() {
            if punct(k, open) {
                level += 1;
            } else if punct(k, shut) {
                level -= 1;
                if level == 0 {
                    return k + 1;
                }
            }
            k += 1;
        }
        k
    };
    while punct(j, '#') {
        j = close(j + 1, '[', ']');
    }
    if ident(j, "pub") {
        j += 1;
        if punct(j, '(') {
            j = close(j, '(', ')');
        }
    }
    if !ident(j, "mod") {
        return None;
    }
    match t.get(j + 2) {
        Some(Token::Punct(';')) => Some(j + 3),
        Some(Token::Punct('{')) => Some(close(j + 2, '{', '}')),
        _ => None,
    }
}

/// The paths of a `use` tree (after `use`), each with the name it binds (`None`
/// for a glob).
fn use_tree(t: &[Token], k: &mut usize, prefix: Vec<String>, out: &mut Vec<(Vec<String>, Option<String>)>) {
    let mut p = prefix;
    loop {
        match t.get(*k) {
            Some(Token::PathSep) => *k += 1,
            Some(Token::Punct('*')) => {
                *k += 1;
                p.push("*".into());
                out.push((p, None));
                return;
            }
            Some(Token::Punct('{')) => {
                *k += 1;
                loop {
                    match t.get(*k) {
                        Some(Token::Punct('}')) | None => {
                            *k += 1;
                            return;
                        }
                        Some(Token::Punct(',')) => *k += 1,
                        _ => use_tree(t, k, p.clone(), out),
                    }
                }
            }
            Some(Token::Ident(s)) if s == "self" && !p.is_empty() => {
                *k += 1;
                let alias = alias_after(t, k).unwrap_or_else(|| p.last().unwrap().clone());
                out.push((p, Some(alias)));
                return;
            }
            Some(Token::Ident(s)) => {
                *k += 1;
                p.push(s.clone());
                if t.get(*k) != Some(&Token::PathSep) {
                    let alias = alias_after(t, k).unwrap_or_else(|| s.clone());
                    out.push((p, Some(alias)));
                    return;
                }
            }
            _ => return,
        }
    }
}

fn alias_after(t: &[Token], k: &mut usize) -> Option<String> {
    if t.get(*k) == Some(&Token::Ident("as".into())) {
        if let Some(Token::Ident(a)) = t.get(*k + 1) {
            *k += 2;
            return Some(a.clone());
        }
    }
    None
}

/// Identifiers, `::` and single punctuation of Rust source, without comments,
/// string and character literals (lifetimes are kept as identifiers).
fn tokenize(src: &str) -> Vec<Token> {
    let c: Vec<char> = src.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    let ident_char = |ch: char| ch.is_alphanumeric() || ch == '_';
    while i < c.len() {
        let ch = c[i];
        if ch == '/' && c.get(i + 1) == Some(&'/') {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if ch == '/' && c.get(i + 1) == Some(&'*') {
            let mut level = 0;
            while i < c.len() {
                if c[i] == '/' && c.get(i + 1) == Some(&'*') {
                    level += 1;
                    i += 2;
                } else if c[i] == '*' && c.get(i + 1) == Some(&'/') {
                    level -= 1;
                    i += 2;
                    if level == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if ch == '"' {
            i += 1;
            while i < c.len() && c[i] != '"' {
                i += if c[i] == '\\' { 2 } else { 1 };
            }
            i += 1;
        } else if ch == '\'' {
            // a character literal ('x', '\n', '\u{1F600}'), or a lifetime
            if c.get(i + 1) == Some(&'\\') {
                i += 2;
                while i < c.len() && c[i] != '\'' {
                    i += 1;
                }
                i += 1;
            } else if c.get(i + 2) == Some(&'\'') {
                i += 3;
            } else {
                i += 1;
            }
        } else if ident_char(ch) || ch == '$' {
            let start = i;
            while i < c.len() && (ident_char(c[i]) || c[i] == '$') {
                i += 1;
            }
            let word: String = c[start..i].iter().collect();
            // raw strings r"…", r#"…"#, br"…", and byte strings b"…"
            let hashes = c[i..].iter().take_while(|&&h| h == '#').count();
            if (word == "r" || word == "br") && c.get(i + hashes) == Some(&'"') {
                i += hashes + 1;
                let close: Vec<char> = std::iter::once('"').chain(std::iter::repeat_n('#', hashes)).collect();
                while i < c.len() && c[i..].iter().take(close.len()).ne(close.iter()) {
                    i += 1;
                }
                i += close.len();
            } else if word == "b" && c.get(i) == Some(&'"') {
                continue;
            } else if word.chars().next().is_some_and(|f| !f.is_ascii_digit()) {
                out.push(Token::Ident(word));
            }
        } else if ch == ':' && c.get(i + 1) == Some(&':') {
            out.push(Token::PathSep);
            i += 2;
        } else {
            if !ch.is_whitespace() {
                out.push(Token::Punct(ch));
            }
            i += 1;
        }
    }
    out
}
