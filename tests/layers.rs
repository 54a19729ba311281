//! The library's layers depend only downwards: a file of `src/` names (through `crate::`)
//! only modules of its own layer or of the layers below it. The layers, bottom up:
//!
//! 0. `error`
//! 1. `camera`, `style`, `mesh` (without its loaders)
//! 2. `edge_math`
//! 3. `mesh::formats`, the loaders
//! 4. the pass: `gpu`, `scene`
//! 5. `world`
//! 6. `truth`, the ray-cast ground truth
//! 7. `tools`
//!
//! (`lib.rs` declares them all and is not checked.)

use std::path::{Path, PathBuf};

/// The layer of a module path below `crate` (`["gpu", "deferred"]`), or `None` for one this
/// test does not know, which fails it: a new top-level module needs a place here.
fn layer(path: &[&str]) -> Option<u32> {
    Some(match path {
        ["error", ..] => 0,
        ["camera", ..] | ["style", ..] => 1,
        ["mesh", "formats", ..] => 3,
        ["mesh", ..] => 1,
        ["edge_math", ..] => 2,
        ["gpu", ..] | ["scene", ..] => 4,
        ["world", ..] => 5,
        ["truth", ..] => 6,
        ["tools", ..] => 7,
        // The crate-level re-exports of the core types: `crate::Error`, `crate::Mesh`, ….
        [name, ..] if name.starts_with(char::is_uppercase) => 0,
        _ => return None,
    })
}

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

/// The module path of a source file: `src/gpu/deferred.rs` → `["gpu", "deferred"]`.
fn module_of(src: &Path, file: &Path) -> Vec<String> {
    let mut parts: Vec<String> = file
        .strip_prefix(src)
        .unwrap()
        .with_extension("")
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    if parts.last().is_some_and(|p| p == "mod") {
        parts.pop();
    }
    parts
}

/// Every `crate::a::b` path the code (not the comments) names, and the `crate::{a, b}`
/// groups, as the first two segments.
fn crate_paths(source: &str) -> Vec<Vec<String>> {
    let mut paths = Vec::new();
    for line in source.lines() {
        let code = line.split("//").next().unwrap_or("");
        let mut rest = code;
        while let Some(at) = rest.find("crate::") {
            let after = &rest[at + "crate::".len()..];
            let preceded = rest[..at]
                .chars()
                .last()
                .is_some_and(|c| c.is_alphanumeric() || c == '_');
            rest = after;
            if preceded {
                continue;
            }
            if let Some(group) = after.strip_prefix('{') {
                let inner = group.split('}').next().unwrap_or("");
                for item in inner.split(',') {
                    let segments: Vec<String> = item
                        .trim()
                        .split("::")
                        .take(2)
                        .map(|s| s.trim().to_owned())
                        .collect();
                    if !segments[0].is_empty() {
                        paths.push(segments);
                    }
                }
                continue;
            }
            let segments: Vec<String> = after
                .split(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .next()
                .unwrap_or("")
                .split("::")
                .filter(|s| !s.is_empty())
                .take(2)
                .map(str::to_owned)
                .collect();
            if !segments.is_empty() {
                paths.push(segments);
            }
        }
    }
    paths
}

#[test]
fn every_file_names_only_its_own_layer_and_the_ones_below() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let mut checked = 0;
    let mut wrong = Vec::new();
    for file in &files {
        let module = module_of(&src, file);
        if module == ["lib"] {
            continue;
        }
        let names: Vec<&str> = module.iter().map(String::as_str).collect();
        let own =
            layer(&names).unwrap_or_else(|| panic!("{}: a module no layer holds", file.display()));
        let source = std::fs::read_to_string(file).unwrap();
        for path in crate_paths(&source) {
            let segments: Vec<&str> = path.iter().map(String::as_str).collect();
            let Some(theirs) = layer(&segments) else {
                wrong.push(format!(
                    "{}: crate::{} is in no layer",
                    file.display(),
                    path.join("::")
                ));
                continue;
            };
            checked += 1;
            if theirs > own {
                wrong.push(format!(
                    "{} (layer {own}) names crate::{} (layer {theirs})",
                    file.strip_prefix(&src).unwrap().display(),
                    path.join("::")
                ));
            }
        }
    }
    assert!(
        checked > 100,
        "only {checked} references found: is the scan broken?"
    );
    assert!(wrong.is_empty(), "upward references:\n{}", wrong.join("\n"));
}

#[test]
fn the_scan_finds_paths_and_groups_but_not_comments() {
    let source = "use crate::gpu::{frame, targets};\n\
                  use crate::{error::Result, mesh::Mesh};\n\
                  // crate::tools in a comment\n\
                  let x = crate::truth::draw(a); my_crate::other();\n";
    let found: Vec<String> = crate_paths(source).iter().map(|p| p.join("::")).collect();
    assert_eq!(found, ["gpu", "error::Result", "mesh::Mesh", "truth::draw"]);
}
