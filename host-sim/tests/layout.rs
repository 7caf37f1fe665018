//! The folders show the architecture: no import circle between the modules of the library, the
//! command line or the harness. A module may use its ancestors' items (a folder's `mod.rs`
//! holds what its files share) and its descendants'; between any other two, imports point one
//! way only.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Module path of each `.rs` file under `root` (`a/b.rs` and `a/b/mod.rs` are `a::b`).
fn modules(root: &Path) -> BTreeMap<Vec<String>, PathBuf> {
    let mut out = BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                let rel = p.strip_prefix(root).unwrap().with_extension("");
                let mut m: Vec<String> = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                if matches!(m.last().map(String::as_str), Some("mod" | "lib" | "main")) {
                    m.pop();
                }
                out.insert(m, p);
            }
        }
    }
    out
}

/// The code of a file without comments and without its unit tests (a test may use anything).
fn code(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let text = match text.find("#[cfg(test)]\nmod tests") {
        Some(i) => &text[..i],
        None => &text,
    };
    text.lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The paths written after `prefix` (`crate::`, `super::`): `a::b::C`, and each member of a
/// `{a, b::c}` group, as lists of names.
fn paths_after(code: &str, prefix: &str) -> Vec<Vec<String>> {
    let name = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let mut out = Vec::new();
    for (i, _) in code.match_indices(prefix) {
        if code[..i].chars().next_back().is_some_and(name) {
            continue;
        }
        let rest = &code[i + prefix.len()..];
        let mut path = Vec::new();
        let mut r = rest;
        loop {
            let n: String = r.chars().take_while(|&c| name(c)).collect();
            if n.is_empty() {
                if let Some(group) = r.strip_prefix('{') {
                    let inner = &group[..group.find('}').unwrap_or(group.len())];
                    for member in inner.split(',') {
                        let mut p = path.clone();
                        p.extend(
                            member
                                .trim()
                                .split("::")
                                .map(|s| s.split_whitespace().next().unwrap_or("").to_string())
                                .filter(|s| !s.is_empty()),
                        );
                        out.push(p);
                    }
                }
                break;
            }
            r = &r[n.len()..];
            path.push(n);
            match r.strip_prefix("::") {
                Some(next) => r = next,
                None => {
                    out.push(path.clone());
                    break;
                }
            }
        }
    }
    out
}

/// Which other modules each module imports (its ancestors left out).
fn imports(root: &Path) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
    let mods = modules(root);
    let mut edges = BTreeMap::new();
    for (m, path) in &mods {
        let code = code(path);
        // `super` of `a/b.rs` and of `a/b/mod.rs` (both `a::b`) is `a`.
        let parent: Vec<String> = m[..m.len().saturating_sub(1)].to_vec();
        let mut targets = BTreeSet::new();
        let resolve = |full: Vec<String>, targets: &mut BTreeSet<Vec<String>>| {
            for k in (1..=full.len()).rev() {
                if mods.contains_key(&full[..k]) {
                    targets.insert(full[..k].to_vec());
                    return;
                }
            }
        };
        for p in paths_after(&code, "crate::") {
            resolve(p, &mut targets);
        }
        for p in paths_after(&code, "super::") {
            let mut full = parent.clone();
            full.extend(p);
            resolve(full, &mut targets);
        }
        targets.retain(|t| t != m && !m.starts_with(t));
        edges.insert(m.clone(), targets);
    }
    edges
}

/// A circle of imports in `edges`, if there is one.
fn circle(edges: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>) -> Option<Vec<String>> {
    // 0 unvisited, 1 on the current path, 2 done.
    let mut state: BTreeMap<&Vec<String>, u8> = BTreeMap::new();
    fn visit<'a>(
        v: &'a Vec<String>,
        edges: &'a BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
        state: &mut BTreeMap<&'a Vec<String>, u8>,
        path: &mut Vec<&'a Vec<String>>,
    ) -> Option<Vec<String>> {
        state.insert(v, 1);
        path.push(v);
        for w in edges.get(v).into_iter().flatten() {
            // An import of a descendant is the parent using its own parts.
            if w.starts_with(v) {
                continue;
            }
            match state.get(w).copied().unwrap_or(0) {
                1 => {
                    let i = path.iter().position(|p| *p == w).unwrap();
                    let mut c: Vec<String> = path[i..].iter().map(|p| p.join("::")).collect();
                    c.push(w.join("::"));
                    return Some(c);
                }
                0 => {
                    if let Some(c) = visit(w, edges, state, path) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        path.pop();
        state.insert(v, 2);
        None
    }
    for v in edges.keys() {
        if state.get(v).copied().unwrap_or(0) == 0 {
            if let Some(c) = visit(v, edges, &mut state, &mut Vec::new()) {
                return Some(c);
            }
        }
    }
    None
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

#[test]
fn no_import_circles() {
    for dir in ["src", "cli/src", "host-sim/src"] {
        let edges = imports(&root().join(dir));
        assert!(edges.len() > 20, "{dir}: {} modules", edges.len());
        if let Some(c) = circle(&edges) {
            panic!("{dir}: an import circle: {}", c.join(" -> "));
        }
    }
}

/// The check finds a circle when there is one: two sibling files that import each other.
#[test]
fn a_circle_is_found() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(d.path().join("lib.rs"), "mod a;\nmod b;\nmod c;\n").unwrap();
    std::fs::write(d.path().join("a.rs"), "use crate::b::B;\n").unwrap();
    std::fs::write(d.path().join("b.rs"), "use super::{c::C, x};\n").unwrap();
    std::fs::write(d.path().join("c.rs"), "fn f() { crate::a::g() }\n").unwrap();
    let edges = imports(d.path());
    let c = circle(&edges).expect("a -> b -> c -> a");
    assert_eq!(c.len(), 4, "{c:?}");
    // Without c's import, none.
    std::fs::write(d.path().join("c.rs"), "// crate::a::g()\n").unwrap();
    assert_eq!(circle(&imports(d.path())), None);
}
