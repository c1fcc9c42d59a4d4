//! The workspace's shape: no import circles inside a crate. Each crate's `src/` is read as a
//! graph of files, with an edge from a file to every module file it names by path
//! (`crate::a::b`, `super::x`, `self::x`, or a child module by name); a strongly connected
//! component of more than one file is a circle. Test modules (`#[cfg(test)] mod tests`, inline
//! or in a `tests.rs`) are left out: tests may import what they test from any side.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use crate::workspace::workspace_root;

type ModPath = Vec<String>;

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .map(|e| e.expect("directory entry").path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs")
            && path.file_name().is_some_and(|n| n != "tests.rs")
        {
            out.push(path);
        }
    }
}

/// The module a file defines: `a/b.rs` and `a/b/mod.rs` are `[a, b]`; lib.rs and main.rs `[]`.
fn module_of(src: &Path, file: &Path) -> (ModPath, bool) {
    let rel = file.strip_prefix(src).expect("file under src");
    let mut parts: ModPath = rel
        .with_extension("")
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    let is_dir_module = matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    );
    if is_dir_module {
        parts.pop();
    }
    (parts, is_dir_module)
}

/// Source text without comments, string literals, visibility paths (`pub(super)` names no
/// import) and the `#[cfg(test)] mod tests { .. }` block.
fn code_of(text: &str) -> String {
    let text = match text.find("#[cfg(test)]\nmod tests {") {
        Some(i) => &text[..i],
        None => text,
    };
    let mut out = String::with_capacity(text.len());
    let bytes = text.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i..].starts_with(b"//") {
            while i < bytes.len() && bytes[i] != b'\n' {
                i += 1;
            }
        } else if bytes[i..].starts_with(b"/*") {
            i += 2;
            while i < bytes.len() && !bytes[i..].starts_with(b"*/") {
                i += 1;
            }
            i += 2;
        } else if bytes[i] == b'"' {
            i += 1;
            while i < bytes.len() && bytes[i] != b'"' {
                i += if bytes[i] == b'\\' { 2 } else { 1 };
            }
            i += 1;
            out.push_str("\"\"");
        } else {
            out.push(bytes[i] as char);
            i += 1;
        }
    }
    out.replace("pub(super)", "pub")
        .replace("pub(crate)", "pub")
}

fn is_ident(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// Every path in `code` as its segments (`a::b::{c, d::e}` gives `[a, b, c]` and
/// `[a, b, d, e]`), where the first segment is a whole identifier.
fn paths(code: &str) -> Vec<ModPath> {
    let chars: Vec<char> = code.chars().collect();
    let mut found = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        if is_ident(chars[i]) && (i == 0 || !(is_ident(chars[i - 1]) || chars[i - 1] == ':')) {
            let mut prefix = Vec::new();
            let end = read_path(&chars, i, &mut prefix, &mut found);
            i = end.max(i + 1);
        } else {
            i += 1;
        }
    }
    found
}

/// Reads a path starting at `i` (after `prefix`), pushing complete paths to `found`; returns
/// the index after it.
fn read_path(
    chars: &[char],
    mut i: usize,
    prefix: &mut ModPath,
    found: &mut Vec<ModPath>,
) -> usize {
    let depth = prefix.len();
    loop {
        let start = i;
        while i < chars.len() && is_ident(chars[i]) {
            i += 1;
        }
        if i == start {
            break;
        }
        prefix.push(chars[start..i].iter().collect());
        if chars.get(i) == Some(&':') && chars.get(i + 1) == Some(&':') {
            i += 2;
            if chars.get(i) == Some(&'{') {
                i += 1;
                loop {
                    while i < chars.len() && (chars[i].is_whitespace() || chars[i] == ',') {
                        i += 1;
                    }
                    if i >= chars.len() || chars[i] == '}' {
                        i += 1;
                        break;
                    }
                    let before = i;
                    i = read_path(chars, i, prefix, found);
                    // `self` or `*` inside braces, or anything unexpected: skip a character.
                    if i == before {
                        i += 1;
                    }
                }
                prefix.truncate(depth);
                return i;
            }
            continue;
        }
        break;
    }
    if prefix.len() > depth {
        found.push(prefix.clone());
    }
    prefix.truncate(depth);
    i
}

