//! The library's layers depend one way (README, "How it works"): geometry → pattern →
//! read (the file readers) → folding → unfold and constraints → dynamics → calibrate → write (the file
//! writers) → plot → commands, with `error` beneath them all and the
//! crate root and prelude above. This reads every library source file, collects the
//! `crate::…` and `super::…` paths it uses (unit tests aside), and fails on an import of a
//! higher layer, on unfold and constraints importing each other, and on any cycle between
//! files.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Rank of a top-level module; modules of equal rank may not import each other.
fn rank(module: &str) -> Option<usize> {
    Some(match module {
        "error" | "names" => 0,
        "geometry" => 1,
        "pattern" => 2,
        "read" => 3,
        "folding" => 4,
        "unfold" | "constraints" => 5,
        "dynamics" => 6,
        "calibrate" | "design" => 7,
        "write" => 8,
        "plot" => 9,
        "commands" => 10,
        _ => return None,
    })
}

/// Module path of every library file (`src/a/b.rs` → ["a", "b"]), the binary left out.
fn library_files() -> BTreeMap<Vec<String>, String> {
    fn walk(dir: &Path, prefix: &[String], out: &mut BTreeMap<Vec<String>, String>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_stem().unwrap().to_str().unwrap().to_string();
            if path.is_dir() {
                if prefix.is_empty() && name == "cli" {
                    continue;
                }
                let mut next = prefix.to_vec();
                next.push(name);
                walk(&path, &next, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                if prefix.is_empty() && (name == "main" || name == "cli") {
                    continue;
                }
                let mut module = prefix.to_vec();
                if !(prefix.is_empty() && name == "lib") {
                    module.push(name);
                }
                out.insert(module, std::fs::read_to_string(&path).unwrap());
            }
        }
    }
    let mut files = BTreeMap::new();
    walk(Path::new("src"), &[], &mut files);
    files
}

/// Reads a path after `crate::` or `super::` at `text[start..]`, expanding `{a, b::c}`
/// groups; pushes every full path (segments after the prefix).
fn read_paths(text: &[char], mut at: usize, prefix: Vec<String>, out: &mut Vec<Vec<String>>) -> usize {
    let mut path = prefix;
    loop {
        while at < text.len() && text[at].is_whitespace() {
            at += 1;
        }
        if at < text.len() && text[at] == '{' {
            at += 1;
            loop {
                at = read_paths(text, at, path.clone(), out);
                while at < text.len() && (text[at].is_whitespace() || text[at] == ',') {
                    at += 1;
                }
                if at >= text.len() || text[at] == '}' {
                    return at + 1;
                }
            }
        }
        let start = at;
        while at < text.len() && (text[at].is_alphanumeric() || text[at] == '_') {
            at += 1;
        }
        let segment: String = text[start..at].iter().collect();
        if segment.is_empty() || segment == "self" || segment == "*" {
            out.push(path);
            return at;
        }
        path.push(segment);
        if text[at..].starts_with(&[':', ':']) {
            at += 2;
        } else {
            out.push(path);
            return at;
        }
    }
}

