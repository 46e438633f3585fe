//! No import circle between the top-level modules of any crate of the workspace (the same check as
//! `scripts/module_graph.py`, which also prints the graph): a new circle fails here.
//!
//! Reads the workspace's own `*/src/` folders (beside this crate's manifest), not any outside data. Comments, string
//! literals and `#[cfg(test)]` modules at the end of a file are left out: the graph is the one the
//! library compiles.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The library code of a file: up to its test module, without line comments and strings.
fn code(text: &str) -> String {
    let mut out = String::new();
    for line in text.lines() {
        if line.trim_start().starts_with("#[cfg(test)]") {
            break;
        }
        let mut in_string = false;
        let mut prev = ' ';
        for (i, c) in line.char_indices() {
            if !in_string && line[i..].starts_with("//") {
                break;
            }
            if c == '"' && prev != '\\' {
                in_string = !in_string;
            } else if !in_string {
                out.push(c);
            }
            prev = c;
        }
        out.push('\n');
    }
    out
}

/// Top-level modules named by `crate::` paths in `code` (brace groups included).
fn references(code: &str) -> BTreeSet<String> {
    let ident = |s: &str| -> String {
        s.trim_start()
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut found = BTreeSet::new();
    for (at, _) in code.match_indices("crate::") {
        let before = code[..at].chars().next_back().unwrap_or(' ');
        if before.is_alphanumeric() || before == '_' || before == ':' {
            continue;
        }
        let rest = &code[at + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let (mut depth, mut start) = (0usize, 0usize);
            for (i, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => {
                        found.insert(ident(&group[start..i]));
                        break;
                    }
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        found.insert(ident(&group[start..i]));
                        start = i + 1;
                    }
                    _ => {}
                }
            }
        } else {
            found.insert(ident(rest));
        }
    }
    found
}

fn graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let top = |p: &Path| -> Option<String> {
        let rel = p.strip_prefix(src).ok()?;
        let first = rel.components().next()?.as_os_str().to_str()?;
        let name = first.trim_end_matches(".rs");
        (name != "lib").then(|| name.to_string())
    };
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in &files {
        if let Some(m) = top(f) {
            g.entry(m).or_default();
        }
    }
    for f in &files {
        let Some(m) = top(f) else { continue };
        if f.file_name()
            .is_some_and(|n| n.to_string_lossy().ends_with("tests.rs"))
        {
            continue;
        }
        let deps: BTreeSet<String> = references(&code(&std::fs::read_to_string(f).unwrap()))
            .into_iter()
            .filter(|d| d != &m && g.contains_key(d))
            .collect();
        g.get_mut(&m).unwrap().extend(deps);
    }
    g
}

/// A cycle through `g`, if any (depth-first search with the path on a stack).
fn find_cycle(g: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        v: &str,
        g: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(v.to_string(), 1);
        path.push(v.to_string());
        for w in &g[v] {
            match state.get(w.as_str()).copied().unwrap_or(0) {
                1 => {
                    let from = path.iter().position(|p| p == w).unwrap_or(0);
                    let mut cycle = path[from..].to_vec();
                    cycle.push(w.clone());
                    return Some(cycle);
                }
                0 => {
                    if let Some(c) = visit(w, g, state, path) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        path.pop();
        state.insert(v.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for v in g.keys() {
        if state.get(v.as_str()).copied().unwrap_or(0) == 0
            && let Some(c) = visit(v, g, &mut state, &mut Vec::new())
        {
            return Some(c);
        }
    }
    None
}

/// The workspace folder: this crate's manifest folder's parent.
fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("validation sits in the workspace")
        .to_path_buf()
}

#[test]
fn render_modules_import_one_way() {
    let src = workspace().join("render/src");
    let g = graph(&src);
    assert!(
        g.len() > 20,
        "{} modules found in {}",
        g.len(),
        src.display()
    );
    // The check can fail: the integrator imports the scene, so a scene importing the integrator
    // would close a circle.
    assert!(g["integrator"].contains("scene"), "{g:?}");
    let mut closed = g.clone();
    closed.get_mut("scene").unwrap().insert("integrator".into());
    assert!(find_cycle(&closed).is_some());
    assert_eq!(find_cycle(&g), None, "{g:?}");
}

#[test]
fn every_crates_modules_import_one_way() {
    let crates = [
        "skin-optics",
        "brdf",
        "skin-io",
        "multipole",
        "skin-fit",
        "skin-export",
        "skin-plot",
        "skin-cli",
        "validation",
        "python",
    ];
    for name in crates {
        let src = workspace().join(name).join("src");
        let g = graph(&src);
        assert!(
            g.len() >= 2,
            "{} modules found in {}",
            g.len(),
            src.display()
        );
        assert_eq!(find_cycle(&g), None, "{name}: {g:?}");
    }
    // multipole's methods sit side by side: the skin model builds on diffusion, never the reverse.
    let g = graph(&workspace().join("multipole/src"));
    assert!(g["skin"].contains("diffusion"), "{g:?}");
    assert!(!g["diffusion"].contains("skin"), "{g:?}");
}