/// Strongly connected components with more than one member (Tarjan).
fn circles(edges: &BTreeMap<usize, BTreeSet<usize>>, n: usize) -> Vec<Vec<usize>> {
    struct State<'a> {
        edges: &'a BTreeMap<usize, BTreeSet<usize>>,
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        stack: Vec<usize>,
        on_stack: Vec<bool>,
        next: usize,
        out: Vec<Vec<usize>>,
    }
    fn visit(s: &mut State, v: usize) {
        s.index[v] = Some(s.next);
        s.low[v] = s.next;
        s.next += 1;
        s.stack.push(v);
        s.on_stack[v] = true;
        let targets: Vec<usize> = s.edges.get(&v).into_iter().flatten().copied().collect();
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
                let w = s.stack.pop().expect("on stack");
                s.on_stack[w] = false;
                component.push(w);
                if w == v {
                    break;
                }
            }
            if component.len() > 1 {
                s.out.push(component);
            }
        }
    }
    let mut s = State {
        edges,
        index: vec![None; n],
        low: vec![0; n],
        stack: Vec::new(),
        on_stack: vec![false; n],
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

/// The import circles among the files of one crate's `src/`.
fn crate_circles(src: &Path) -> Vec<Vec<PathBuf>> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let modules: Vec<(ModPath, bool)> = files.iter().map(|f| module_of(src, f)).collect();
    let by_path: BTreeMap<&ModPath, usize> = modules
        .iter()
        .enumerate()
        .map(|(i, (m, _))| (m, i))
        .collect();
    // The longest prefix of `path` that is a module file.
    let resolve = |path: &[String]| -> Option<usize> {
        (0..=path.len())
            .rev()
            .find_map(|n| by_path.get(&path[..n].to_vec()).copied())
    };
    let mut edges: BTreeMap<usize, BTreeSet<usize>> = BTreeMap::new();
    for (i, file) in files.iter().enumerate() {
        let text = std::fs::read_to_string(file)
            .unwrap_or_else(|e| panic!("cannot read {}: {e}", file.display()));
        let (here, is_dir_module) = &modules[i];
        // `super` of a file module is its folder's module; of a folder module, the parent.
        let parent: ModPath = here[..here.len().saturating_sub(1)].to_vec();
        for path in paths(&code_of(&text)) {
            let target: Option<ModPath> = match path[0].as_str() {
                "crate" => Some(path[1..].to_vec()),
                "self" => Some(here.iter().chain(&path[1..]).cloned().collect()),
                "super" => {
                    let mut base = parent.clone();
                    let mut rest = &path[1..];
                    while rest.first().map(String::as_str) == Some("super") {
                        base.pop();
                        rest = &rest[1..];
                    }
                    Some(base.into_iter().chain(rest.iter().cloned()).collect())
                }
                first if *is_dir_module && path.len() > 1 => {
                    let child: ModPath = here.iter().cloned().chain([first.to_string()]).collect();
                    by_path
                        .contains_key(&child)
                        .then(|| here.iter().chain(&path).cloned().collect())
                }
                _ => None,
            };
            if let Some(target) = target.and_then(|t| resolve(&t)) {
                if target != i {
                    edges.entry(i).or_default().insert(target);
                }
            }
        }
    }
    circles(&edges, files.len())
        .into_iter()
        .map(|c| {
            let mut c: Vec<PathBuf> = c.into_iter().map(|i| files[i].clone()).collect();
            c.sort();
            c
        })
        .collect()
}

#[test]
fn no_crate_has_import_circles() {
    let root = workspace_root();
    let mut found = Vec::new();
    for krate in [
        "tracer",
        "proto",
        "worker",
        "coordinator",
        "bench/luxcore-export",
    ] {
        let src = root.join(krate).join("src");
        if !src.is_dir() {
            continue;
        }
        for circle in crate_circles(&src) {
            let names: Vec<String> = circle
                .iter()
                .map(|p| p.strip_prefix(&root).unwrap_or(p).display().to_string())
                .collect();
            found.push(names.join(" <-> "));
        }
    }
    assert!(found.is_empty(), "import circles:\n{}", found.join("\n"));
}

#[test]
fn the_circle_check_finds_a_circle() {
    let dir = tempfile::tempdir().expect("temp dir");
    let src = dir.path();
    std::fs::create_dir_all(src.join("family")).unwrap();
    std::fs::write(src.join("lib.rs"), "pub mod family;\npub mod leaf;\n").unwrap();
    std::fs::write(src.join("leaf.rs"), "pub struct Shared;\n").unwrap();
    std::fs::write(
        src.join("family/mod.rs"),
        "mod kind;\nuse kind::Kind;\nuse crate::leaf::Shared;\n",
    )
    .unwrap();
    // The child imports its parent, which imports the child: a circle.
    std::fs::write(
        src.join("family/kind.rs"),
        "use super::{Helper, other};\n// use crate::nothing;\npub struct Kind;\n",
    )
    .unwrap();
    let found = crate_circles(src);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(
        found[0],
        vec![src.join("family/kind.rs"), src.join("family/mod.rs")]
    );
    // Importing the shared type from the leaf instead breaks it.
    std::fs::write(
        src.join("family/kind.rs"),
        "use crate::leaf::Shared;\npub struct Kind;\n",
    )
    .unwrap();
    assert!(crate_circles(src).is_empty());
}