/// Every path a file uses, resolved to absolute segments from the crate root.
fn used_paths(module: &[String], source: &str) -> Vec<Vec<String>> {
    // Unit tests may use anything; they sit after `#[cfg(test)]`.
    let library = source.split("#[cfg(test)]").next().unwrap_or("");
    // Comments (docs included) name other layers freely.
    let code: String = library
        .lines()
        .map(|line| line.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n");
    let text: Vec<char> = code.chars().collect();
    let mut out = Vec::new();
    let mut at = 0;
    while at < text.len() {
        let rest = &text[at..];
        let preceded_by_ident = at > 0 && (text[at - 1].is_alphanumeric() || text[at - 1] == '_');
        if !preceded_by_ident && rest.starts_with(&['c', 'r', 'a', 't', 'e', ':', ':']) {
            at = read_paths(&text, at + 7, Vec::new(), &mut out);
        } else if !preceded_by_ident && rest.starts_with(&['s', 'u', 'p', 'e', 'r', ':', ':']) {
            let mut base = module.to_vec();
            while text[at..].starts_with(&['s', 'u', 'p', 'e', 'r', ':', ':']) {
                base.pop();
                at += 7;
            }
            at = read_paths(&text, at, base, &mut out);
        } else {
            at += 1;
        }
    }
    out
}

/// The file a path lands in: its longest prefix that is a module file.
fn resolve(files: &BTreeMap<Vec<String>, String>, path: &[String]) -> Vec<String> {
    (0..=path.len())
        .rev()
        .map(|k| path[..k].to_vec())
        .find(|prefix| files.contains_key(prefix))
        .unwrap_or_default()
}

#[test]
fn library_layers_depend_one_way_without_cycles() {
    let files = library_files();
    assert!(files.len() > 20, "found only {} library files", files.len());
    let mut problems = Vec::new();
    let mut edges: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    for (module, source) in &files {
        let Some(own) = module.first() else { continue };
        if own == "prelude" {
            continue;
        }
        let own_rank = rank(own).unwrap_or_else(|| panic!("no layer for module `{own}`: add it to rank()"));
        for path in used_paths(module, source) {
            let mut target = resolve(&files, &path);
            // The root re-exports `Result` and `NanofoldError` from `error`.
            if target.is_empty() {
                target = vec!["error".to_string()];
            }
            let top = &target[0];
            let Some(target_rank) = rank(top) else {
                problems.push(format!(
                    "{}: uses `crate::{}` outside the layers",
                    module.join("::"),
                    path.join("::")
                ));
                continue;
            };
            if target_rank > own_rank || (target_rank == own_rank && top != own) {
                problems.push(format!(
                    "{} (layer {own}) imports {} (layer {top})",
                    module.join("::"),
                    path.join("::")
                ));
            }
            if &target != module && !module.starts_with(&target) {
                edges.entry(module.clone()).or_default().insert(target);
            }
        }
    }
    // Cycles between files (a child using its parent's items is not one).
    let nodes: Vec<&Vec<String>> = files.keys().collect();
    let mut state: BTreeMap<&Vec<String>, u8> = BTreeMap::new();
    fn visit<'a>(
        node: &'a Vec<String>,
        edges: &'a BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
        state: &mut BTreeMap<&'a Vec<String>, u8>,
        stack: &mut Vec<&'a Vec<String>>,
        problems: &mut Vec<String>,
    ) {
        state.insert(node, 1);
        stack.push(node);
        for next in edges.get(node).into_iter().flatten() {
            match state.get(next).copied().unwrap_or(0) {
                0 => visit(next, edges, state, stack, problems),
                1 => {
                    let from = stack.iter().position(|n| *n == next).unwrap_or(0);
                    let cycle: Vec<String> = stack[from..].iter().map(|n| n.join("::")).collect();
                    problems.push(format!("cycle: {} -> {}", cycle.join(" -> "), next.join("::")));
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(node, 2);
    }
    for node in nodes {
        if state.get(node).copied().unwrap_or(0) == 0 {
            visit(node, &edges, &mut state, &mut Vec::new(), &mut problems);
        }
    }
    assert!(problems.is_empty(), "layer violations:\n{}", problems.join("\n"));
}

#[test]
fn the_checker_sees_grouped_nested_and_relative_paths() {
    let module = vec!["dynamics".to_string(), "closed".to_string(), "assemble".to_string()];
    let source = "use super::{ClosedChain, model::{Data, Model}};\nuse crate::io::{self, scene::load};\nfn f() { super::super::plot::draw(); }\n#[cfg(test)]\nmod tests { use crate::cli::X; }";
    let paths: BTreeSet<String> = used_paths(&module, source).iter().map(|p| p.join("::")).collect();
    let expected: BTreeSet<String> = [
        "dynamics::closed::ClosedChain",
        "dynamics::closed::model::Data",
        "dynamics::closed::model::Model",
        "io",
        "io::scene::load",
        "dynamics::plot::draw",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    assert_eq!(paths, expected);
}

/// Every `nanofold::a::b` path (two segments at most) a front end's sources use, with the
/// file that uses it; `use nanofold::{x, y::z}` groups expanded.
fn front_end_paths(files: &[&str]) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    for file in files {
        let source = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{file}: {e}"));
        let code: String = source
            .lines()
            .map(|line| line.split("//").next().unwrap_or(""))
            .collect::<Vec<_>>()
            .join("\n");
        let text: Vec<char> = code.chars().collect();
        let prefix: Vec<char> = "nanofold::".chars().collect();
        let mut at = 0;
        while at + prefix.len() <= text.len() {
            let preceded_by_ident = at > 0 && (text[at - 1].is_alphanumeric() || text[at - 1] == '_');
            if !preceded_by_ident && text[at..].starts_with(&prefix) {
                let mut paths = Vec::new();
                at = read_paths(&text, at + prefix.len(), Vec::new(), &mut paths);
                for path in paths {
                    let shown: Vec<String> = path.into_iter().take(2).collect();
                    out.entry(shown.join("::")).or_insert_with(|| file.to_string());
                }
            } else {
                at += 1;
            }
        }
    }
    out
}

fn rust_files(dir: &str) -> Vec<String> {
    let mut files: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "rs"))
        .map(|p| p.display().to_string())
        .collect();
    files.sort();
    files
}

/// The front door and the prelude: all a front end may use.
fn through_the_door(path: &str) -> bool {
    let top = path.split("::").next().unwrap_or("");
    top == "commands" || top == "prelude"
}

/// Every path a front end's files name past the door, as "file: nanofold::path".
fn past_the_door(files: &[String]) -> Vec<String> {
    let paths = front_end_paths(&files.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(paths.keys().any(|p| p.starts_with("commands")), "{paths:?}");
    paths
        .iter()
        .filter(|(path, _)| !through_the_door(path))
        .map(|(path, file)| format!("{file}: nanofold::{path}"))
        .collect()
}

#[test]
fn python_calls_only_the_door_and_the_prelude() {
    let past = past_the_door(&rust_files("python/src"));
    assert!(
        past.is_empty(),
        "the Python binding reaches past the door:\n{}",
        past.join("\n")
    );
}

#[test]
fn the_command_line_calls_only_the_door_and_the_prelude() {
    let mut files = rust_files("src/cli");
    files.push("src/cli.rs".into());
    files.push("src/main.rs".into());
    let past = past_the_door(&files);
    assert!(
        past.is_empty(),
        "the command line reaches past the door:\n{}",
        past.join("\n")
    );
}
